"""The compiled packing of a block: its payloads are what rclpy's serializer makes of
messages built field by field from topics.py."""

from __future__ import annotations

import numpy as np
import pytest
from rclpy.serialization import deserialize_message, serialize_message
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import JointState
from std_msgs.msg import Float64, Float64MultiArray, MultiArrayDimension, UInt8

from drill_sim_ros import topics
from drill_sim_ros.model.params import RPM_PER_RAD_S
from drill_sim_ros.ros.frame import SampleFrame

F = topics.TELEMETRY_INDEX
TIMES_NS = np.array([0, 10_000_000, 123_456_789_012, 5_000_000_000], dtype=np.int64)
PADDED = (topics.BIT_MODE, topics.BIT_JOINT_STATES, topics.SURFACE_JOINT_STATES,
          topics.SURFACE_MEASURED, topics.TELEMETRY)


def random_rows(rows: int, seed: int = 3) -> np.ndarray:
    """SI telemetry rows of any values (a mode of 0..3, a negative zero)."""
    rng = np.random.default_rng(seed)
    data = rng.uniform(-5e4, 5e4, (rows, len(topics.TELEMETRY_FIELDS)))
    data[:, F["mode"]] = rng.integers(0, 4, rows)
    data[0, F["rop_m_s"]] = -0.0
    data[:, F["sim_time_s"]] = TIMES_NS[:rows] / 1e9
    return data


def joint_state(names: tuple[str, ...], sec: int, nanosec: int, values: list[float]
                ) -> JointState:
    n = len(names)
    msg = JointState(name=list(names), position=values[0:n], velocity=values[n:2 * n],
                     effort=values[2 * n:3 * n])
    msg.header.stamp.sec, msg.header.stamp.nanosec = sec, nanosec
    return msg


def expected_messages(v: np.ndarray, time_ns: int) -> dict[str, object]:
    """Messages of one SI row as topics.py documents them, built one field at a time."""
    sec, nanosec = divmod(time_ns, 1_000_000_000)
    label = ",".join(topics.TELEMETRY_FIELDS)
    n = len(topics.TELEMETRY_FIELDS)
    telemetry = Float64MultiArray(data=v.tolist())
    telemetry.layout.dim = [MultiArrayDimension(label=label, size=n, stride=n)]
    clock = Clock()
    clock.clock.sec, clock.clock.nanosec = sec, nanosec
    return {
        topics.BIT_WOB: Float64(data=v[F["wob_n"]]), topics.BIT_TOB: Float64(data=v[F["tob_nm"]]),
        topics.BIT_ROP: Float64(data=v[F["rop_m_s"]]),
        topics.BIT_RPM: Float64(data=v[F["bit_rpm"]]),
        topics.BIT_DEPTH_OF_CUT: Float64(data=v[F["depth_of_cut_m"]]),
        topics.BIT_MODE: UInt8(data=int(v[F["mode"]])),
        topics.BIT_JOINT_STATES: joint_state(topics.BIT_JOINTS, sec, nanosec, [
            v[F["bit_angle_rad"]], v[F["bit_depth_m"]], v[F["bit_rpm"]] / RPM_PER_RAD_S,
            v[F["rop_m_s"]], v[F["tob_nm"]], v[F["wob_n"]]]),
        topics.SURFACE_JOINT_STATES: joint_state(topics.SURFACE_JOINTS, sec, nanosec, [
            v[F["surface_angle_rad"]], v[F["bit_depth_m"]],
            v[F["surface_rpm"]] / RPM_PER_RAD_S, v[F["rop_m_s"]], v[F["surface_torque_nm"]],
            v[F["applied_wob_n"]]]),
        topics.SURFACE_MEASURED: joint_state(topics.MEASURED_JOINTS, sec, nanosec, [
            v[F["surface_angle_rad"]], v[F["surface_angle_rad"]], v[F["bit_depth_m"]],
            v[F["bit_depth_m"]], v[F["drive_speed_measured_rad_s"]],
            v[F["drive_speed_measured_rad_s"]], v[F["rop_m_s"]], v[F["rop_m_s"]],
            v[F["motor_torque_measured_nm"]], v[F["string_torque_measured_nm"]],
            v[F["hook_load_measured_n"]], v[F["applied_wob_estimate_n"]]]),
        topics.TELEMETRY: telemetry,
        topics.CLOCK: clock,
    }


@pytest.mark.parametrize("with_clock", [True, False])
def test_payloads_are_the_serialized_messages_in_publishing_order(with_clock):
    rows = random_rows(len(TIMES_NS), seed=5)
    frame = SampleFrame(with_clock)
    assert frame.topics[-1] == topics.CLOCK if with_clock else topics.CLOCK not in frame.topics
    packed = frame.pack(rows, TIMES_NS)
    assert len(packed) == len(TIMES_NS)
    for row, time_ns, payloads in zip(rows, TIMES_NS.tolist(), packed, strict=True):
        expected = expected_messages(row, time_ns)
        assert len(payloads) == len(frame.topics)
        for topic, payload in zip(frame.topics, payloads, strict=True):
            msg = expected[topic]
            serialized = serialize_message(msg)
            assert type(payload) is bytes, topic
            assert len(payload) == len(serialized), topic
            assert deserialize_message(payload, type(msg)) == msg, topic
            if topic in PADDED:               # rclpy leaves padding bytes undefined
                assert all(a == b or a == 0 for a, b in zip(payload, serialized, strict=True))
            else:
                assert payload == serialized, topic


def test_templates_zero_their_padding():
    frame = SampleFrame(with_clock=False)
    rows = np.ones((1, len(topics.TELEMETRY_FIELDS)))
    payload = frame.pack(rows, np.zeros(1, dtype=np.int64))[0][
        frame.topics.index(topics.BIT_JOINT_STATES)]
    assert payload[17:20] == b"\x00\x00\x00"  # frame_id "": length 1 + NUL, then 3 pad bytes


def test_hook_means_the_applied_wob_on_every_topic_it_is_on():
    """A controller reads drill/surface/measured and writes drill/cmd/top_drive, whose
    ``hook`` effort is the applied WOB: wherever a state topic names a ``hook`` joint, its
    effort is the applied WOB too (true, or the measured estimate), never the hook load
    (issue 26). Read from the packed messages of a row whose fields all differ."""
    rows = random_rows(1, seed=11)
    frame = SampleFrame(with_clock=False)
    payloads = dict(zip(frame.topics, frame.pack(rows, TIMES_NS[:1])[0], strict=True))
    row = rows[0]
    applied_wob = {row[F["applied_wob_n"]], row[F["applied_wob_estimate_n"]]}
    assert "hook" in topics.COMMAND_JOINTS
    for topic in (topics.SURFACE_JOINT_STATES, topics.SURFACE_MEASURED):
        msg = deserialize_message(payloads[topic], JointState)
        for joint, effort in zip(msg.name, msg.effort, strict=True):
            if joint == "hook":
                assert effort in applied_wob, (topic, joint)
