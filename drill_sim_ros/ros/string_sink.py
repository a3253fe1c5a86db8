"""drill/string/torsion: the string profiles of a block as JointState messages.

One message per :class:`~drill_sim_ros.model.depth_profile.StringSample`, stamped like the
samples (simulated time), one joint per depth (``string_0021.1m``, top to bottom): velocity
= angular speed rad/s, effort = torque N m, no position. Published and recorded through the
node's :class:`~drill_sim_ros.ros.sinks.SampleSinks`, so the recording holds the same bytes.
"""

from __future__ import annotations

from typing import Any

from rclpy.serialization import serialize_message
from sensor_msgs.msg import JointState

from drill_sim_ros import topics
from drill_sim_ros.model.depth_profile import StringSample
from drill_sim_ros.model.presets import Preset
from drill_sim_ros.model.telemetry import NS_PER_S
from drill_sim_ros.ros.sinks import SampleSinks


def torsion_message(sample: StringSample, names: list[str]) -> JointState:
    """The JointState of one string profile (``names``: the joint of each depth)."""
    msg = JointState(name=names, velocity=sample.speed_rad_s.tolist(),
                     effort=sample.torque_nm.tolist())
    msg.header.stamp.sec, msg.header.stamp.nanosec = divmod(sample.stamp_ns, NS_PER_S)
    return msg


class StringTorsionSink:
    """Publishes (and records) the string profiles of each block on drill/string/torsion."""

    def __init__(self, sinks: SampleSinks, names: list[str]) -> None:
        self._sinks = sinks
        self._names = names

    def emit(self, samples: list[StringSample]) -> None:
        for sample in samples:
            payload = serialize_message(torsion_message(sample, self._names))
            self._sinks.emit_one(topics.STRING_TORSION, payload, sample.stamp_ns)


def string_topics(preset: Preset, values: dict[str, Any]) -> tuple[str, ...]:
    """The string topics sim_node publishes: drill/string/torsion for a distributed string
    with ``string.rate_hz`` > 0, else none."""
    on = preset.string.distributed and values["string.rate_hz"] > 0
    return (topics.STRING_TORSION,) if on else ()
