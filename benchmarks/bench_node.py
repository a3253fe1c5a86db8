"""sim_node figures with a subscriber on every topic: prints them (no asserts).

(a) real time at 100 Hz: CPU % of one core (process CPU time / wall time, from
    /proc/<pid>/stat) against the reference measured in the same run: a bare rclpy process
    whose thread publishes sim_node's own payloads (the same bytes, topics and QoS) every
    10 ms through ``Publisher.publish``; and the node's tick lateness p50/p99 (its
    /diagnostics);
(b) free run (real_time_factor 0): achieved real-time factor (sim seconds per wall second),
    without and with in-process recording (record.path).
Targets (issue 10): (a) sim_node <= 1.5x the reference, p99 <= 2 ms; (b) >= 100x, and with
recording >= a third of that.
Usage: .venv/bin/python benchmarks/bench_node.py [--seconds 10] [--preset field_8p5in_shale]
"""

from __future__ import annotations

import argparse
import os
import random
import signal
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

# Loopback DDS and a domain of our own, before rclpy is imported.
os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
os.environ.pop("ROS_LOCALHOST_ONLY", None)
os.environ.setdefault("ROS_DOMAIN_ID", str(random.randint(1, 101)))
os.environ.setdefault("AMENT_PREFIX_PATH", sys.prefix)

import numpy as np
import rclpy
from rclpy.node import Node
from rclpy.qos import QoSProfile, ReliabilityPolicy

from drill_sim_ros import topics
from drill_sim_ros.ros.messages import type_of

BIN = Path(sys.prefix) / "bin"
TICKS = os.sysconf("SC_CLK_TCK")
PUBLISHED = [t for t in topics.MSG_TYPES if t not in topics.COMMANDS]


def cpu_seconds(pid: int) -> float:
    """utime + stime of a process, in seconds."""
    fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / TICKS


class Listener(Node):
    """One subscription per published topic; keeps the last /diagnostics values."""

    def __init__(self) -> None:
        super().__init__("bench_listener")
        self.count = 0
        self.diagnostics: dict[str, str] = {}
        # (wall s at receipt, the node's real_time_factor_achieved over its last second)
        self.rates: list[tuple[float, float]] = []
        qos = QoSProfile(depth=100, reliability=ReliabilityPolicy.RELIABLE)
        for topic in PUBLISHED:
            self.create_subscription(type_of(topic), topic, self._on_message, qos)
        self.create_subscription(type_of(topics.DIAGNOSTICS), topics.DIAGNOSTICS,
                                 self._on_diagnostics, qos)

    def _on_message(self, _msg: object) -> None:
        self.count += 1

    def _on_diagnostics(self, msg) -> None:
        self.diagnostics = {kv.key: kv.value for s in msg.status for kv in s.values}
        if "real_time_factor_achieved" in self.diagnostics:
            self.rates.append((time.monotonic(),
                               float(self.diagnostics["real_time_factor_achieved"])))


def sim_rate(rates: list[tuple[float, float]], start: float, end: float) -> float:
    """Simulated seconds per wall second: the mean of the node's own once-a-second figures
    (sim time advanced over the wall time between two /diagnostics, both read in the node)
    received in [start, end]. Receipt times cannot serve: in free run the listener falls
    behind and /diagnostics waits behind the telemetry, so its arrivals bunch up."""
    inside = [rate for wall, rate in rates if start <= wall <= end]
    return float(np.mean(inside)) if inside else float("nan")


def spin_for(node: Node, seconds: float) -> None:
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        rclpy.spin_once(node, timeout_sec=0.05)


def start_node(preset: str, factor: float, record_path: str = "") -> subprocess.Popen:
    command = [str(BIN / "sim_node"), "--ros-args", "-p", f"model.preset:={preset}",
               "-p", f"real_time_factor:={factor}", "-p", "status_line:=false"]
    if record_path:
        command += ["-p", f"record.path:={record_path}"]
    return subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)


def start_reference(preset: str) -> subprocess.Popen:
    return subprocess.Popen([sys.executable, __file__, "--reference-publisher", preset],
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)


