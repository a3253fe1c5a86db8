"""The in-place packing of the string profiles: each payload is what rclpy's serializer makes
of a StringProfile or JointState built field by field, and decodes to the profile's values."""

from __future__ import annotations

import numpy as np
import pytest
from rclpy.serialization import deserialize_message, serialize_message
from sensor_msgs.msg import JointState

from drill_sim_ros.model.depth_profile import StringSample, depth_name, sample_depths_m
from drill_sim_ros.ros import typed
from drill_sim_ros.ros.string_sink import JOINT_STATE, TYPED, profile_packer

STAMPS_NS = (0, 100_000_000, 123_456_789_012, 2**31 * 1_000_000_000 - 1)


def samples(depths: int, seed: int = 7) -> list[StringSample]:
    """Profiles of any values (a negative zero too), one per stamp of STAMPS_NS."""
    rng = np.random.default_rng(seed)
    out = [StringSample(t, rng.uniform(-30.0, 30.0, depths), rng.uniform(-4e4, 4e4, depths))
           for t in STAMPS_NS]
    out[0].speed_rad_s[0] = -0.0
    return out


def expected(message: str, sample: StringSample, depths_m: np.ndarray, frame_id: str):
    sec, nanosec = divmod(sample.stamp_ns, 1_000_000_000)
    if message == TYPED:
        msg = typed.StringProfile(depth_m=list(depths_m), speed_rad_s=list(sample.speed_rad_s),
                                  torque_nm=list(sample.torque_nm))
        msg.header.frame_id = frame_id
    else:
        msg = JointState(name=[depth_name(d) for d in depths_m],
                         velocity=list(sample.speed_rad_s), effort=list(sample.torque_nm))
    msg.header.stamp.sec, msg.header.stamp.nanosec = sec, nanosec
    return msg


@pytest.mark.parametrize("message", [TYPED, JOINT_STATE])
@pytest.mark.parametrize("depths", [1, 3, 64])
@pytest.mark.parametrize("frame_id", ["drill_sim_ros", "rig12"])
def test_payloads_are_the_serialized_messages(message, depths, frame_id) -> None:
    assert typed.PROFILE_AVAILABLE, "drill_sim_msgs is not installed (make venv builds msgs/)"
    depths_m = sample_depths_m(2873.4, depths)
    packer = profile_packer(message, depths_m, [depth_name(d) for d in depths_m], frame_id)
    payloads = [packer.pack(s) for s in samples(depths)]    # one buffer, reused in place
    for sample, payload in zip(samples(depths), payloads, strict=True):
        msg = expected(message, sample, depths_m, frame_id)
        serialized = serialize_message(msg)
        assert type(payload) is bytes and len(payload) == packer.size
        decoded = deserialize_message(payload, type(msg))
        assert decoded == msg
        # rclpy's buffer sometimes runs 8 bytes past the message's last field (a JointState
        # of an odd number of 15-byte names: 84 bytes for 76); its padding bytes are
        # undefined, the packer zeroes them
        assert len(serialized) in (len(payload), len(payload) + 8)
        assert all(a == b or a == 0 for a, b in zip(payload, serialized, strict=False))
        if message == TYPED:
            np.testing.assert_array_equal(decoded.depth_m, depths_m)
            np.testing.assert_array_equal(decoded.speed_rad_s, sample.speed_rad_s)
            np.testing.assert_array_equal(decoded.torque_nm, sample.torque_nm)
            assert decoded.header.frame_id == frame_id
        else:
            assert len(decoded.position) == 0
            np.testing.assert_array_equal(decoded.velocity, sample.speed_rad_s)
            np.testing.assert_array_equal(decoded.effort, sample.torque_nm)
        assert (decoded.header.stamp.sec * 1_000_000_000 + decoded.header.stamp.nanosec
                == sample.stamp_ns)
    first = deserialize_message(payloads[0], type(msg))
    assert np.signbit((first.speed_rad_s if message == TYPED else first.velocity)[0])


def test_the_typed_message_is_smaller_than_the_joint_state() -> None:
    """64 depths: the joint names cost more than the depths they stand for (both laid out by
    hand here, CDR's alignment counted from the end of the 4-byte encapsulation)."""
    depths_m = sample_depths_m(2873.4, 64)
    names = [depth_name(d) for d in depths_m]
    sizes = {m: profile_packer(m, depths_m, names, "drill_sim_ros").size
             for m in (TYPED, JOINT_STATE)}
    # StringProfile: encapsulation 4, stamp 8, frame_id 4 + 14, 2 pad; depth_m: length 4,
    # 512 (8-aligned already); speed_rad_s and torque_nm: length 4, 4 pad, 512 each
    assert sizes[TYPED] == 4 + 8 + 4 + 14 + 2 + (4 + 512) + 2 * (4 + 4 + 512)
    # JointState: encapsulation 4, stamp 8, frame_id "" 4 + 1 + 3 pad; 64 names: count 4,
    # each length 4 + 15 + 1 pad; position: count 0; velocity and effort: count 4, 4 pad, 512
    assert sizes[JOINT_STATE] == 4 + 8 + 8 + 4 + 64 * 20 + 4 + 2 * (4 + 4 + 512)
