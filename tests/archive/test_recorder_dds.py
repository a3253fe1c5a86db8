"""mcap_recorder over loopback DDS: exact counts, unchanged bytes, signals, SIGKILL bound."""

from __future__ import annotations

import logging
import signal
import time

import pytest
import yaml
from rclpy.qos import QoSProfile
from rclpy.serialization import deserialize_message
from sensor_msgs.msg import JointState
from std_msgs.msg import Float64

from drill_sim_ros.archive.reader import ArchiveReader
from drill_sim_ros.archive.reindex import reindex
from drill_sim_ros.archive.schemas import message_definition
from tests.archive.helpers import (
    counts_mcap_ros2,
    counts_rosbags,
    running,
    statistics_counts,
    stop,
    wait_for,
)
from tests.archive.ros_fixtures import ros_node

pytestmark = pytest.mark.ros
_log = logging.getLogger(__name__)

# The sim's default shape: 10 topics at 100 Hz.
FLOAT_TOPICS = [f"/drill/test/f{i}" for i in range(9)]
JOINTS = "/drill/test/joints"
TOPICS = [*FLOAT_TOPICS, JOINTS]
RATE_HZ = 100.0
# The SIGKILL bound stated in docs/archive.md: at most 1 s of data lost.
MAX_LOSS_S = 1.0


def _publishers(node):
    qos = QoSProfile(depth=100)
    pubs = {t: node.create_publisher(Float64, t, qos) for t in FLOAT_TOPICS}
    pubs[JOINTS] = node.create_publisher(JointState, JOINTS, qos)
    return pubs


def _message(topic: str, k: int):
    if topic == JOINTS:
        return JointState(name=["a", "b"], position=[float(k), 0.0])
    return Float64(data=float(k))


def _counter(topic: str, data: bytes) -> int:
    """The round number a recorded message carries."""
    if topic == JOINTS:
        return int(deserialize_message(data, JointState).position[0])
    return int(deserialize_message(data, Float64).data)


def _matched(pubs) -> bool:
    return all(p.get_subscription_count() > 0 for p in pubs.values())


def _publish_rounds(pubs, rounds: int, stop_after=None) -> int:
    """Publish ``rounds`` rounds at RATE_HZ on every topic (absolute schedule); rounds sent."""
    start = time.monotonic()
    for k in range(rounds):
        delay = start + k / RATE_HZ - time.monotonic()
        if delay > 0:
            time.sleep(delay)
        for topic, pub in pubs.items():
            pub.publish(_message(topic, k))
        if stop_after is not None and stop_after(k + 1):
            return k + 1
    return rounds


def _record(tmp_path, name: str):
    path = tmp_path / name
    command = ["mcap_recorder", "-o", str(path), "--topics", "/drill/test/.*"]
    return path, running(command, tmp_path / f"{name}.log")


@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM, signal.SIGHUP])
def test_recorded_run_decodes_with_both_libraries_and_counts_match(tmp_path, sig) -> None:
    path, recorder_cm = _record(tmp_path, "dds.mcap")
    rounds = 100
    with recorder_cm as recorder, ros_node("test_publisher") as node:
        pubs = _publishers(node)
        received: list[bytes] = []  # what a raw subscriber of our own gets on the wire
        node.create_subscription(JointState, JOINTS, received.append, 1000, raw=True)
        assert wait_for(lambda: _matched(pubs) and pubs[JOINTS].get_subscription_count() == 2,
                        30), "the recorder never subscribed"
        time.sleep(0.3)  # let the recorder's side of the match settle too
        _publish_rounds(pubs, rounds)
        assert wait_for(lambda: len(received) == rounds, 5)
        time.sleep(0.3)
        assert stop(recorder, sig) == 0
    expected = {t: rounds for t in TOPICS}
    assert counts_mcap_ros2(path) == expected
    assert counts_rosbags(path) == expected
    assert statistics_counts(path) == expected
    _check_bytes_and_metadata(path, received)


def _check_bytes_and_metadata(path, received: list[bytes]) -> None:
    reader = ArchiveReader(path)
    rows = {t: [] for t in TOPICS}
    for message in reader.messages():
        rows[message.topic].append(message.data)
    assert rows[JOINTS] == received  # the wire bytes, unchanged (padding bytes included)
    for topic, data in rows.items():
        assert [_counter(topic, d) for d in data] == list(range(len(data)))
    channel = next(c for c in reader.channels.values() if c.topic == JOINTS)
    offered = yaml.safe_load(channel.offered_qos_yaml)
    assert len(offered) == 1 and offered[0]["reliability"] == "reliable"
    assert channel.type_hash == message_definition("sensor_msgs/msg/JointState").type_hash


def test_sigkill_loses_at_most_one_second_and_reindex_restores_summary(tmp_path) -> None:
    path, recorder_cm = _record(tmp_path, "killed.mcap")
    kill_at_round = 250  # 2.5 s into the run
    with recorder_cm as recorder, ros_node("test_publisher") as node:
        pubs = _publishers(node)
        assert wait_for(lambda: _matched(pubs), 30), "the recorder never subscribed"
        time.sleep(0.3)
        sent = _publish_rounds(pubs, kill_at_round)
        recorder.send_signal(signal.SIGKILL)
        assert recorder.wait(10) == -signal.SIGKILL
    reader = ArchiveReader(path)
    per_topic = {t: [] for t in TOPICS}
    for message in reader.messages():
        per_topic[message.topic].append(message.data)
    assert reader.problem is not None and "truncated" in reader.problem
    for topic, rows in per_topic.items():
        assert [_counter(topic, d) for d in rows] == list(range(len(rows)))  # no gap
        assert sent - len(rows) <= MAX_LOSS_S * RATE_HZ, f"{topic}: lost {sent - len(rows)}"
    _log.info("SIGKILL after %d rounds: lost %s", sent, sorted({sent - len(r) for r in
                                                                per_topic.values()}))
    reindexed = tmp_path / "reindexed.mcap"
    result = reindex(path, reindexed)
    counts = {t: len(rows) for t, rows in per_topic.items()}
    assert result.messages == sum(counts.values())
    assert statistics_counts(reindexed) == counts == counts_rosbags(reindexed)
