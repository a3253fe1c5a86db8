"""One way for the command-line tools to stop on SIGINT, SIGTERM and SIGHUP alike.

Outside rclpy (``drill_sim``, ``mcap_reindex``, ``mcap_to_rerun``), :func:`stop_on_signals`
turns SIGINT, SIGTERM and SIGHUP (a closed terminal) into one KeyboardInterrupt, named by the
signal, so every tool finishes or discards its output the same way on all three (SIGINT too
goes through it, so its first step and last resort hold when it lands inside numba's
compiler). rclpy tools keep
rclpy's SIGINT and SIGTERM handling and add :func:`interrupt_on_hangup`.

Python ignores an exception raised while a C callback runs (numba's compiler calls some), so
a tool may also ask for a first step that cannot be lost (``on_stop``: remove what is under
way) and a last resort (``grace_s``: the process ends with status 130 if it is still running
that long after the signal).
"""

from __future__ import annotations

import os
import signal
import sys
import threading
from collections.abc import Callable, Iterator
from contextlib import contextmanager

STOP_SIGNALS = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)
INTERRUPTED_STATUS = 130      # as after Ctrl-C
_STOP_REQUESTED = threading.Event()     # a stop signal arrived within stop_on_signals


def stop_requested() -> bool:
    """Whether a stop signal arrived in the current :func:`stop_on_signals` block: an error
    raised after it is the interruption's (numba's compiler, torn by the KeyboardInterrupt,
    re-raises it as a RuntimeError), not the user's to read as a traceback."""
    return _STOP_REQUESTED.is_set()


def _interrupt(signum: int, frame: object) -> None:
    raise KeyboardInterrupt(signal.Signals(signum).name)


def _stopper(on_stop: Callable[[], None] | None,
             grace_s: float | None) -> Callable[[int, object], None]:
    def stop(signum: int, frame: object) -> None:
        _STOP_REQUESTED.set()
        if on_stop is not None:
            on_stop()
        if grace_s is not None:
            timer = threading.Timer(grace_s, os._exit, args=(INTERRUPTED_STATUS,))
            timer.daemon = True
            timer.start()
        _interrupt(signum, frame)
    return stop


@contextmanager
def stop_on_signals(on_stop: Callable[[], None] | None = None,
                    grace_s: float | None = None) -> Iterator[None]:
    """Within the block, SIGINT, SIGTERM and SIGHUP raise KeyboardInterrupt (named by the signal),
    after ``on_stop()`` and, with ``grace_s``, arming the last resort (module doc). Outside
    the main thread (a test calling a tool in process) nothing changes."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    _STOP_REQUESTED.clear()
    handler = _stopper(on_stop, grace_s)
    previous = {sig: signal.signal(sig, handler) for sig in STOP_SIGNALS}
    hook, sys.unraisablehook = sys.unraisablehook, _quiet_stop(sys.unraisablehook)
    try:
        yield
    finally:
        for sig, old in previous.items():
            signal.signal(sig, old)
        sys.unraisablehook = hook


def _quiet_stop(hook: Callable[[object], None]) -> Callable[[object], None]:
    """``sys.unraisablehook`` that drops the stop's own KeyboardInterrupt where Python could
    not raise it (a callback, e.g. inside numba's compiler: "Exception ignored in ...", a
    traceback the user did not cause); the last resort ends the process then. Once a stop
    was asked for, it drops every such report: objects the interruption tore mid-work (an
    LLVM module numba was compiling) fail in their finalizers. Anything else goes to
    ``hook``."""
    def quiet(unraisable: object) -> None:
        if stop_requested():
            return
        if not isinstance(getattr(unraisable, "exc_value", None), KeyboardInterrupt):
            hook(unraisable)
    return quiet


def interrupt_on_hangup() -> None:
    """SIGHUP raises KeyboardInterrupt, as SIGINT does under rclpy's handler (rclpy tools)."""
    signal.signal(signal.SIGHUP, _interrupt)
