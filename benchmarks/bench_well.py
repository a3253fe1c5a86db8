"""The deviated well's cost: the closed-loop bench with and without the wall (issue 32).

Prints, no asserts. In process, soft_torque in speed mode, 180 s at 100 Hz on the deviated
field preset, against the same preset with its ``well`` block removed (the vertical hole,
the model as before), alternated in one process so both see the same machine; and the
kernel's step alone on each (the string stepped with a row every 100 steps).
Target: the bench on the deviated preset >= 100x real time, and as fast as without the well.
Usage: .venv/bin/python benchmarks/bench_well.py [--preset field_8p5in_deviated] [--rounds 3]
"""

from __future__ import annotations

import argparse
import tempfile
import time
from collections.abc import Callable, Sequence
from dataclasses import replace
from pathlib import Path

import yaml

from drill_sim_ros.control.bench import run_in_process
from drill_sim_ros.control.scenario import Scenario
from drill_sim_ros.model.presets import Preset, load_preset, preset_path
from drill_sim_ros.model.simulator import SimConfig, Simulator


def kernel_ns_per_step(preset: Preset, steps: int = 400_000) -> float:
    """ns per step of the kernel alone on ``preset`` (a row every 100 steps), best of 3."""
    best = float("inf")
    for _ in range(3):
        sim = Simulator(preset.params, SimConfig(dtau=preset.dtau, n_nodes=2048),
                        top_drive=preset.top_drive, scales=preset.scales,
                        string=preset.kernel_string, bit_law=preset.bit_law)
        start = time.perf_counter()
        sim.advance(steps, 100)
        best = min(best, (time.perf_counter() - start) / steps * 1e9)
    return best


def bench_rate(scenario: Scenario, cpu: bool = False) -> float:
    """Periods per second of the in-process closed loop; ``cpu``: per second of this
    process's CPU time (what a quiet machine's wall clock would give, as near as a loaded
    one can tell: the other jobs' time does not count)."""
    start = time.process_time()
    run = run_in_process(scenario)
    return scenario.periods / (time.process_time() - start if cpu else run.wall_s)


def alternated(variants: Sequence[tuple[str, Callable[[], float]]], rounds: int,
               rate_hz: float = 100.0) -> dict[str, list[float]]:
    """Periods per second of each variant (a name and a call that runs the bench once and
    returns its rate), alternated round by round in one process so that all see the same
    machine; prints each with its real-time factor at ``rate_hz`` periods a simulated
    second. The timing loop of this script and of bench_energy_guard.py."""
    rates: dict[str, list[float]] = {name: [] for name, _ in variants}
    for i in range(rounds):
        for name, run in variants:
            rate = run()
            rates[name].append(rate)
            print(f"round {i + 1}, bench {name}: {rate:,.0f} periods/s "
                  f"({rate / rate_hz:.0f}x real time)", flush=True)
    return rates


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--preset", default="field_8p5in_deviated")
    parser.add_argument("--rounds", type=int, default=3)
    args = parser.parse_args()
    walled = load_preset(args.preset)
    vertical = replace(walled, string=replace(walled.string, well=None))
    scenario = Scenario(preset=args.preset, controller="soft_torque", duration_s=180.0,
                        enable_at_s=60.0)
    run_in_process(scenario.with_(duration_s=1.0, enable_at_s=0.0))     # compile, warm up
    for name, preset in (("with the well", walled), ("without it", vertical)):
        print(f"kernel, {name}: {kernel_ns_per_step(preset):.0f} ns/step")
    data = yaml.safe_load(preset_path(args.preset).read_text())
    data.pop("well")
    vertical_path = Path(tempfile.mkdtemp(prefix="bench_well_")) / "vertical.yaml"
    vertical_path.write_text(yaml.safe_dump(data))
    plain = scenario.with_(preset=str(vertical_path))
    alternated((("with the well", lambda: bench_rate(scenario)),
                ("without it", lambda: bench_rate(plain))), args.rounds)


if __name__ == "__main__":
    main()
