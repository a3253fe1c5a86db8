"""Helpers for ROS tests: a fresh rclpy context, bounded spinning, a collecting probe node.

Every wait here ends at a deadline: :func:`spin_until` returns False instead of hanging.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from typing import Any

import rclpy
from rclpy.context import Context
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.qos import HistoryPolicy, QoSProfile, ReliabilityPolicy

from drill_sim_ros.ros.messages import type_of

# Deep enough that a test never loses a sample of a run it inspects.
PROBE_QOS = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=50_000,
                       reliability=ReliabilityPolicy.RELIABLE)


@dataclass
class Ros:
    """A fresh context with its executor; nodes added here are destroyed at the end."""

    context: Context
    executor: SingleThreadedExecutor
    nodes: list[Node] = field(default_factory=list)

    def add(self, node: Node) -> Node:
        self.nodes.append(node)
        self.executor.add_node(node)
        return node

    def remove(self, node: Node) -> None:
        self.executor.remove_node(node)
        self.nodes.remove(node)
        node.destroy_node()

    def spin_until(self, predicate: Callable[[], bool], timeout_s: float) -> bool:
        """Spin until ``predicate()`` holds (True) or ``timeout_s`` passes (False)."""
        deadline = time.monotonic() + timeout_s
        while not predicate():
            remaining = deadline - time.monotonic()
            if remaining <= 0:
                return False
            self.executor.spin_once(timeout_sec=min(0.05, remaining))
        return True

    def spin_for(self, duration_s: float) -> None:
        self.spin_until(lambda: False, duration_s)

    def call(self, node: Node, srv_type: Any, name: str, request: Any,
             timeout_s: float = 10.0) -> Any:
        """Call a service and return its response (AssertionError on timeout)."""
        client = node.create_client(srv_type, name)
        try:
            assert self.spin_until(client.service_is_ready, timeout_s), f"{name} not ready"
            future = client.call_async(request)
            assert self.spin_until(future.done, timeout_s), f"{name} did not answer"
            return future.result()
        finally:
            node.destroy_client(client)


@contextmanager
def ros_context() -> Iterator[Ros]:
    """A fresh rclpy context (DDS on loopback: see tests/conftest.py)."""
    context = Context()
    rclpy.init(context=context)
    ros = Ros(context, SingleThreadedExecutor(context=context))
    try:
        yield ros
    finally:
        for node in list(ros.nodes):
            ros.remove(node)
        ros.executor.shutdown(timeout_sec=1.0)
        rclpy.try_shutdown(context=context)


class Probe(Node):
    """Subscribes to topics and keeps (receive time, message) per topic, in order."""

    def __init__(self, context: Context, topic_names: Iterable[str], raw: bool = False,
                 name: str = "probe") -> None:
        super().__init__(name, context=context)
        self.received: dict[str, list[tuple[float, Any]]] = {}
        for topic in topic_names:
            self.received[topic] = []
            self.create_subscription(type_of(topic), topic, self._keeper(topic), PROBE_QOS,
                                     raw=raw)

    def _keeper(self, topic: str) -> Callable[[Any], None]:
        store = self.received[topic]
        return lambda msg: store.append((time.monotonic(), msg))

    def messages(self, topic: str) -> list[Any]:
        return [msg for _, msg in self.received[topic]]

    def count(self, topic: str) -> int:
        return len(self.received[topic])


def overrides(**values: Any) -> list[Parameter]:
    """Parameter overrides from keyword arguments (``__`` stands for ``.``)."""
    return [Parameter(name.replace("__", "."), value=value) for name, value in values.items()]
