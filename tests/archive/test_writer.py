"""Ros2McapWriter and InProcessRecorder: the ROS 2 profile rosbag2, rosbags, mcap_ros2 read."""

from __future__ import annotations

import io
import threading

import pytest
import yaml
from mcap.reader import make_reader
from rclpy.qos import QoSProfile
from rclpy.serialization import serialize_message
from sensor_msgs.msg import JointState
from std_msgs.msg import Float64

from drill_sim_ros import topics
from drill_sim_ros.archive.background import BackgroundWriter
from drill_sim_ros.archive.errors import ArchiveError, UnknownMessageTypeError, WriterClosedError
from drill_sim_ros.archive.inprocess import InProcessRecorder
from drill_sim_ros.archive.schemas import message_definition
from drill_sim_ros.archive.writer import Ros2McapWriter
from drill_sim_ros.model.errors import DrillSimError
from tests.archive.helpers import counts_mcap_ros2, counts_rosbags, statistics_counts

MS = 1_000_000


def _joint_state(i: int) -> JointState:
    return JointState(name=list(topics.BIT_JOINTS), position=[i, -i], velocity=[1.0, 2.0],
                      effort=[3.0, 4.0])


def test_schema_text_and_hash_come_from_the_installed_package() -> None:
    definition = message_definition("sensor_msgs/msg/JointState")
    assert definition.type_name == "sensor_msgs/msg/JointState"
    assert definition.text.startswith("# This is a message that holds data")
    assert "\n" + "=" * 80 + "\nMSG: std_msgs/Header\n" in definition.text
    assert "MSG: builtin_interfaces/Time\n" in definition.text
    assert definition.type_hash.startswith("RIHS01_") and len(definition.type_hash) == 71
    assert message_definition("sensor_msgs/msg/JointState") is definition  # built once


def test_unknown_type_is_a_clear_archive_error() -> None:
    with pytest.raises(UnknownMessageTypeError, match="no_such_msgs"):
        message_definition("no_such_msgs/msg/Thing")
    assert issubclass(UnknownMessageTypeError, ArchiveError)
    assert issubclass(ArchiveError, DrillSimError)


def test_round_trip_through_bytesio_with_profile_metadata_and_statistics() -> None:
    buffer = io.BytesIO()
    writer = Ros2McapWriter(buffer)
    wob = writer.add_channel(topics.BIT_WOB, "std_msgs/msg/Float64", "- depth: 10\n")
    joints = writer.add_channel(topics.BIT_JOINT_STATES, "sensor_msgs/msg/JointState")
    for i in range(50):
        writer.write(wob, serialize_message(Float64(data=float(i))), i * 10 * MS)
        writer.write(joints, serialize_message(_joint_state(i)), i * 10 * MS)
    writer.finish()
    writer.finish()  # idempotent
    buffer.seek(0)
    reader = make_reader(buffer)
    assert reader.get_header().profile == "ros2"
    summary = reader.get_summary()
    assert summary.statistics.message_count == 100
    assert summary.statistics.channel_message_counts == {wob.channel_id: 50, joints.channel_id: 50}
    channel = summary.channels[wob.channel_id]
    assert channel.message_encoding == "cdr"
    assert channel.metadata["offered_qos_profiles"] == "- depth: 10\n"
    assert channel.metadata["topic_type_hash"] == message_definition(topics.MSG_TYPES[
        topics.BIT_WOB]).type_hash
    schema = summary.schemas[channel.schema_id]
    assert (schema.name, schema.encoding) == ("std_msgs/msg/Float64", "ros2msg")
    record = next(m for m in reader.iter_metadata() if m.name == "rosbag2")
    assert record.metadata["ROS_DISTRO"] == "jazzy"
    bag = yaml.safe_load(record.metadata["serialized_metadata"])
    assert bag["version"] == 9 and bag["message_count"] == 100
    assert bag["duration"]["nanoseconds"] == 490 * MS
    assert bag["custom_data"] == {}  # rosbag2 decodes it as a map: null would throw
    with pytest.raises(WriterClosedError):
        writer.write(wob, b"", 0)


