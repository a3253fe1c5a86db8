"""An independent /drill/telemetry subscriber (own context, background executor thread)."""

from __future__ import annotations

import numpy as np
import rclpy
from rclpy.context import Context
from rclpy.executors import SingleThreadedExecutor
from rclpy.qos import HistoryPolicy, QoSProfile, ReliabilityPolicy
from std_msgs.msg import Float64MultiArray

from drill_sim_ros.ros.spinning import SpinThread


class TelemetryListener:
    """Collects every telemetry row it receives on ``topic``."""

    def __init__(self, topic: str) -> None:
        self.context = Context()
        rclpy.init(context=self.context)
        self.node = rclpy.create_node("viz_test_listener", context=self.context)
        qos = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=1000,
                         reliability=ReliabilityPolicy.RELIABLE)
        self.rows: list[np.ndarray] = []
        self.node.create_subscription(Float64MultiArray, topic, self._on_msg, qos)
        self.executor = SingleThreadedExecutor(context=self.context)
        self.executor.add_node(self.node)
        self._spinning = SpinThread(self.executor, self.context, "viz-test-listener")

    def _on_msg(self, msg: Float64MultiArray) -> None:
        self.rows.append(np.array(msg.data, dtype=np.float64))

    def close(self) -> np.ndarray:
        """Stop spinning; return the rows received, shape (n, fields)."""
        self._spinning.stop()
        self.node.destroy_node()
        rclpy.try_shutdown(context=self.context)
        return np.stack(self.rows) if self.rows else np.empty((0, 0))
