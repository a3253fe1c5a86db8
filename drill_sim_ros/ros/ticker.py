"""The sim node's tick thread and the lock it shares with the executor (pure Python, no rclpy).

The executor used to run the tick as an rcl timer, and rebuilt its wait set on every wake-up
(about 1 ms of CPU per 10 ms tick). A :class:`Ticker` instead calls its ``work`` function on
a daemon thread and sleeps for whatever time ``work`` asks for, so the executor wakes only for
commands, services, parameters and the 1 Hz timers. :class:`HandoffLock` keeps the two
threads from touching the simulation at once without letting a busy ticker starve them.
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Callable, Iterator
from contextlib import contextmanager

_log = logging.getLogger(__name__)


class HandoffLock:
    """A mutex that a looping background thread hands over to waiting callbacks.

    Callbacks take it with :meth:`urgent`, the ticker with :meth:`background`. A callback
    holds the gate while it waits, and the ticker passes the gate before each acquisition, so
    a callback waits for at most the batch in progress, however fast the ticker loops.
    """

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._gate = threading.Lock()

    @contextmanager
    def urgent(self) -> Iterator[None]:
        with self._gate:
            self._lock.acquire()
        try:
            yield
        finally:
            self._lock.release()

    @contextmanager
    def background(self) -> Iterator[None]:
        with self._gate:
            pass
        with self._lock:
            yield


class Ticker:
    """Calls ``work()`` on a daemon thread until :meth:`stop`.

    ``work`` returns the seconds to wait before its next call: None waits until :meth:`wake`,
    0 calls it again at once (free run; CPython hands the GIL to the executor's thread
    within its switch interval). An exception from ``work`` goes to ``on_error``; the
    loop goes on unless ``on_error`` returns False.
    """

    def __init__(self, work: Callable[[], float | None],
                 on_error: Callable[[Exception], bool], name: str = "ticker") -> None:
        self._work = work
        self._on_error = on_error
        self._wake = threading.Event()
        self._stopping = False
        self._thread = threading.Thread(target=self._loop, name=name, daemon=True)

    def start(self) -> None:
        self._thread.start()

    def wake(self) -> None:
        """Call ``work`` now (the schedule or the state changed)."""
        self._wake.set()

    def stop(self, timeout_s: float = 5.0) -> None:
        """End the loop after the current call and wait for it (idempotent)."""
        self._stopping = True
        self._wake.set()
        if self._thread.is_alive() and self._thread is not threading.current_thread():
            self._thread.join(timeout_s)
            if self._thread.is_alive():
                _log.error("%s did not stop within %g s", self._thread.name, timeout_s)

    def _loop(self) -> None:
        while not self._stopping:
            self._wake.clear()
            delay = self._call()
            if self._stopping:
                return
            if delay is None or delay > 0:
                self._wake.wait(delay)

    def _call(self) -> float | None:
        try:
            return self._work()
        except Exception as exc:
            if not self._on_error(exc):
                self._stopping = True
            return None
