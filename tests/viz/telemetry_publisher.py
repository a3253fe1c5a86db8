"""A stand-in for sim_node: publishes telemetry rows on /drill/telemetry (reliable)."""

from __future__ import annotations

import time

import numpy as np
import rclpy
from rclpy.context import Context
from rclpy.qos import HistoryPolicy, QoSProfile, ReliabilityPolicy
from std_msgs.msg import Float64MultiArray, MultiArrayDimension

from drill_sim_ros import topics


class TelemetryPublisher:
    """Own context and node; ``publish(rows, rate_hz)`` paces the messages."""

    def __init__(self, topic: str = topics.TELEMETRY, name: str = "viz_test_publisher") -> None:
        self.context = Context()
        rclpy.init(context=self.context)
        self.node = rclpy.create_node(name, context=self.context)
        qos = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=1000,
                         reliability=ReliabilityPolicy.RELIABLE)
        self.publisher = self.node.create_publisher(Float64MultiArray, topic, qos)
        label = ",".join(topics.TELEMETRY_FIELDS)
        n = len(topics.TELEMETRY_FIELDS)
        self._dim = MultiArrayDimension(label=label, size=n, stride=n)

    def wait_for_subscriber(self, timeout_s: float) -> bool:
        deadline = time.monotonic() + timeout_s
        while time.monotonic() < deadline:
            if self.publisher.get_subscription_count() > 0:
                return True
            time.sleep(0.05)
        return False

    def message(self, row: np.ndarray) -> Float64MultiArray:
        msg = Float64MultiArray()
        msg.layout.dim = [self._dim]
        msg.data = row.tolist()
        return msg

    def publish(self, rows: np.ndarray, rate_hz: float) -> None:
        """Publish every row, paced at ``rate_hz`` against the monotonic clock."""
        start = time.monotonic()
        for i, row in enumerate(rows):
            delay = start + i / rate_hz - time.monotonic()
            if delay > 0:
                time.sleep(delay)
            self.publisher.publish(self.message(row))

    def close(self) -> None:
        self.node.destroy_node()
        rclpy.try_shutdown(context=self.context)
