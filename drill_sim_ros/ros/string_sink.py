"""The string profiles of a block, packed in place and published on one of two topics.

One message per :class:`~drill_sim_ros.model.depth_profile.StringSample`, stamped like the
samples (simulated time), one value per depth, top to bottom. ``string.message`` chooses:

- ``typed`` (the default): ``drill/typed/string/torsion``, drill_sim_msgs/StringProfile:
  header (frame_id = the rig), ``depth_m``, ``speed_rad_s``, ``torque_nm``;
- ``joint_state``: ``drill/string/torsion``, sensor_msgs/JointState for tools that read only
  standard messages: one joint per depth (``string_0021.1m``), velocity = angular speed
  rad/s, effort = torque N m, no position.

Either way the message's bytes are a CDR template written once (:mod:`drill_sim_ros.ros.cdr`:
the depths or joint names, the lengths, the padding), and each profile only writes its stamp
and its two arrays into that preallocated buffer (:class:`ProfilePacker`): no message object,
no serialization on the step path. Published and recorded through the node's
:class:`~drill_sim_ros.ros.sinks.SampleSinks`, so the recording holds the same bytes.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from rclpy.publisher import Publisher

from drill_sim_ros import topics
from drill_sim_ros.model.depth_profile import StringSample
from drill_sim_ros.model.presets import Preset
from drill_sim_ros.model.telemetry import NS_PER_S
from drill_sim_ros.ros.cdr import Layout, joint_state_layout, string_profile_layout
from drill_sim_ros.ros.frame import aligned_index
from drill_sim_ros.ros.sinks import SampleSinks

TYPED, JOINT_STATE = "typed", "joint_state"
MESSAGES = (TYPED, JOINT_STATE)           # the choices of string.message
# the payload starts 4 bytes into its float64 buffer: the CDR body's float64 values (8-aligned
# after the 4-byte encapsulation header) are then elements of that buffer
_LEAD = 4


class ProfilePacker:
    """The CDR payload of a profile message, kept in one preallocated buffer.

    ``layout``: the message's template whose last doubles are the speeds, then the torques,
    one per depth, each array contiguous; ``leading``: the values of the doubles before them
    (StringProfile's depths), written once.
    """

    def __init__(self, layout: Layout, leading: np.ndarray) -> None:
        if layout.stamp is None:
            raise ValueError("a profile layout has a header stamp")
        depths = (len(layout.doubles) - len(leading)) // 2
        self.size = len(layout.template)
        self._store = np.zeros(-(-(_LEAD + self.size) // 8), dtype=np.float64)
        raw = self._store.view(np.uint8)
        self._payload = raw[_LEAD:_LEAD + self.size]
        self._payload[:] = np.frombuffer(layout.template, np.uint8)
        doubles, lead = layout.doubles, len(leading)
        self._run(doubles[:lead])[:] = leading
        self._speed = self._run(doubles[lead:lead + depths])
        self._torque = self._run(doubles[lead + depths:])
        at = aligned_index(_LEAD + layout.stamp, 4)
        self._stamp = self._store.view(np.int32)[at:at + 2]     # sec, nanosec (< 2**31)

    def _run(self, offsets: tuple[int, ...]) -> np.ndarray:
        """The view of the buffer holding the doubles at ``offsets`` (consecutive)."""
        if not offsets:
            return self._store[:0]
        first = aligned_index(_LEAD + offsets[0], 8)
        if list(offsets) != [offsets[0] + 8 * i for i in range(len(offsets))]:
            raise ValueError("a profile array is not contiguous in its layout")
        return self._store[first:first + len(offsets)]

    def pack(self, sample: StringSample) -> bytes:
        """The payload of ``sample`` (the buffer rewritten in place, then copied out)."""
        self._speed[:] = sample.speed_rad_s
        self._torque[:] = sample.torque_nm
        self._stamp[:] = divmod(sample.stamp_ns, NS_PER_S)
        return self._payload.tobytes()


def profile_packer(message: str, depths_m: np.ndarray, names: list[str],
                   frame_id: str) -> ProfilePacker:
    """The packer of ``string.message`` (``typed``: StringProfile framed ``frame_id``;
    ``joint_state``: JointState of ``names``) for profiles at ``depths_m``."""
    if message == TYPED:
        return ProfilePacker(string_profile_layout(frame_id, len(depths_m)),
                             np.asarray(depths_m, dtype=np.float64))
    return ProfilePacker(joint_state_layout(tuple(names), with_position=False), np.zeros(0))


class StringProfileSink:
    """Publishes (and records) the string profiles of each block on ``topic``."""

    def __init__(self, sinks: SampleSinks, topic: str, publishers: dict[str, Publisher],
                 packer: ProfilePacker) -> None:
        self._sinks = sinks
        self._topic = topic
        self._publishers = publishers
        self._packer = packer

    def emit(self, samples: list[StringSample]) -> None:
        for sample in samples:
            self._sinks.emit_one(self._topic, self._packer.pack(sample), sample.stamp_ns,
                                 self._publishers)


def string_message(values: dict[str, Any], typed_available: bool) -> str:
    """The message the profiles go out as: ``string.message``, or ``joint_state`` when
    drill_sim_msgs is not installed."""
    return values["string.message"] if typed_available else JOINT_STATE


def string_topics(preset: Preset, values: dict[str, Any],
                  typed_available: bool) -> tuple[str, ...]:
    """The string topic sim_node publishes: for a distributed string with
    ``string.rate_hz`` > 0, drill/typed/string/torsion or drill/string/torsion (see
    :func:`string_message`); else none."""
    if not (preset.string.distributed and values["string.rate_hz"] > 0):
        return ()
    typed = string_message(values, typed_available) == TYPED
    return (topics.TYPED_STRING_TORSION if typed else topics.STRING_TORSION,)
