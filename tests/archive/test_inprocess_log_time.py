"""The in-process recording's log time: wall-clock origin + simulated time; stamps unchanged."""

from __future__ import annotations

import time
from pathlib import Path

from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory
from rclpy.qos import QoSProfile
from sensor_msgs.msg import JointState

from drill_sim_ros import topics
from drill_sim_ros.archive.inprocess import InProcessRecorder

MS = 1_000_000


def _record(path: Path, sim_times_ns: list[int], **kwargs: object) -> InProcessRecorder:
    recorder = InProcessRecorder(str(path), **kwargs)
    recorder.add_topic(topics.BIT_JOINT_STATES, topics.MSG_TYPES[topics.BIT_JOINT_STATES],
                       QoSProfile(depth=10))
    for t_ns in sim_times_ns:
        joints = JointState(name=list(topics.BIT_JOINTS), position=[0.0, 0.0])
        joints.header.stamp.sec, joints.header.stamp.nanosec = divmod(t_ns, 1_000_000_000)
        recorder.write(topics.BIT_JOINT_STATES, joints, t_ns)
    recorder.close()
    return recorder


def _log_and_stamps(path: Path) -> tuple[list[int], list[int]]:
    log, stamps = [], []
    with path.open("rb") as stream:
        reader = make_reader(stream, decoder_factories=[DecoderFactory()])
        for _, _, message, decoded in reader.iter_decoded_messages():
            log.append(message.log_time)
            stamps.append(decoded.header.stamp.sec * 1_000_000_000
                          + decoded.header.stamp.nanosec)
    return log, stamps


def test_log_time_starts_at_the_wall_clock_and_keeps_sim_spacing(tmp_path: Path) -> None:
    sim = [i * 10 * MS for i in range(200)]           # 2 s of sim time at 100 Hz
    before = time.time_ns()
    recorder = _record(tmp_path / "run.mcap", sim)
    after = time.time_ns()
    log, stamps = _log_and_stamps(tmp_path / "run.mcap")
    assert stamps == sim                               # header stamps: simulated time
    assert before <= log[0] <= after                   # a real date, not 1970
    assert [t - log[0] for t in log] == sim            # spacing of simulated time, exactly
    assert recorder.log_time_origin_ns == log[0]


def test_the_origin_is_taken_from_the_first_message_sim_time(tmp_path: Path) -> None:
    """A recording that starts at sim time 5 s: origin = wall clock - 5 s."""
    sim = [5_000 * MS + i * 10 * MS for i in range(10)]
    before = time.time_ns()
    recorder = _record(tmp_path / "late.mcap", sim)
    log, _ = _log_and_stamps(tmp_path / "late.mcap")
    assert before <= log[0] <= time.time_ns()
    assert recorder.log_time_origin_ns == log[0] - sim[0]


def test_an_explicit_origin_is_used_as_given(tmp_path: Path) -> None:
    origin = 1_700_000_000 * 1_000_000_000
    _record(tmp_path / "fixed.mcap", [0, 10 * MS], log_time_origin_ns=origin)
    log, _ = _log_and_stamps(tmp_path / "fixed.mcap")
    assert log == [origin, origin + 10 * MS]
