"""SpinThread: an executor spun in its own thread, stopped before the executor shuts down
(ros2/rclpy#968: a shutdown during another thread's spin killed the gateway's thread)."""

from __future__ import annotations

import threading
import time

import pytest
import rclpy
from rclpy.executors import SingleThreadedExecutor

from drill_sim_ros.ros.spinning import TURN_S, SpinThread

pytestmark = pytest.mark.ros


def test_it_serves_callbacks_until_stopped_then_the_thread_ends_and_nothing_runs() -> None:
    context = rclpy.Context()
    rclpy.init(context=context)
    errors: list[BaseException] = []
    hook, threading.excepthook = threading.excepthook, lambda a: errors.append(a.exc_value)
    try:
        node = rclpy.create_node("spin_thread_test", context=context)
        ticks: list[float] = []
        node.create_timer(0.01, lambda: ticks.append(time.monotonic()))
        executor = SingleThreadedExecutor(context=context)
        executor.add_node(node)
        spinning = SpinThread(executor, context, "spin-test")
        end = time.monotonic() + 10.0
        while len(ticks) < 20:
            assert time.monotonic() < end, f"{len(ticks)} timer callbacks in 10 s"
            time.sleep(0.01)
        started = time.monotonic()
        spinning.stop()
        assert time.monotonic() - started < 1.0 + TURN_S     # heard within a turn or so
        assert not any(t.name == "spin-test" for t in threading.enumerate())
        count = len(ticks)
        time.sleep(0.1)                  # ten periods of the timer: none runs any more
        assert len(ticks) == count
        spinning.stop()                  # again: nothing to do, no error
        node.destroy_node()
    finally:
        threading.excepthook = hook
        rclpy.try_shutdown(context=context)
    assert errors == []
