"""Shared helpers for the archive tests: files, subprocesses, in-test ROS nodes, readers."""

from __future__ import annotations

import collections
import os
import signal
import subprocess
import sys
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path

BIN = Path(sys.executable).parent
FLOAT64 = "std_msgs/msg/Float64"


def wait_for(predicate: Callable[[], bool], timeout_s: float, period_s: float = 0.02) -> bool:
    """Poll ``predicate`` until it holds or ``timeout_s`` passes; returns its last value."""
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        if predicate():
            return True
        time.sleep(period_s)
    return predicate()


def start(command: list[str], log_path: Path) -> subprocess.Popen:
    """Start a console script of the venv with the test environment, output to a log file."""
    log = log_path.open("wb")
    return subprocess.Popen([str(BIN / command[0]), *command[1:]], stdout=log,
                            stderr=subprocess.STDOUT, env=os.environ.copy())


def stop(process: subprocess.Popen, sig: int = signal.SIGINT, timeout_s: float = 15.0) -> int:
    """Send ``sig`` and wait; kill after ``timeout_s`` (then the test fails on the code)."""
    if process.poll() is None:
        process.send_signal(sig)
    try:
        return process.wait(timeout_s)
    except subprocess.TimeoutExpired:
        process.kill()
        process.wait(5)
        return -999


@contextmanager
def running(command: list[str], log_path: Path) -> Iterator[subprocess.Popen]:
    """A subprocess that is always gone when the block ends."""
    process = start(command, log_path)
    try:
        yield process
    finally:
        if process.poll() is None:
            process.kill()
            process.wait(5)


def counts_mcap_ros2(path: Path) -> collections.Counter:
    """Messages per topic, each decoded by mcap-ros2-support."""
    from mcap.reader import make_reader
    from mcap_ros2.decoder import DecoderFactory

    counts: collections.Counter = collections.Counter()
    with path.open("rb") as stream:
        reader = make_reader(stream, decoder_factories=[DecoderFactory()])
        for _, channel, _, decoded in reader.iter_decoded_messages():
            assert decoded is not None
            counts[channel.topic] += 1
    return counts


def counts_rosbags(path: Path) -> collections.Counter:
    """Messages per topic, each decoded by rosbags (a bare .mcap with the ros2 profile)."""
    from rosbags.highlevel import AnyReader

    counts: collections.Counter = collections.Counter()
    with AnyReader([path]) as reader:
        for connection, _, raw in reader.messages():
            assert reader.deserialize(raw, connection.msgtype) is not None
            counts[connection.topic] += 1
    return counts


def statistics_counts(path: Path) -> collections.Counter:
    """Per-topic counts from the file's summary Statistics record."""
    from mcap.reader import make_reader

    with path.open("rb") as stream:
        summary = make_reader(stream).get_summary()
    assert summary is not None and summary.statistics is not None
    topic = {cid: channel.topic for cid, channel in summary.channels.items()}
    stats = summary.statistics
    assert stats.message_count == sum(stats.channel_message_counts.values())
    return collections.Counter(
        {topic[cid]: n for cid, n in stats.channel_message_counts.items()}
    )


def write_float64_run(path: Path, topic: str, count: int, period_ns: int = 1_000_000) -> Path:
    """``count`` std_msgs/Float64 messages 0, 1, ... on ``topic``, one per ``period_ns`` of log
    time, through the archive's writer (1 kHz: one 0.5 s chunk per 500 messages)."""
    from rclpy.serialization import serialize_message
    from std_msgs.msg import Float64

    from drill_sim_ros.archive.writer import Ros2McapWriter
    with Ros2McapWriter(str(path)) as writer:
        channel = writer.add_channel(topic, "std_msgs/msg/Float64")
        for i in range(count):
            writer.write(channel, serialize_message(Float64(data=float(i))), i * period_ns)
    return path
