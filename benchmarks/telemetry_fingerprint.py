"""Telemetry fingerprints: a short hash of each of 47 runs, to diff before and after a refactor.

Every vertical scenario with the three reference controllers (25 s), torque mode on both
strings, the deviated scenarios and the deviated preset drilling (walled strings, soft_torque),
the session on seven presets with its string profiles, the exact delay, the string hung off
bottom, the walled presets turning steadily. A refactor that keeps the telemetry bit for bit
prints the same lines. Prints only; no expected values are kept (they are what the code
before the change prints). Use a fresh NUMBA_CACHE_DIR (or clear it): a cached kernel does
not notice a change in an inlined function of another file.

Usage: .venv/bin/python benchmarks/telemetry_fingerprint.py > before.txt  (then after, diff)
"""
from __future__ import annotations

import hashlib
import sys

import numpy as np

from drill_sim_ros.control.bench import run_in_process
from drill_sim_ros.control.scenario import Scenario, load_scenario, scenario_path
from drill_sim_ros.model.presets import load_preset
from drill_sim_ros.model.session import SessionConfig, SimSession
from drill_sim_ros.model.simulator import SimConfig, Simulator
from drill_sim_ros.model.string import (
    W_BIT,
    W_DAMP,
    W_DAMP_GAVE,
    W_LAST,
    W_POS,
    W_TOP,
    W_WALL_GAVE,
    W_WORK,
)


def h(a) -> str:
    return hashlib.sha256(np.ascontiguousarray(a, dtype=np.float64).tobytes()).hexdigest()[:16]


def bench_cases():
    base = [("field_default", None), ("hard_streak", None), ("noisy_delayed_sensors", None),
            ("tight_torque_limit", None), ("speed_ramp", None), ("wob_step", None),
            ("long_string", None), ("low_speed_high_wob", None), ("field_60rpm", None)]
    for name, _ in base:
        sc = load_scenario(scenario_path(name))
        for ctl in ("stiff", "soft_torque", "z_torque"):
            yield f"{name}/{ctl}", sc.with_(controller=ctl, duration_s=25.0, enable_at_s=5.0)
    lumped = Scenario(preset="field_8p5in_shale_lumped", duration_s=20.0, enable_at_s=5.0)
    for ctl in ("stiff", "soft_torque", "z_torque"):
        yield f"lumped/{ctl}", lumped.with_(controller=ctl)
    yield "lumped/torque_mode", lumped.with_(controller="z_torque", mode="torque")
    dist = Scenario(duration_s=20.0, enable_at_s=5.0)
    yield "dist/torque_mode", dist.with_(controller="z_torque", mode="torque")
    for name in ("deviated_startup", "deviated_tag_bottom"):     # walled strings
        yield f"{name}/soft_torque", load_scenario(scenario_path(name)).with_(
            controller="soft_torque", duration_s=25.0)
    yield "deviated_drilling/soft_torque", Scenario(           # bench_closed_loop's case
        preset="field_8p5in_deviated", controller="soft_torque", duration_s=20.0,
        enable_at_s=0.0)


def walled_steady(preset: str) -> str:
    """The walled preset's own simulator turning steadily (every junction sliding), 3000 wave
    steps: its state, its waves and the layout's rows of state (the slots, the junctions'
    slips and the guard's sums), by name: a refactor may add rows of constants."""
    p = load_preset(preset)
    sim = Simulator(p.params, SimConfig(dtau=p.dtau), top_drive=p.top_drive, scales=p.scales,
                    string=p.kernel_string, bit_law=p.bit_law)
    sim.advance(3000 * p.kernel_string.substeps, 0)
    wave, wave_i, wave_f, _ = sim.string_arrays()
    state_rows = [W_LAST, W_WORK, W_DAMP, W_TOP, W_BIT, W_WALL_GAVE, W_DAMP_GAVE]
    return " ".join(h(x) for x in (sim.state, wave, wave_i[W_POS], wave_f[state_rows]))


def main() -> None:
    for name, sc in bench_cases():
        run = run_in_process(sc)
        print(name, h(run.rows), h(run.accumulators), run.clamped_commands, flush=True)
    for preset in ("fig5_8a", "fig9", "fig12", "field_8p5in_shale_lumped", "field_8p5in_shale",
                   "field_8p5in_deviated", "field_8p5in_build_turn"):
        p = load_preset(preset)
        s = SimSession(SessionConfig(preset=p, string_rate_hz=10.0))
        blocks = [s.run(200) for _ in range(3)]
        rows = np.concatenate([b.rows for b in blocks])
        strings = [x for b in blocks for x in b.strings]
        sh = hashlib.sha256()
        for x in strings:
            sh.update(np.ascontiguousarray(x.speed_rad_s).tobytes())
            sh.update(np.ascontiguousarray(x.torque_nm).tobytes())
            sh.update(str(x.stamp_ns).encode())
        print("session", preset, h(rows), sh.hexdigest()[:16], len(strings), flush=True)
    for preset in ("fig5_8a", "fig7"):
        p = load_preset(preset)
        sim = Simulator(p.params, SimConfig(dtau=p.dtau, method="exact"), top_drive=p.top_drive,
                        scales=p.scales, string=p.kernel_string, bit_law=p.bit_law)
        out = sim.advance(20000, every=10)
        print("exact", preset, h(out.data if hasattr(out, "data") else out.rows), h(sim.state),
              flush=True)
    p = load_preset("field_8p5in_shale")
    sim = Simulator(p.params, SimConfig(dtau=p.dtau), top_drive=p.top_drive, scales=p.scales,
                    string=p.kernel_string, bit_law=p.bit_law)
    sim.hang_off_bottom()
    out = sim.advance(5000, every=10)
    print("hang", h(sim.state), h(sim.string_profile()[0]), flush=True)
    for preset in ("field_8p5in_deviated", "field_8p5in_build_turn"):
        print("steady", preset, walled_steady(preset), flush=True)


if __name__ == "__main__":
    sys.exit(main())
