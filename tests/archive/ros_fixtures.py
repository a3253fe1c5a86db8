"""In-test ROS nodes, each in its own rclpy context, spun on a background executor."""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager

import rclpy
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node
from std_srvs.srv import Trigger

from drill_sim_ros import topics
from drill_sim_ros.ros.spinning import SpinThread
from tests.archive.helpers import wait_for


@contextmanager
def ros_node(name: str) -> Iterator[Node]:
    """A node in a private context, spun in a thread until the block ends."""
    context = rclpy.Context()
    rclpy.init(context=context)
    node = rclpy.create_node(name, context=context)
    executor = SingleThreadedExecutor(context=context)
    executor.add_node(node)
    spinning = SpinThread(executor, context)
    try:
        yield node
    finally:
        spinning.stop()
        node.destroy_node()
        rclpy.try_shutdown(context=context)


def step_sim(node: Node, count: int) -> None:
    """Call sim_node's ~/step ``count`` times, each answered within 30 s (a first call may
    wait for the kernel's compilation on a loaded machine with a cold numba cache)."""
    client = node.create_client(Trigger, f"/{topics.NODE_NAME}/step")
    assert client.wait_for_service(timeout_sec=30), "sim_node's ~/step never appeared"
    for _ in range(count):
        future = client.call_async(Trigger.Request())
        assert wait_for(future.done, 30), "~/step did not answer"
        assert future.result().success, future.result().message
