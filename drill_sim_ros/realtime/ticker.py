"""The sim node's tick thread and the lock it shares with the executor (no ROS).

The executor used to run the tick as an rcl timer, and rebuilt its wait set on every wake-up
(about 1 ms of CPU per 10 ms tick). A :class:`Ticker` instead calls its ``work`` function on
a daemon thread and sleeps for whatever time ``work`` asks for, so the executor wakes only for
commands, services, parameters and the 1 Hz timers. :class:`HandoffLock` keeps the two
threads from touching the simulation at once without letting a busy ticker starve them.
"""

from __future__ import annotations

import contextlib
import logging
import os
import select
import threading
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager

_log = logging.getLogger(__name__)
# Waits up to this long are a plain sleep, which costs less than select() (about 15 us of CPU
# per wake-up here); a wake() during one takes effect when it ends.
SHORT_WAIT_S = 0.02


class HandoffLock:
    """A mutex that a looping background thread hands over to waiting callbacks.

    Callbacks take it with :meth:`urgent`, the ticker with :meth:`acquire_background`. A callback
    holds the gate while it waits, and the ticker passes the gate before each acquisition, so
    a callback waits for at most the batch in progress, however fast the ticker loops.
    """

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._gate = threading.Lock()

    @contextmanager
    def urgent(self) -> Iterator[None]:
        with self._gate:                 # one waiter at a time
            self._lock.acquire()
        try:
            yield
        finally:
            self._lock.release()

    def acquire_background(self) -> None:
        """The ticker's acquisition (then :meth:`release`): it passes the gate first, so a
        waiting callback goes first. Plain calls: a generator context manager costs tens of
        microseconds per tick on a cold cache."""
        self._gate.acquire()
        self._gate.release()
        self._lock.acquire()

    def release(self) -> None:
        self._lock.release()


class Ticker:
    """Calls ``work()`` on a daemon thread until :meth:`stop`.

    ``work`` returns the seconds to wait before its next call: None waits until :meth:`wake`,
    a longer wait ends early on :meth:`wake`, one of at most ``SHORT_WAIT_S`` does not,
    0 calls it again at once (free run; CPython hands the GIL to the executor's thread
    within its switch interval). An exception from ``work`` goes to ``on_error``; the
    loop goes on unless ``on_error`` returns False.
    """

    def __init__(self, work: Callable[[], float | None],
                 on_error: Callable[[Exception], bool], name: str = "ticker") -> None:
        self._work = work
        self._on_error = on_error
        # A self-pipe, not a threading.Event, for the waits a wake() must cut short: Event.wait
        # runs a Condition's Python code and allocates a lock on every call (measured: about
        # 1 point of CPU at 100 Hz on a cold cache). Short waits are a plain sleep.
        self._wake_fd, self._wake_write_fd = os.pipe()
        os.set_blocking(self._wake_fd, False)
        os.set_blocking(self._wake_write_fd, False)
        self._stopping = False
        self._thread = threading.Thread(target=self._loop, name=name, daemon=True)

    def start(self) -> None:
        self._thread.start()

    def wake(self) -> None:
        """Call ``work`` now (the schedule or the state changed); nothing once stopped."""
        if self._wake_fd >= 0:
            with contextlib.suppress(OSError):   # full of wakes already, or closed by stop()
                os.write(self._wake_write_fd, b"w")

    def stop(self, timeout_s: float = 5.0) -> None:
        """End the loop after the current call and wait for it (idempotent)."""
        self._stopping = True
        if self._wake_fd < 0:
            return
        self.wake()
        if self._thread.is_alive() and self._thread is not threading.current_thread():
            self._thread.join(timeout_s)
            if self._thread.is_alive():
                _log.error("%s did not stop within %g s", self._thread.name, timeout_s)
                return                   # the thread may still select() on the fd
        if not self._thread.is_alive():
            os.close(self._wake_fd)
            os.close(self._wake_write_fd)
            self._wake_fd = -1

    def _loop(self) -> None:
        fd, wait = self._wake_fd, [self._wake_fd]
        while not self._stopping:
            try:
                delay = self._work()
            except Exception as exc:
                delay = None
                if not self._on_error(exc):
                    self._stopping = True
            if self._stopping:
                return
            if delay is not None and delay <= SHORT_WAIT_S:
                time.sleep(delay)   # 0 still yields the GIL; a wake meanwhile waits for this tick
            elif select.select(wait, (), (), delay)[0]:
                os.read(fd, 4096)               # all the wakes so far at once
