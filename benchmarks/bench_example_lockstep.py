"""The example controller in command-triggered lockstep: periods per second, determinism.

sim_node (field preset, ``lockstep:=true -p lockstep_trigger:=command``, recording in
process) and examples/lockstep_controller.py run as two processes on loopback DDS; this
process watches only /diagnostics (1 Hz), so it adds no wake-up per period. Prints, for two
runs, the periods per second between the first /diagnostics past t = 0 and the first one
past ``--periods`` periods (simulated time from the stamps, wall time as received), and
whether the two recordings' first ``--periods`` periods of telemetry are bit-identical. No
asserts. Target (issue 22): >= 500 periods/s.
Usage: .venv/bin/python benchmarks/bench_example_lockstep.py [--periods 5000]
"""

from __future__ import annotations

import argparse
import os
import random
import subprocess
import sys
import tempfile
import time
from pathlib import Path

os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
os.environ.pop("ROS_LOCALHOST_ONLY", None)
os.environ.setdefault("ROS_DOMAIN_ID", str(random.randint(1, 101)))
os.environ.setdefault("AMENT_PREFIX_PATH", sys.prefix)

import numpy as np
import rclpy
from bench_node import stop  # the sibling script (benchmarks/ is on sys.path when run)
from diagnostic_msgs.msg import DiagnosticArray
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node

from drill_sim_ros import topics
from drill_sim_ros.ros.closed_loop import read_telemetry

BIN = Path(sys.prefix) / "bin"
EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "lockstep_controller.py"
PERIOD_S = 0.01


def one_run(periods: int, record: Path) -> tuple[float, np.ndarray]:
    """(periods/s, the recording's telemetry rows up to ``periods`` periods)."""
    context = rclpy.Context()
    rclpy.init(context=context)
    executor = SingleThreadedExecutor(context=context)
    node = Node("bench_example_watch", context=context)
    seen: list[tuple[float, float]] = []           # (wall s, sim s) per /diagnostics
    node.create_subscription(DiagnosticArray, topics.DIAGNOSTICS, lambda msg: seen.append(
        (time.monotonic(), msg.header.stamp.sec + msg.header.stamp.nanosec * 1e-9)), 10)
    executor.add_node(node)
    sim = subprocess.Popen([str(BIN / "sim_node"), "--ros-args", "-p", "lockstep:=true",
                            "-p", "lockstep_trigger:=command", "-p", "status_line:=false",
                            "-p", "publish_clock:=false", "-p", f"record.path:={record}"],
                           stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    example = subprocess.Popen([sys.executable, str(EXAMPLE)], stdout=subprocess.DEVNULL,
                               stderr=subprocess.DEVNULL)
    try:
        deadline = time.monotonic() + 120.0 + periods / 50.0
        end_s = periods * PERIOD_S
        while not (seen and seen[-1][1] >= end_s) and time.monotonic() < deadline:
            executor.spin_once(timeout_sec=0.1)
    finally:
        stop(example)
        stop(sim)
        executor.remove_node(node)
        node.destroy_node()
        rclpy.try_shutdown(context=context)
    running = [(wall, sim_s) for wall, sim_s in seen if sim_s > 0]
    (wall_a, sim_a), (wall_b, sim_b) = running[0], running[-1]
    rate = (sim_b - sim_a) / PERIOD_S / (wall_b - wall_a) if wall_b > wall_a else float("nan")
    return rate, read_telemetry(record)[:periods + 1]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--periods", type=int, default=5000)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory(prefix="bench_example_") as tmp:
        rate_a, rows_a = one_run(args.periods, Path(tmp) / "a.mcap")
        rate_b, rows_b = one_run(args.periods, Path(tmp) / "b.mcap")
    same = rows_a.shape == rows_b.shape == (args.periods + 1, len(topics.TELEMETRY_FIELDS)) \
        and rows_a.tobytes() == rows_b.tobytes()
    print(f"examples/lockstep_controller.py against sim_node in command-triggered lockstep, "
          f"field preset: {rate_a:.0f} and {rate_b:.0f} periods/s over {args.periods} periods "
          f"({min(rate_a, rate_b) / 100.0:.1f}x real time at 100 Hz); the two recordings' "
          f"telemetry {'is bit-identical' if same else 'DIFFERS'} ({len(rows_a)} and "
          f"{len(rows_b)} samples)")


if __name__ == "__main__":
    main()
