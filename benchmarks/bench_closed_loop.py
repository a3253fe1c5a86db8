"""Closed-loop periods per second: in process and over DDS (issue 12; prints, no asserts).

The field preset on both strings (the distributed default and its lumped twin), 100 Hz
control period, a Python controller (soft_torque, speed mode) reacting to every sample:
- in process (``drill_sim closed-loop``): ``run_in_process``, against a reference measured
  beside it: the same session stepped one period at a time with no controller (the floor);
- over DDS (``--ros``): sim_node and top_drive_controller as processes on loopback, periods
  per second as the controller node measures them (first to last sample).
Target: in process >= 100x real time (10 000 periods/s).
Usage: .venv/bin/python benchmarks/bench_closed_loop.py [--seconds 180] [--dds-seconds 60]
           [--preset NAME ...] (default: field_8p5in_shale field_8p5in_shale_lumped;
           --dds-seconds 0 skips DDS)
"""

from __future__ import annotations

import argparse
import os
import random
import sys
import time

os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
os.environ.pop("ROS_LOCALHOST_ONLY", None)
os.environ.setdefault("ROS_DOMAIN_ID", str(random.randint(1, 101)))
os.environ.setdefault("AMENT_PREFIX_PATH", sys.prefix)

from drill_sim_ros.control.bench import run_in_process, session_config
from drill_sim_ros.control.scenario import Scenario
from drill_sim_ros.model.session import SimSession
from drill_sim_ros.ros.closed_loop import run_over_dds


def session_only(scenario: Scenario) -> float:
    """Periods/s of the session alone, one period per call (the floor of any bench)."""
    session = SimSession(session_config(scenario, scenario.load_preset()))
    start = time.perf_counter()
    for _ in range(scenario.periods):
        session.run(1)
    return scenario.periods / (time.perf_counter() - start)


def in_process(scenario: Scenario, rounds: int = 3) -> None:
    """Print ``rounds`` in-process runs of ``scenario``, each beside the session alone."""
    run_in_process(scenario.with_(duration_s=1.0, enable_at_s=0.0))      # compile, warm up
    for _ in range(rounds):
        floor = session_only(scenario)
        run = run_in_process(scenario)
        rate = scenario.periods / run.wall_s
        print(f"{scenario.preset}, in process: {rate:,.0f} periods/s ({rate / 100:.0f}x real "
              f"time at 100 Hz) with the controller; session alone {floor:,.0f} periods/s "
              f"(controller and command cost {1e6 / rate - 1e6 / floor:.0f} us per period)",
              flush=True)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=180.0)
    parser.add_argument("--dds-seconds", type=float, default=60.0)
    parser.add_argument("--preset", nargs="*",
                        default=["field_8p5in_shale", "field_8p5in_shale_lumped"])
    args = parser.parse_args()
    scenario = Scenario(controller="soft_torque", duration_s=args.seconds, enable_at_s=60.0
                        if args.seconds > 60 else 0.0)
    for preset in args.preset:
        in_process(scenario.with_(preset=preset))
    if args.dds_seconds <= 0:
        return
    dds = scenario.with_(duration_s=args.dds_seconds, enable_at_s=min(20.0, args.dds_seconds))
    for _ in range(2):
        remote = run_over_dds(dds)
        rate = (dds.periods - 1) / remote.wall_s
        print(f"over DDS (sim_node + top_drive_controller, {dds.preset}): {rate:,.0f} "
              f"periods/s ({rate / 100:.1f}x real time) over {dds.periods:,} periods")


if __name__ == "__main__":
    main()
