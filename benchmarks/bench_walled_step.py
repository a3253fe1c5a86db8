"""Where the deviated closed loop's time goes: the walled string's step and the Python around it.

Prints, no asserts. CPU time of this process (``time.process_time``), and for the closed
loop the wall clock beside it: on the shared 2-core machine the wall clock counts other
jobs, the CPU time much less; on a quiet machine the two agree within a percent. For one
scenario on a walled string (default deviated_startup: field_8p5in_deviated, a cell of one
wave step at every junction):
- the kernel alone, us per wave step (``bit_substeps`` bit-law steps and one step of the
  delay lines): the session's simulator from the scenario's start, and the preset's own
  simulator turning steadily (its step; every cell one step of the lines);
- the closed loop in process (``control.bench.Bench`` and the scenario's controller, as
  ``run_in_process``), CPU us per control period: the whole period, the session's period
  (``Bench.step``), and the controller with its measurement; the kernel's share is the
  wave steps per period times the first figure.
With ``--drilling``: instead of the scenario's own start, its preset drilling from a steady
start under soft_torque, enabled from t = 0 (``benchmarks/bench_closed_loop.py``'s case, which
times it by the wall clock only): on the deviated preset every junction slides from the
first step.
Before/after a change: run it on both checkouts back to back (PYTHONPATH, and a fresh
NUMBA_CACHE_DIR for a changed model file), several times, and compare best and median.
Usage: .venv/bin/python benchmarks/bench_walled_step.py [--scenario deviated_startup]
           [--seconds 5] [--repeats 5] [--drilling]
"""

from __future__ import annotations

import argparse
import statistics
import time

from drill_sim_ros.control.bench import Bench, build_controller, run_in_process
from drill_sim_ros.control.scenario import Scenario, load_scenario, scenario_path
from drill_sim_ros.model.simulator import SimConfig, Simulator


def kernel_us_per_wave_step(sim: Simulator, substeps: int, wave_steps: int = 500) -> float:
    """CPU us per wave step of ``sim`` over ``wave_steps`` wave steps (no rows)."""
    start = time.process_time()
    sim.advance(substeps * wave_steps, 0)
    return (time.process_time() - start) / wave_steps * 1e6


def preset_simulator(scenario: Scenario) -> Simulator:
    """The scenario's preset stepped at its own dtau, started turning steadily."""
    p = scenario.load_preset()
    return Simulator(p.params, SimConfig(dtau=p.dtau, n_nodes=2048), top_drive=p.top_drive,
                     scales=p.scales, string=p.kernel_string, bit_law=p.bit_law)


def loop_us_per_period(scenario: Scenario) -> tuple[float, float, float, float]:
    """CPU us per period of the closed loop: (whole, the session's period, controller), and
    the whole by the wall clock."""
    bench = Bench(scenario)
    controller = build_controller(scenario, bench.preset)
    session_s = controller_s = 0.0
    start, wall_start = time.process_time(), time.perf_counter()
    command = controller.update(bench.measurement())
    for _ in range(bench.periods):
        t0 = time.process_time()
        bench.step(command)
        t1 = time.process_time()
        if not bench.done:
            command = controller.update(bench.measurement())
        session_s += t1 - t0
        controller_s += time.process_time() - t1
    whole_s, wall_s = time.process_time() - start, time.perf_counter() - wall_start
    return tuple(1e6 * s / bench.periods for s in (whole_s, session_s, controller_s, wall_s))


def spread(values: list[float]) -> str:
    """The least and the median of ``values``."""
    return f"best {min(values):.2f}, median {statistics.median(values):.2f}"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenario", default="deviated_startup")
    parser.add_argument("--seconds", type=float, default=5.0)
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--drilling", action="store_true",
                        help="the preset drilling from a steady start (bench_closed_loop.py)")
    args = parser.parse_args()
    scenario = load_scenario(scenario_path(args.scenario)).with_(duration_s=args.seconds)
    if args.drilling:
        scenario = Scenario(preset=scenario.preset, controller="soft_torque",
                            duration_s=args.seconds, enable_at_s=0.0)
    run_in_process(scenario.with_(duration_s=0.2))                 # compile, warm up
    bench = Bench(scenario)
    substeps = bench.preset.kernel_string.substeps
    wave_steps = round(bench.session.steps / substeps)
    name = f"{scenario.preset} drilling" if args.drilling else args.scenario
    print(f"{name} ({bench.preset.name}): parts {bench.session.sim.string_arrays()[3]}"
          f", {substeps} bit steps a wave step, {wave_steps} wave steps a period")
    session_k = [kernel_us_per_wave_step(Bench(scenario).session.sim, substeps)
                 for _ in range(args.repeats)]
    steady_k = [kernel_us_per_wave_step(preset_simulator(scenario), substeps)
                for _ in range(args.repeats)]
    print(f"kernel, us per wave step: the session's from its start {spread(session_k)}; "
          f"the preset's, turning steadily {spread(steady_k)}")
    loops = [loop_us_per_period(scenario) for _ in range(args.repeats)]
    whole = [x[0] for x in loops]
    best, period_us = min(loops), scenario.period_s * 1e6
    print(f"closed loop, CPU us per period: {spread(whole)} ({period_us / min(whole):.0f}x "
          f"real time at best, {period_us / statistics.median(whole):.0f}x median, of CPU); "
          f"the best split: "
          f"session {best[1]:.1f} (its kernel about {wave_steps * min(session_k):.1f}), "
          f"controller and measurement {best[2]:.1f}")
    wall = [x[3] for x in loops]
    print(f"closed loop, wall us per period: {spread(wall)} ({period_us / min(wall):.0f}x "
          f"real time at best, {period_us / statistics.median(wall):.0f}x median, by the "
          "wall clock)")


if __name__ == "__main__":
    main()
