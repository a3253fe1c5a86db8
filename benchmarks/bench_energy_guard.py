"""The physics guard's cost (issue 52): the wall's energy check after every run of the
simulator (Simulator._check_wall_energy), on the closed-loop bench and per call.

Prints, no asserts. In process, soft_torque in speed mode, 180 s at 100 Hz on the deviated
field preset, with the guard and with it switched off (the check replaced by a no-op: the
code before the guard), alternated in one process so both see the same machine; and the
check's own cost per call. Target: the bench >= 100x real time, the guard within the noise.
Usage: .venv/bin/python benchmarks/bench_energy_guard.py [--rounds 3]
"""

from __future__ import annotations

import argparse
import time

from drill_sim_ros.control.bench import run_in_process
from drill_sim_ros.control.scenario import Scenario
from drill_sim_ros.model.presets import load_preset
from drill_sim_ros.model.simulator import SimConfig, Simulator

GUARD = Simulator._check_wall_energy


def check_us(preset_name: str, calls: int = 100_000) -> float:
    """Microseconds per call of the guard on a distributed string with its wall."""
    p = load_preset(preset_name)
    sim = Simulator(p.params, SimConfig(dtau=p.dtau, n_nodes=2048), top_drive=p.top_drive,
                    scales=p.scales, string=p.kernel_string, bit_law=p.bit_law)
    sim.advance(1000)
    start = time.perf_counter()
    for _ in range(calls):
        GUARD(sim)
    return (time.perf_counter() - start) / calls * 1e6


def bench_rate(scenario: Scenario, guarded: bool) -> float:
    """Periods per second of the in-process closed loop, with or without the guard."""
    Simulator._check_wall_energy = GUARD if guarded else (lambda self: None)
    try:
        run = run_in_process(scenario)
    finally:
        Simulator._check_wall_energy = GUARD
    return scenario.periods / run.wall_s


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--preset", default="field_8p5in_deviated")
    parser.add_argument("--rounds", type=int, default=3)
    args = parser.parse_args()
    scenario = Scenario(preset=args.preset, controller="soft_torque", duration_s=180.0,
                        enable_at_s=60.0)
    run_in_process(scenario.with_(duration_s=1.0, enable_at_s=0.0))     # compile, warm up
    print(f"the guard: {check_us(args.preset):.2f} us per call (one call per control period)")
    rates: dict[bool, list[float]] = {True: [], False: []}
    for i in range(args.rounds):
        for guarded in (False, True):
            rate = bench_rate(scenario, guarded)
            rates[guarded].append(rate)
            print(f"round {i + 1}, bench {'with' if guarded else 'without'} the guard: "
                  f"{rate:,.0f} periods/s ({rate / 100:.0f}x real time)", flush=True)
    best_with, best_without = max(rates[True]), max(rates[False])
    print(f"best of {args.rounds}: with/without = {best_with / best_without:.3f}")


if __name__ == "__main__":
    main()
