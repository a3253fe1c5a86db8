"""The physics guard's cost (issue 52): the string's energy check after every run of the
simulator (Simulator._check_energy, string.balance), on the closed-loop bench and per call.

Prints, no asserts. In process, soft_torque in speed mode, 180 s at 100 Hz on the deviated
field preset, with the check and with it switched off (replaced by a no-op), alternated in
one process so both see the same machine (bench_well.alternated); the check's own cost per
call; and the kernel's ns a step (bench_well.kernel_ns_per_step), whose sums of the works
(string.step: top, bit, wall, dampers) cannot be switched off: run this script on the code
before the guard too (PYTHONPATH and a fresh NUMBA_CACHE_DIR) and compare that line.
Target: the bench >= 100x real time, the guard within the noise.
Usage: .venv/bin/python benchmarks/bench_energy_guard.py [--preset NAME] [--rounds 3] [--cpu]
"""

from __future__ import annotations

import argparse
import time

from bench_well import alternated, bench_rate, kernel_ns_per_step  # the sibling script

from drill_sim_ros.control.scenario import Scenario
from drill_sim_ros.model.presets import load_preset
from drill_sim_ros.model.simulator import SimConfig, Simulator

GUARD = getattr(Simulator, "_check_energy", None)      # None: the code before the guard


def check_us(preset_name: str, calls: int = 20_000) -> float:
    """Microseconds of CPU per call of the guard after a control period (10 ms) on
    ``preset_name`` (CPU time: the machine's other jobs do not count)."""
    p = load_preset(preset_name)
    sim = Simulator(p.params, SimConfig(dtau=p.dtau, n_nodes=2048), top_drive=p.top_drive,
                    scales=p.scales, string=p.kernel_string, bit_law=p.bit_law)
    period = sim.steps_for(0.01 / p.scales.time_s)
    sim.advance(period)
    start = time.process_time()
    for _ in range(calls):
        GUARD(sim, period)
    return (time.process_time() - start) / calls * 1e6


def guarded_rate(scenario: Scenario, guarded: bool, cpu: bool) -> float:
    """Periods per second (of CPU with ``cpu``) of the in-process closed loop, with or
    without the guard."""
    Simulator._check_energy = GUARD if guarded else (lambda self, n_steps: None)
    try:
        return bench_rate(scenario, cpu)
    finally:
        Simulator._check_energy = GUARD


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--preset", default="field_8p5in_deviated")
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--cpu", action="store_true",
                        help="rates per second of CPU time (a loaded machine)")
    args = parser.parse_args()
    scenario = Scenario(preset=args.preset, controller="soft_torque", duration_s=180.0,
                        enable_at_s=60.0)
    bench_rate(scenario.with_(duration_s=1.0, enable_at_s=0.0))     # compile, warm up
    print(f"kernel: {kernel_ns_per_step(load_preset(args.preset)):.0f} ns/step")
    if GUARD is None:
        print("no energy guard in this code (before issue 52's balance)")
        return
    print(f"the guard: {check_us(args.preset):.2f} us of CPU per call (one call per control "
          "period)")
    rates = alternated((("without the guard", lambda: guarded_rate(scenario, False, args.cpu)),
                        ("with the guard", lambda: guarded_rate(scenario, True, args.cpu))),
                       args.rounds)
    best_with, best_without = max(rates["with the guard"]), max(rates["without the guard"])
    print(f"best of {args.rounds}: with/without = {best_with / best_without:.3f}")


if __name__ == "__main__":
    main()