def reference_publisher(preset: str) -> None:
    """The reference: a thread publishing sim_node's payloads of one block every 10 ms."""
    from drill_sim_ros.model.presets import load_preset
    from drill_sim_ros.model.session import SessionConfig, SimSession
    from drill_sim_ros.ros.frame import SampleFrame
    from drill_sim_ros.ros.sim_node import CLOCK_QOS, DATA_QOS

    rclpy.init()
    node = Node("bench_reference")
    frame = SampleFrame(with_clock=True)
    pubs = [node.create_publisher(type_of(t), t, CLOCK_QOS if t == topics.CLOCK else DATA_QOS)
            for t in frame.topics]
    block = SimSession(SessionConfig(preset=load_preset(preset))).run(100)
    payloads = frame.pack(block.rows, block.stamps_ns)
    stop_event = threading.Event()

    def publish_every_10_ms() -> None:
        deadline = time.monotonic()
        i = 0
        while not stop_event.is_set():
            for pub, payload in zip(pubs, payloads[i % len(payloads)], strict=True):
                pub.publish(payload)
            i += 1
            deadline += 0.01
            time.sleep(max(0.0, deadline - time.monotonic()))

    thread = threading.Thread(target=publish_every_10_ms, daemon=True)
    thread.start()
    try:
        rclpy.spin(node)
    except KeyboardInterrupt:
        pass
    finally:
        stop_event.set()
        thread.join(1.0)
        node.destroy_node()
        rclpy.try_shutdown()


def stop(proc: subprocess.Popen) -> None:
    proc.send_signal(signal.SIGINT)
    try:
        proc.wait(timeout=10)
    except subprocess.TimeoutExpired:
        proc.kill()
        proc.wait()


def measure(listener: Listener, proc: subprocess.Popen, seconds: float) -> dict[str, float]:
    """CPU %, message rate and diagnostics of one running process over a steady window."""
    try:
        # start-up (numba compiles on a cold cache: tens of seconds), discovery, then 3 s
        first = listener.count
        end = time.monotonic() + 120.0
        while listener.count == first and time.monotonic() < end:
            rclpy.spin_once(listener, timeout_sec=0.05)
        spin_for(listener, 3.0)
        cpu0, wall0, n0 = cpu_seconds(proc.pid), time.monotonic(), listener.count
        spin_for(listener, seconds)
        cpu1, wall1, n1 = cpu_seconds(proc.pid), time.monotonic(), listener.count
        spin_for(listener, 1.1)                       # the next /diagnostics
        diag = dict(listener.diagnostics)
    finally:
        stop(proc)
    wall = wall1 - wall0
    return {"cpu_percent": 100.0 * (cpu1 - cpu0) / wall, "received_per_s": (n1 - n0) / wall,
            "p50_ms": float(diag.get("tick_lateness_p50_ms", "nan")),
            "p99_ms": float(diag.get("tick_lateness_p99_ms", "nan")),
            "overruns": float(diag.get("overruns", "nan")),
            "sim_rate": sim_rate(listener.rates, wall0, wall1),
            "rtf_reported": float(diag.get("real_time_factor_achieved", "nan"))}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=10.0)
    parser.add_argument("--preset", default="field_8p5in_shale")
    parser.add_argument("--reference-publisher", metavar="PRESET", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.reference_publisher:
        reference_publisher(args.reference_publisher)
        return
    rclpy.init()
    listener = Listener()
    try:
        ref = measure(listener, start_reference(args.preset), args.seconds)
        rt = measure(listener, start_node(args.preset, 1.0), args.seconds)
        print(f"(a) real time, 100 Hz, {len(PUBLISHED)} topics subscribed: sim_node CPU "
              f"{rt['cpu_percent']:.1f} % of one core, reference publisher "
              f"{ref['cpu_percent']:.1f} %: ratio {rt['cpu_percent'] / ref['cpu_percent']:.2f}x"
              f"; tick lateness p50 {rt['p50_ms']:.3f} ms, p99 {rt['p99_ms']:.3f} ms; "
              f"overruns {rt['overruns']:g}; {rt['received_per_s']:.0f} msg/s received "
              f"(reference {ref['received_per_s']:.0f})")
        free = measure(listener, start_node(args.preset, 0.0), args.seconds)
        print(f"(b) free run: achieved real-time factor {free['sim_rate']:.1f}x (mean of the "
              f"node's once-a-second figures; the last {free['rtf_reported']:.1f}x); CPU "
              f"{free['cpu_percent']:.0f} %; {free['received_per_s']:.0f} msg/s received")
        with tempfile.TemporaryDirectory() as tmp:
            path = str(Path(tmp) / "free.mcap")
            rec = measure(listener, start_node(args.preset, 0.0, path), args.seconds)
        print(f"(c) free run, recording in process: achieved real-time factor "
              f"{rec['sim_rate']:.1f}x = {rec['sim_rate'] / free['sim_rate']:.2f} of (b); "
              f"CPU {rec['cpu_percent']:.0f} %")
    finally:
        listener.destroy_node()
        rclpy.try_shutdown()


if __name__ == "__main__":
    main()
