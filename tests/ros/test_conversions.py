"""Per-sample conversions: the Python-float rows agree bit for bit with the numpy reference,
and the packed CDR payloads are what rclpy's serializer produces."""

from __future__ import annotations

import math

import numpy as np
import pytest
from rclpy.serialization import deserialize_message, serialize_message
from sensor_msgs.msg import JointState

from drill_sim_ros import topics
from drill_sim_ros.model import kernel as k
from drill_sim_ros.model.presets import load_preset
from drill_sim_ros.model.simulator import Samples
from drill_sim_ros.ros.conversions import (
    SampleMessages,
    TelemetryConverter,
    telemetry_rows,
)

F = topics.TELEMETRY_INDEX
PADDED = (topics.BIT_MODE, topics.BIT_JOINT_STATES, topics.SURFACE_JOINT_STATES,
          topics.TELEMETRY)


def random_samples(rows: int, seed: int = 3) -> Samples:
    rng = np.random.default_rng(seed)
    data = rng.uniform(-50.0, 50.0, (rows, k.N_COLS))
    data[:, k.C_MODE] = rng.integers(0, 4, rows)
    data[0, k.C_V] = -0.0
    return Samples(data, depth_offset=1234.0, angle_offset=2.0 * math.pi * 57)


@pytest.mark.parametrize("rows", [1, 7])
def test_python_rows_equal_the_numpy_reference_bit_for_bit(rows):
    preset = load_preset("field_8p5in_shale")
    samples = random_samples(rows)
    times = [i * 10_000_000 / 1_000_000_000 for i in range(rows)]
    fast = TelemetryConverter(preset.scales).rows(samples, times, 2.5e6)
    reference = telemetry_rows(samples, preset.scales, np.array(times), 2.5e6)
    assert np.array(fast).tobytes() == reference.tobytes()
    assert all(type(value) is float for row in fast for value in row)


def test_payloads_are_the_serialized_messages_in_publishing_order():
    messages = SampleMessages()
    rng = np.random.default_rng(5)
    for time_ns in (0, 10_000_000, 123_456_789_012):
        row = rng.uniform(-1e5, 1e5, len(topics.TELEMETRY_FIELDS)).tolist()
        row[F["mode"]] = float(rng.integers(0, 4))
        payloads = messages.payloads(row, time_ns)
        messages.fill(row, time_ns)
        listed = messages.messages(with_clock=True)
        assert [t for t, _ in listed][-1] == topics.CLOCK
        assert len(payloads) == len(listed)
        for (topic, msg), payload in zip(listed, payloads, strict=True):
            assert type(payload) is bytes, topic
            expected = serialize_message(msg)
            assert len(payload) == len(expected), topic
            assert deserialize_message(payload, type(msg)) == msg, topic
            if topic in PADDED:               # rclpy leaves padding bytes undefined
                assert all(a == b or a == 0 for a, b in zip(payload, expected, strict=True))
            else:
                assert payload == expected, topic
        assert messages.messages(with_clock=False) == listed[:-1]
    bit = deserialize_message(payloads[listed.index((topics.BIT_JOINT_STATES, listed[6][1]))],
                              JointState)
    assert list(bit.name) == list(topics.BIT_JOINTS)
    assert bit.header.stamp.sec == 123 and bit.header.stamp.nanosec == 456_789_012
    assert list(bit.effort) == [row[F["tob_nm"]], row[F["wob_n"]]]


def test_templates_zero_their_padding():
    payload = SampleMessages().payloads([1.0] * len(topics.TELEMETRY_FIELDS), 0)[6]
    assert payload[17:20] == b"\x00\x00\x00"  # frame_id "": length 1 + NUL, then 3 pad bytes
