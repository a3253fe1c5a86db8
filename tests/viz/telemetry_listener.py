"""An independent /drill/telemetry subscriber (own context, background executor thread)."""

from __future__ import annotations

import threading

import numpy as np
import rclpy
from rclpy.context import Context
from rclpy.executors import ExternalShutdownException, SingleThreadedExecutor
from rclpy.qos import HistoryPolicy, QoSProfile, ReliabilityPolicy
from std_msgs.msg import Float64MultiArray


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
        self._thread = threading.Thread(target=self._spin, daemon=True)
        self._thread.start()

    def _on_msg(self, msg: Float64MultiArray) -> None:
        self.rows.append(np.array(msg.data, dtype=np.float64))

    def _spin(self) -> None:
        try:
            while self.context.ok():
                self.executor.spin_once(timeout_sec=0.1)
        except ExternalShutdownException:
            pass

    def close(self) -> np.ndarray:
        """Stop spinning; return the rows received, shape (n, fields)."""
        rclpy.try_shutdown(context=self.context)
        self._thread.join(timeout=5)
        self.node.destroy_node()
        return np.stack(self.rows) if self.rows else np.empty((0, 0))