def test_chunks_close_after_half_a_second_of_log_time(tmp_path) -> None:
    """The SIGKILL loss bound: no chunk spans more than 0.5 s of log time (at 1 kHz here)."""
    path = tmp_path / "span.mcap"
    with Ros2McapWriter(str(path)) as writer:
        channel = writer.add_channel(topics.BIT_WOB, "std_msgs/msg/Float64")
        for i in range(3000):
            writer.write(channel, serialize_message(Float64(data=float(i))), i * MS)
    with path.open("rb") as stream:
        chunks = make_reader(stream).get_summary().chunk_indexes
    spans = [c.message_end_time - c.message_start_time for c in chunks]
    assert len(chunks) == 6 and max(spans) <= 500 * MS


def test_inprocess_recorder_is_lossless_and_readable_by_both_libraries(tmp_path) -> None:
    path = tmp_path / "inprocess.mcap"
    recorder = InProcessRecorder(str(path))
    recorder.add_topic(topics.BIT_WOB, "std_msgs/msg/Float64", QoSProfile(depth=10))
    recorder.add_topic(topics.BIT_JOINT_STATES, "sensor_msgs/msg/JointState")
    for i in range(2000):
        recorder.write(topics.BIT_WOB, Float64(data=float(i)), i * MS)
        recorder.write(topics.BIT_JOINT_STATES, _joint_state(i), i * MS)
    recorder.close()
    recorder.close()
    expected = {topics.BIT_WOB: 2000, topics.BIT_JOINT_STATES: 2000}
    assert (recorder.written, recorder.dropped) == (4000, 0)
    assert counts_mcap_ros2(path) == expected
    assert counts_rosbags(path) == expected
    assert statistics_counts(path) == expected


def test_inprocess_write_to_an_undeclared_topic_is_counted_not_silent(tmp_path) -> None:
    recorder = InProcessRecorder(str(tmp_path / "x.mcap"))
    recorder.write("/not/declared", Float64(), 0)
    recorder.close()
    assert recorder.dropped == 1


class _BlockedSink:
    """A sink whose writes wait for a gate: makes the queue overflow deterministically."""

    def __init__(self) -> None:
        self.gate = threading.Event()
        self.rows: list[bytes] = []
        self.finished = False

    def add_channel(self, topic: str, type_name: str, offered_qos_yaml: str = "") -> str:
        return topic

    def write(self, channel: str, data: bytes, log_time_ns: int) -> None:
        assert self.gate.wait(10)
        self.rows.append(data)

    def flush(self) -> None: ...

    def finish(self) -> None:
        self.finished = True

    @property
    def message_count(self) -> int:
        return len(self.rows)

    messages_on_disk = message_count


def test_overflow_drops_are_counted_and_close_drains_the_rest() -> None:
    sink = _BlockedSink()
    writer = BackgroundWriter(sink, capacity=10)
    writer.add_channel("/t", "std_msgs/msg/Float64")
    accepted = sum(writer.put("/t", bytes([i]), i) for i in range(100))
    sink.gate.set()
    writer.close()
    assert writer.dropped == 100 - accepted > 0
    assert writer.written == len(sink.rows) == accepted and sink.finished
    assert sink.rows == sorted(sink.rows)  # the order is kept


def test_bad_writer_options_raise_archive_errors(tmp_path) -> None:
    with pytest.raises(ArchiveError):
        Ros2McapWriter(str(tmp_path / "a.mcap"), compression="lzma")
    (tmp_path / "a_file").write_bytes(b"")
    with pytest.raises(ArchiveError, match="cannot write"):
        Ros2McapWriter(str(tmp_path / "a_file" / "dir.mcap"))
