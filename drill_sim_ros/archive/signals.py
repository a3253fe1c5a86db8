"""One way for the command-line tools to stop on SIGINT, SIGTERM and SIGHUP alike.

Outside rclpy (``mcap_reindex``, ``mcap_to_rerun``), :func:`stop_on_signals` turns SIGTERM and
SIGHUP (a closed terminal) into the KeyboardInterrupt that SIGINT raises, so every tool
finishes or discards its output the same way on all three. For rclpy tools, whose SIGINT and
SIGTERM handlers shut the context down, :func:`shutdown_on_hangup` adds SIGHUP to them.
"""

from __future__ import annotations

import signal
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import Any

STOP_SIGNALS = (signal.SIGTERM, signal.SIGHUP)


def _interrupt(signum: int, frame: object) -> None:
    raise KeyboardInterrupt(signal.Signals(signum).name)


@contextmanager
def stop_on_signals() -> Iterator[None]:
    """Within the block, SIGTERM and SIGHUP raise KeyboardInterrupt (named by the signal)."""
    previous = {sig: signal.signal(sig, _interrupt) for sig in STOP_SIGNALS}
    try:
        yield
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, handler)


def shutdown_on_hangup(shutdown: Callable[[], Any]) -> None:
    """SIGHUP calls ``shutdown`` (e.g. ``rclpy.try_shutdown``), as rclpy does for SIGTERM."""
    signal.signal(signal.SIGHUP, lambda *_: shutdown())
