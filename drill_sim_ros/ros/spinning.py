"""An executor spun in a thread of its own, stopped without racing its shutdown.

rclpy's ``Executor.shutdown`` destroys the executor's guard condition at once, also while
another thread's ``spin()`` is building its wait set from it: that thread then dies with
``AttributeError: 'NoneType' object has no attribute 'handle'`` (ros2/rclpy#968, open; seen
here in the OPC UA gateway's stop). So the thread spins in short turns until asked to stop,
and the executor is shut down only after the thread has left its last turn.
"""

from __future__ import annotations

import contextlib
import threading

from rclpy.context import Context
from rclpy.executors import Executor, ExternalShutdownException

TURN_S = 0.05          # one spin_once's longest wait: how soon stop() is heard
JOIN_TIMEOUT_S = 5.0   # a callback still running after this is left to the daemon thread


class SpinThread:
    """Spin ``executor`` (whose nodes live in ``context``) in a daemon thread from now on,
    until :meth:`stop` or the context's shutdown."""

    def __init__(self, executor: Executor, context: Context, name: str = "ros-spin") -> None:
        self.executor = executor
        self._context = context
        self._stopping = threading.Event()
        self._thread = threading.Thread(target=self._spin, name=name, daemon=True)
        self._thread.start()

    def _spin(self) -> None:
        with contextlib.suppress(ExternalShutdownException):
            while not self._stopping.is_set() and self._context.ok():
                self.executor.spin_once(timeout_sec=TURN_S)

    def stop(self, timeout_s: float = JOIN_TIMEOUT_S) -> None:
        """Stop spinning, wait (up to ``timeout_s``) for the thread to end, then shut the
        executor down; a thread still in a callback after that keeps the executor (the
        daemon ends with the process). Idempotent."""
        self._stopping.set()
        if self._thread is not threading.current_thread():
            self._thread.join(timeout_s)
        if not self._thread.is_alive():
            self.executor.shutdown(timeout_sec=1.0)
