"""Recording figures under faults: prints them (no asserts).

(a) SIGKILL of sim_node recording in process (real time, 100 Hz): simulated seconds lost,
    i.e. the last sim_time_s an independent subscriber received before the kill minus the
    last one in the file (read by the damage-tolerant reader);
(b) SIGKILL of mcap_recorder recording that sim_node over DDS: the same difference;
(c) free run (real_time_factor 0) with and without in-process recording: the node's achieved
    real-time factor (mean of its /diagnostics figures after a 3 s warm-up), and their ratio.
Usage: .venv/bin/python benchmarks/bench_recording_faults.py [--runs 3] [--seconds 5]
"""

from __future__ import annotations

import argparse
import os
import random
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
os.environ.pop("ROS_LOCALHOST_ONLY", None)
os.environ.setdefault("ROS_DOMAIN_ID", str(random.randint(1, 101)))
os.environ.setdefault("AMENT_PREFIX_PATH", sys.prefix)

import rclpy
from diagnostic_msgs.msg import DiagnosticArray
from rclpy.executors import SingleThreadedExecutor
from rclpy.qos import QoSProfile, ReliabilityPolicy
from rclpy.serialization import deserialize_message
from std_msgs.msg import Float64MultiArray

from drill_sim_ros import topics
from drill_sim_ros.archive.reader import ArchiveReader
from drill_sim_ros.ros.spinning import SpinThread

BIN = Path(sys.prefix) / "bin"
SIM_TIME = topics.TELEMETRY_INDEX["sim_time_s"]


class Listener:
    """The last telemetry sim time and the achieved real-time factors, in a spun thread."""

    def __init__(self) -> None:
        self.context = rclpy.Context()
        rclpy.init(context=self.context)
        self.node = rclpy.create_node("bench_faults_listener", context=self.context)
        qos = QoSProfile(depth=1000, reliability=ReliabilityPolicy.RELIABLE)
        self.last_sim_time_s = -1.0
        self.rates: list[tuple[float, float]] = []
        self.node.create_subscription(Float64MultiArray, topics.TELEMETRY, self._on_row, qos)
        self.node.create_subscription(DiagnosticArray, topics.DIAGNOSTICS, self._on_diag, qos)
        self._executor = SingleThreadedExecutor(context=self.context)
        self._executor.add_node(self.node)
        self._spinning = SpinThread(self._executor, self.context)

    def _on_row(self, msg: Float64MultiArray) -> None:
        self.last_sim_time_s = max(self.last_sim_time_s, msg.data[SIM_TIME])

    def _on_diag(self, msg: DiagnosticArray) -> None:
        for status in msg.status:
            values = {v.key: v.value for v in status.values}
            if "real_time_factor_achieved" in values:
                self.rates.append((time.monotonic(), float(values["real_time_factor_achieved"])))

    def close(self) -> None:
        self._spinning.stop()
        self.node.destroy_node()
        rclpy.try_shutdown(context=self.context)


def _start(*args: str) -> subprocess.Popen:
    return subprocess.Popen([str(BIN / args[0]), *args[1:]], stdout=subprocess.DEVNULL,
                            stderr=subprocess.DEVNULL)


def _last_recorded_sim_time_s(path: Path) -> float:
    last = -1.0
    for message in ArchiveReader(path).messages(lambda t: t == topics.TELEMETRY):
        last = max(last, deserialize_message(message.data, Float64MultiArray).data[SIM_TIME])
    return last


def _wait(predicate, timeout_s: float) -> bool:
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        if predicate():
            return True
        time.sleep(0.02)
    return False


def _kill_and_measure(victim: subprocess.Popen, listener: Listener, path: Path) -> float:
    victim.send_signal(signal.SIGKILL)
    victim.wait(10)
    received = listener.last_sim_time_s
    return received - _last_recorded_sim_time_s(path)


def sigkill_in_process(seconds: float, work: Path) -> float:
    path = work / f"inproc_{time.monotonic_ns()}.mcap"
    listener = Listener()
    sim = _start("sim_node", "--ros-args", "-p", f"record.path:={path}",
                 "-p", "status_line:=false")
    try:
        assert _wait(lambda: listener.last_sim_time_s > 0, 60), "no telemetry"
        time.sleep(seconds)
        return _kill_and_measure(sim, listener, path)
    finally:
        if sim.poll() is None:
            sim.kill()
        listener.close()


def sigkill_dds_recorder(seconds: float, work: Path) -> float:
    path = work / f"dds_{time.monotonic_ns()}.mcap"
    listener = Listener()
    sim = _start("sim_node", "--ros-args", "-p", "status_line:=false")
    recorder = _start("mcap_recorder", "-o", str(path))
    try:
        assert _wait(lambda: listener.last_sim_time_s > 0, 60), "no telemetry"
        assert _wait(lambda: listener.node.count_subscribers(topics.TELEMETRY) >= 2, 30)
        time.sleep(seconds)
        return _kill_and_measure(recorder, listener, path)
    finally:
        for process in (recorder, sim):
            if process.poll() is None:
                process.send_signal(signal.SIGINT)
                process.wait(20)
        listener.close()


def free_run_rtf(seconds: float, record: Path | None) -> float:
    listener = Listener()
    args = ["sim_node", "--ros-args", "-p", "real_time_factor:=0", "-p", "status_line:=false"]
    if record is not None:
        args += ["-p", f"record.path:={record}"]
    sim = _start(*args)
    try:
        assert _wait(lambda: listener.last_sim_time_s > 0, 60), "no telemetry"
        start = time.monotonic()
        time.sleep(3.0 + seconds)
        window = [r for t, r in listener.rates if t >= start + 3.0]
        return sum(window) / len(window) if window else float("nan")
    finally:
        sim.send_signal(signal.SIGINT)
        sim.wait(60)
        listener.close()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--seconds", type=float, default=5.0)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as work:
        work_dir = Path(work)
        for name, case in (("in-process (sim_node record.path)", sigkill_in_process),
                           ("over DDS (mcap_recorder)", sigkill_dds_recorder)):
            losses = [case(args.seconds, work_dir) for _ in range(args.runs)]
            print(f"SIGKILL after {args.seconds:g} s, {name}: lost "
                  + ", ".join(f"{x:.3f}" for x in losses) + " s of simulated time")
        plain = free_run_rtf(args.seconds, None)
        recorded = free_run_rtf(args.seconds, work_dir / "free.mcap")
        print(f"free run: real-time factor {plain:.1f}x without recording, {recorded:.1f}x "
              f"with in-process recording (ratio {recorded / plain:.2f})")


if __name__ == "__main__":
    main()
