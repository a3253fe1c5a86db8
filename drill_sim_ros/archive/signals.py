"""One way for the command-line tools to stop on SIGINT, SIGTERM and SIGHUP alike.

Outside rclpy (``mcap_reindex``, ``mcap_to_rerun``), :func:`stop_on_signals` turns SIGTERM and
SIGHUP (a closed terminal) into the KeyboardInterrupt that SIGINT raises, so every tool
finishes or discards its output the same way on all three. rclpy tools keep rclpy's SIGINT
and SIGTERM handling and add :func:`interrupt_on_hangup`.
"""

from __future__ import annotations

import signal
from collections.abc import Iterator
from contextlib import contextmanager

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


def interrupt_on_hangup() -> None:
    """SIGHUP raises KeyboardInterrupt, as SIGINT does under rclpy's handler (rclpy tools)."""
    signal.signal(signal.SIGHUP, _interrupt)
