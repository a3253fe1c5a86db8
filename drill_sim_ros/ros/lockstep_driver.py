"""Drive a sim_node in command-triggered lockstep from a Python policy (a ROS node).

The sim (``lockstep:=true -p lockstep_trigger:=command``) advances exactly one period per
message on ``drill/cmd/top_drive`` and then publishes the state at the end of that period.
:class:`LockstepDriver` closes the loop: for every telemetry sample it receives it calls
``policy(row)`` (one SI row, ``TELEMETRY_FIELDS`` order) and publishes the :class:`Command`
it returns, stamped with the sample's stamp. Its first command (when the sim's subscription
matches) reacts to the sim's initial state at t = 0, so the loop starts whether or not the
t = 0 sample arrived.
Nothing is lost: both directions are reliable and deep, and each side waits for the other.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
from rclpy.node import Node
from rclpy.qos import HistoryPolicy, QoSProfile, ReliabilityPolicy
from rclpy.serialization import deserialize_message
from sensor_msgs.msg import JointState
from std_msgs.msg import Float64MultiArray

from drill_sim_ros import topics
from drill_sim_ros.model.telemetry import NS_PER_S, TELEMETRY_INDEX
from drill_sim_ros.ros.messages import stamp

LOCKSTEP_QOS = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=1000,
                          reliability=ReliabilityPolicy.RELIABLE)
_TIME = TELEMETRY_INDEX["sim_time_s"]


@dataclass(frozen=True)
class Command:
    """What one drill/cmd/top_drive message commands; None commands nothing."""

    speed_rad_s: float | None = None       # speed setpoint (kinematic and speed modes)
    motor_torque_nm: float | None = None   # motor torque (torque mode)
    wob_n: float | None = None             # applied WOB


# A policy: the sample it reacts to (None: the initial state at t = 0) -> the command.
Policy = Callable[[np.ndarray | None], Command]


def top_drive_command(command: Command, reacts_to_ns: int) -> JointState:
    """The drill/cmd/top_drive message of ``command`` (None is sent as NaN)."""
    def value(x: float | None) -> float:
        return math.nan if x is None else float(x)
    msg = JointState(name=list(topics.COMMAND_JOINTS),
                     velocity=[value(command.speed_rad_s), math.nan],
                     effort=[value(command.motor_torque_nm), value(command.wob_n)])
    msg.header.stamp = stamp(reacts_to_ns)
    return msg


class LockstepDriver(Node):
    """Runs ``periods`` periods of a sim in command lockstep; ``rows`` keeps every sample
    received (their raw payloads in ``payloads``); ``done`` once the last one is in."""

    def __init__(self, policy: Policy, periods: int, name: str = "lockstep_driver",
                 **node_kwargs: Any) -> None:
        super().__init__(name, **node_kwargs)
        self._policy = policy
        self.periods = periods
        self.sent = 0
        self.rows: list[np.ndarray] = []
        self.payloads: list[bytes] = []
        self._reacted_ns = -1
        self._pub = self.create_publisher(JointState, topics.node_relative(
            topics.CMD_TOP_DRIVE), LOCKSTEP_QOS)
        self.create_subscription(Float64MultiArray, topics.node_relative(topics.TELEMETRY),
                                 self._on_sample, LOCKSTEP_QOS, raw=True)
        self._start = self.create_timer(0.05, self._start_when_matched)

    @property
    def done(self) -> bool:
        return len(self.rows) >= self.periods

    def _start_when_matched(self) -> None:
        """The first command reacts to the initial state (t = 0)."""
        if self._pub.get_subscription_count() == 0 or self._reacted_ns >= 0:
            return
        self.destroy_timer(self._start)
        self._command(None, 0)

    def _on_sample(self, raw: bytes) -> None:
        row = np.asarray(deserialize_message(raw, Float64MultiArray).data)
        stamp_ns = round(row[_TIME] * NS_PER_S)
        if stamp_ns <= self._reacted_ns:
            return                       # the t = 0 sample, already reacted to
        self.rows.append(row)
        self.payloads.append(raw)
        if len(self.rows) < self.periods:
            self._command(row, stamp_ns)

    def _command(self, row: np.ndarray | None, stamp_ns: int) -> None:
        command = self._policy(row)
        self._reacted_ns = stamp_ns
        self._pub.publish(top_drive_command(command, stamp_ns))
        self.sent += 1
