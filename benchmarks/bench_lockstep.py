"""Closed loop in command-triggered lockstep: periods per second, and determinism (no asserts).

sim_node runs in its own process (``lockstep:=true -p lockstep_trigger:=command``, field
preset); this process runs a Python controller node (``LockstepDriver``) that reacts to every
sample with a top-drive speed and WOB command. Prints the periods per second achieved (the
wall time from the first to the last sample) for two runs, and whether their telemetry bytes
are identical. Target (issue 11): >= 500 periods/s, i.e. 5x real time at 100 Hz.
Usage: .venv/bin/python benchmarks/bench_lockstep.py [--periods 5000]
"""

from __future__ import annotations

import argparse
import os
import random
import subprocess
import sys
import time
from pathlib import Path

os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
os.environ.pop("ROS_LOCALHOST_ONLY", None)
os.environ.setdefault("ROS_DOMAIN_ID", str(random.randint(1, 101)))
os.environ.setdefault("AMENT_PREFIX_PATH", sys.prefix)

import numpy as np
import rclpy
from bench_node import stop  # the sibling script (benchmarks/ is on sys.path when run)
from rclpy.executors import SingleThreadedExecutor

from drill_sim_ros import topics
from drill_sim_ros.model.params import RPM_PER_RAD_S
from drill_sim_ros.model.presets import load_preset
from drill_sim_ros.ros.lockstep_driver import Command, LockstepDriver

BIN = Path(sys.prefix) / "bin"
F = topics.TELEMETRY_INDEX
PRESET = load_preset("field_8p5in_shale")


def damping_policy(row: np.ndarray | None) -> Command:
    """A torque-feedback speed reference: the setpoint drops as the measured string torque
    rises above its start value (surface signals only)."""
    rpm0 = PRESET.physical.surface_rpm
    if row is None:
        return Command(speed_rad_s=rpm0 / RPM_PER_RAD_S)
    excess_nm = row[F["string_torque_measured_nm"]] - 10_000.0
    return Command(speed_rad_s=max(0.0, rpm0 - 1e-3 * excess_nm) / RPM_PER_RAD_S)


def one_run(periods: int) -> tuple[float, list[bytes]]:
    sim = subprocess.Popen([str(BIN / "sim_node"), "--ros-args", "-p", "lockstep:=true",
                            "-p", "lockstep_trigger:=command", "-p", "status_line:=false",
                            "-p", "publish_clock:=false"],
                           stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    context = rclpy.Context()
    rclpy.init(context=context)
    executor = SingleThreadedExecutor(context=context)
    driver = LockstepDriver(damping_policy, periods, context=context)
    executor.add_node(driver)
    try:
        deadline = time.monotonic() + 120.0 + periods / 50.0
        first_wall = None
        while not driver.done and time.monotonic() < deadline:
            executor.spin_once(timeout_sec=0.1)
            if first_wall is None and driver.rows:
                first_wall, first_count = time.monotonic(), len(driver.rows)
        elapsed = time.monotonic() - first_wall
        rate = (len(driver.rows) - first_count) / elapsed if elapsed > 0 else float("nan")
        return rate, list(driver.payloads)
    finally:
        executor.remove_node(driver)
        driver.destroy_node()
        rclpy.try_shutdown(context=context)
        stop(sim)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--periods", type=int, default=5000)
    args = parser.parse_args()
    rate_a, bytes_a = one_run(args.periods)
    rate_b, bytes_b = one_run(args.periods)
    print(f"command-triggered lockstep, field preset, Python controller in another process: "
          f"{rate_a:.0f} and {rate_b:.0f} periods/s over {args.periods} periods "
          f"({min(rate_a, rate_b) / 100.0:.1f}x real time at 100 Hz); the two runs' telemetry "
          f"{'is bit-identical' if bytes_a == bytes_b else 'DIFFERS'} "
          f"({len(bytes_a)} and {len(bytes_b)} samples)")


if __name__ == "__main__":
    main()
