"""Throughput of the MCAP archive: in-process recording, recording over DDS, replay.

Prints messages/s. Run from the repository root with the venv (DDS stays on loopback):
    ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST .venv/bin/python benchmarks/bench_mcap.py
"""

from __future__ import annotations

import argparse
import os
import re
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

os.environ.setdefault("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")
os.environ.pop("ROS_LOCALHOST_ONLY", None)
os.environ.setdefault("AMENT_PREFIX_PATH", sys.prefix)

import rclpy
from rclpy.qos import QoSProfile
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import JointState
from std_msgs.msg import Float64, Float64MultiArray, MultiArrayDimension, UInt8

from drill_sim_ros import topics
from drill_sim_ros.archive.inprocess import InProcessRecorder
from drill_sim_ros.archive.pacing import Pacer
from drill_sim_ros.archive.reader import ArchiveReader
from drill_sim_ros.archive.replay_node import Plan, Progress, Replayer, play_once

BIN = Path(sys.executable).parent


def sample_messages(k: int) -> dict[str, object]:
    """One sample of the sim's per-sample topics, shaped like sim_node's."""
    x = float(k)
    joints = JointState(name=list(topics.BIT_JOINTS), position=[x, x], velocity=[x, x],
                        effort=[x, x])
    telemetry = Float64MultiArray(data=[x] * len(topics.TELEMETRY_FIELDS))
    telemetry.layout.dim = [MultiArrayDimension(label=",".join(topics.TELEMETRY_FIELDS),
                                                size=len(topics.TELEMETRY_FIELDS), stride=1)]
    msgs: dict[str, object] = {t: Float64(data=x) for t in (
        topics.BIT_WOB, topics.BIT_TOB, topics.BIT_ROP, topics.BIT_RPM, topics.BIT_DEPTH_OF_CUT)}
    msgs.update({topics.BIT_MODE: UInt8(data=k % 4), topics.BIT_JOINT_STATES: joints,
                 topics.SURFACE_JOINT_STATES: joints, topics.TELEMETRY: telemetry,
                 topics.CLOCK: Clock()})
    return msgs


def bench_inprocess(directory: Path, samples: int) -> Path:
    path = directory / "inprocess.mcap"
    recorder = InProcessRecorder(str(path))
    batches = [sample_messages(k) for k in range(100)]
    for topic in batches[0]:
        recorder.add_topic(topic, topics.MSG_TYPES[topic], QoSProfile(depth=100))
    start = time.perf_counter()
    for k in range(samples):
        for topic, msg in batches[k % 100].items():
            recorder.write(topic, msg, k * 10_000_000)
    queued = time.perf_counter()
    recorder.close()
    end = time.perf_counter()
    count = recorder.written
    print(f"in-process: {count} msgs, caller {count / (queued - start):,.0f} msg/s, "
          f"written+closed {count / (end - start):,.0f} msg/s, dropped {recorder.dropped}, "
          f"{path.stat().st_size / count:.1f} B/msg in file "
          f"(sim default ~1000 msg/s -> {path.stat().st_size / count * 1000 / 1e3:.0f} kB/s)")
    return path


def bench_replay(path: Path) -> None:
    rclpy.init()
    node = rclpy.create_node("bench_replay")
    reader = ArchiveReader(path)
    sum(1 for _ in reader.messages())  # registers the channels
    channels = list(reader.channels.values())
    options = argparse.Namespace(topics=".*")
    replayer = Replayer(node, channels, clock=False)
    pacer = Pacer(0, rate=1e12)
    start = time.perf_counter()
    play_once(reader, replayer, pacer, options, Progress(Plan(channels, 0, 1), 1e12))
    elapsed = time.perf_counter() - start
    print(f"replay (read + publish raw, no subscriber): {replayer.sent / elapsed:,.0f} msg/s")
    node.destroy_node()
    rclpy.try_shutdown()


def bench_dds(directory: Path, count: int) -> None:
    path = directory / "dds.mcap"
    recorder = subprocess.Popen([str(BIN / "mcap_recorder"), "-o", str(path),
                                 "--topics", "/bench/.*"], stderr=subprocess.PIPE, text=True)
    rclpy.init()
    node = rclpy.create_node("bench_publisher")
    pubs = [node.create_publisher(Float64, f"/bench/t{i}", QoSProfile(depth=1000))
            for i in range(10)]
    deadline = time.monotonic() + 30
    while any(p.get_subscription_count() == 0 for p in pubs) and time.monotonic() < deadline:
        time.sleep(0.05)
    time.sleep(0.5)
    start = time.perf_counter()
    for k in range(count // len(pubs)):
        for pub in pubs:
            pub.publish(Float64(data=float(k)))
    elapsed = time.perf_counter() - start
    time.sleep(2.0)
    recorder.send_signal(signal.SIGINT)
    _, log = recorder.communicate(timeout=30)
    node.destroy_node()
    rclpy.try_shutdown()
    recorded = int(re.search(r"(\d+) messages on", log).group(1))
    print(f"over DDS: published {count} as fast as possible in {elapsed:.2f} s "
          f"({count / elapsed:,.0f} msg/s); recorder kept {recorded} "
          f"({recorded / elapsed:,.0f} msg/s over the publishing window)")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--samples", type=int, default=10_000, help="sim samples (x10 msgs)")
    parser.add_argument("--dds-messages", type=int, default=20_000)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        path = bench_inprocess(Path(tmp), args.samples)
        bench_replay(path)
        bench_dds(Path(tmp), args.dds_messages)


if __name__ == "__main__":
    main()
