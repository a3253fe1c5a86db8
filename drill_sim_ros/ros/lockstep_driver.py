"""Drive a sim_node in command-triggered lockstep from a Python policy (a ROS node).

The sim (``lockstep:=true -p lockstep_trigger:=command``) advances exactly one period per
message on ``drill/cmd/top_drive`` and then publishes the state at the end of that period.
:class:`LockstepDriver` closes the loop: for every sample it receives it calls
``policy(sample)`` and publishes the :class:`Command` it returns, stamped with the sample's
stamp. The sample is, by ``sample_topic``, one SI telemetry row (``drill/telemetry``,
``TELEMETRY_FIELDS`` order: the whole truth, for tests and tools) or the rig's surface
measurement (``drill/surface/measured`` as a
:class:`~drill_sim_ros.control.command.SurfaceMeasurement`: what a controller may read).
The sample topics are latched (reliable, transient local, depth 1), so the first sample the
driver receives is the latest the sim published (t = 0 at the start of a run), whenever the
driver starts; it answers that one too, and sends nothing before it (the handshake of
docs/control-loop.md). Nothing is lost: both directions are reliable, and each side waits
for the other. The command topic is volatile, so an answer sent before the sim's
subscription has matched the driver's writer would be lost (discovery announces a node's
publications and subscriptions apart, so the sim's sample can arrive first): the driver
holds each answer until its writer has matched the sim's subscription and every other the
graph shows (:meth:`LockstepDriver.sim_listens`).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np
from rclpy.clock import Clock, ClockType
from rclpy.node import Node
from rclpy.qos import HistoryPolicy, QoSProfile, ReliabilityPolicy
from rclpy.serialization import deserialize_message
from sensor_msgs.msg import JointState
from std_msgs.msg import Float64MultiArray

from drill_sim_ros import topics
from drill_sim_ros.control.command import Command, SurfaceMeasurement
from drill_sim_ros.model.telemetry import NS_PER_S, TELEMETRY_INDEX
from drill_sim_ros.ros.messages import LATEST_SAMPLE_QOS, stamp, stamp_ns

__all__ = ["LOCKSTEP_QOS", "Command", "LockstepDriver", "Policy", "top_drive_command"]

LOCKSTEP_QOS = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=1000,
                          reliability=ReliabilityPolicy.RELIABLE)
_TIME = TELEMETRY_INDEX["sim_time_s"]
MATCH_POLL_S = 0.01          # how often a held answer looks for the sim's subscription
MATCH_WAIT_S = 10.0          # then it goes out anyway (a sim under another node name)

# A policy: the sample it reacts to -> the command.
Policy = Callable[[Any], Command]


def top_drive_command(command: Command, reacts_to_ns: int) -> JointState:
    """The drill/cmd/top_drive message of ``command`` (None is sent as NaN)."""
    def value(x: float | None) -> float:
        return math.nan if x is None else float(x)
    msg = JointState(name=list(topics.COMMAND_JOINTS),
                     velocity=[value(command.speed_rad_s), math.nan],
                     effort=[value(command.motor_torque_nm), value(command.wob_n)])
    msg.header.stamp = stamp(reacts_to_ns)
    return msg


def telemetry_sample(raw: bytes) -> tuple[np.ndarray, int]:
    """A drill/telemetry payload: (SI row, stamp ns)."""
    row = np.asarray(deserialize_message(raw, Float64MultiArray).data)
    return row, round(row[_TIME] * NS_PER_S)


def measured_sample(raw: bytes) -> tuple[SurfaceMeasurement, int]:
    """A drill/surface/measured payload (joints top_drive, quill, hook_load, wob_estimate:
    MEASURED_JOINTS): (measurement, stamp ns)."""
    msg = deserialize_message(raw, JointState)
    time_ns = stamp_ns(msg.header.stamp)
    return SurfaceMeasurement(time_s=time_ns / 1e9, drive_speed_rad_s=msg.velocity[0],
                              motor_torque_nm=msg.effort[0],
                              string_torque_nm=msg.effort[1], hook_load_n=msg.effort[2],
                              applied_wob_estimate_n=msg.effort[3]), time_ns


SAMPLE_DECODERS = {topics.TELEMETRY: telemetry_sample, topics.SURFACE_MEASURED: measured_sample}


class LockstepDriver(Node):
    """Runs ``periods`` periods of a sim in command lockstep (0: until stopped): answers the
    first sample it receives (``first_sample``: t = 0 on a fresh sim) and the next
    ``periods - 1``; with ``keep``, ``rows`` keeps every sample after the first (their raw
    payloads in ``payloads``); ``done`` once the last one is in."""

    def __init__(self, policy: Policy, periods: int, name: str = "lockstep_driver",
                 sample_topic: str = topics.TELEMETRY, keep: bool = True,
                 **node_kwargs: Any) -> None:
        super().__init__(name, **node_kwargs)
        self._policy = policy
        self.periods = periods
        self.sent = 0
        self.received = 0
        self.keep = keep
        self.rows: list[Any] = []
        self.payloads: list[bytes] = []
        self.first_sample: Any = None
        self._reacted_ns = -1
        self._decode = SAMPLE_DECODERS[sample_topic]
        self._pub = self.create_publisher(JointState, topics.node_relative(
            topics.CMD_TOP_DRIVE), LOCKSTEP_QOS)
        msg_type = JointState if sample_topic == topics.SURFACE_MEASURED else Float64MultiArray
        self._sub = self.create_subscription(msg_type, topics.node_relative(sample_topic),
                                             self._on_sample, LATEST_SAMPLE_QOS, raw=True)
        self._held: JointState | None = None    # an answer waiting for the sim to listen
        self._held_polls = 0
        self._listened_at = -1                  # the matched count sim_listens() last held at
        self._match_timer = self.create_timer(  # wall time: /clock stands while lockstep waits
            MATCH_POLL_S, self._send_held, clock=Clock(clock_type=ClockType.STEADY_TIME),
            autostart=False)

    @property
    def done(self) -> bool:
        return self.periods > 0 and self.received >= self.periods

    def _on_sample(self, raw: bytes) -> None:
        sample, time_ns = self._decode(raw)
        if time_ns <= self._reacted_ns:
            return                          # answered already
        if self._reacted_ns < 0:
            self.first_sample = sample
            self._command(sample, time_ns)
            return
        self.received += 1
        if self.keep:
            self.rows.append(sample)
            self.payloads.append(raw)
        if self.periods <= 0 or self.received < self.periods:
            self._command(sample, time_ns)

    def sim_listens(self) -> bool:
        """Whether the command writer has matched the sim's subscription (a node named
        ``topics.NODE_NAME`` in this namespace) and every other subscription the graph shows
        on the topic: only then does an answer reach the sim."""
        readers = self.get_subscriptions_info_by_topic(self._pub.topic_name)
        sim = any(r.node_name == topics.NODE_NAME and r.node_namespace == self.get_namespace()
                  for r in readers)
        return sim and self._pub.get_subscription_count() >= len(readers)

    def _sim_still_listens(self) -> bool:
        """sim_listens(), asked of the graph again only when the matched count moved."""
        count = self._pub.get_subscription_count()
        if count != self._listened_at:
            self._listened_at = count if self.sim_listens() else -1
        return self._listened_at >= 0

    def _command(self, sample: Any, time_ns: int) -> None:
        command = self._policy(sample)
        self._reacted_ns = time_ns
        message = top_drive_command(command, time_ns)
        if self._held is None and self._sim_still_listens():
            self._publish(message)
            return
        self._held, self._held_polls = message, 0
        self._match_timer.reset()

    def _send_held(self) -> None:
        self._held_polls += 1
        if self._held is not None and (self._sim_still_listens()
                                       or self._held_polls * MATCH_POLL_S >= MATCH_WAIT_S):
            message, self._held = self._held, None
            self._publish(message)
        if self._held is None:
            self._match_timer.cancel()

    def _publish(self, message: JointState) -> None:
        self._pub.publish(message)
        self.sent += 1
