"""The live bridge's stream to a viewer at a ``--connect`` URL, watched while the bridge runs.

The viewer gets a recording stream of its own (same application and recording id as the
.rrd / --serve one), attached to the dashboard's :class:`~drill_sim_ros.viz.recording.Recordings`
while a viewer takes what is sent. Every ``CHECK_PERIOD_S`` (monotonic clock) the link probes
the URL (TCP) and flushes the stream with a short timeout. When nothing listens any more, or
the viewer does not read (a flush timeout, or rerun's client has lost the connection), the link
warns once, detaches the stream and lets it go; when a viewer listens again it opens a new
stream (blueprint and static views re-sent) and says which samples the viewer lacks.

Measured with rerun 0.41: its gRPC client buffers without limit while it has not reached the
server, and while a connected server does not read; it never reconnects by itself; and
``disconnect()`` (also rerun's own exit hook) blocks for as long as a server holds data
unread. So a stream is let go on a daemon thread, no new stream is opened while that thread
still waits, and :meth:`ViewerLink.closing` tells the bridge to exit without waiting for it.
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import rerun as rr

from drill_sim_ros.viz.recording import Recordings, flush_recording, viewer_listening

CHECK_PERIOD_S = 2.0
PROBE_TIMEOUT_S = 0.25     # TCP connect, and the flush; a healthy viewer takes 2 s of data in ms


@dataclass(frozen=True)
class Progress:
    """How far the dashboard has logged: samples and the sim time of the last one, s."""

    samples: int = 0
    last_time_s: float | None = None

    def time_text(self) -> str:
        return "the start" if self.last_time_s is None else f"{self.last_time_s:.3f} s"


class ViewerLink:
    """Attach a viewer's stream while one takes data at ``url``; detach it when none does.

    ``open_stream`` makes a new stream to ``url`` with the blueprint and the static views.
    ``others`` says what keeps the telemetry while the viewer is away (for the warning).
    """

    def __init__(self, url: str, recordings: Recordings,
                 open_stream: Callable[[], rr.RecordingStream], logger: Any,
                 others: str) -> None:
        self.url = url
        self.stream: rr.RecordingStream | None = None
        self._recordings = recordings
        self._open_stream = open_stream
        self._logger = logger
        self._others = others
        self._next_check_s = float("-inf")
        self._seen = Progress()       # at the last check that found the viewer taking data
        self._warned = False          # about the outage going on
        self._letting_go: threading.Thread | None = None

    def poll(self, now_s: float, progress: Progress) -> None:
        """Check the viewer if a check is due (``now_s``: monotonic clock, s)."""
        if now_s < self._next_check_s:
            return
        self._next_check_s = now_s + CHECK_PERIOD_S
        listening = viewer_listening(self.url, PROBE_TIMEOUT_S)
        if self.stream is not None:
            problem = "stopped listening" if not listening else self._not_reading(self.stream)
            if problem is not None:
                self._cut(progress, problem)
        elif listening and not self.closing():
            self._attach(progress)
        elif not listening and not self._warned:
            self._warn(f"no viewer listening at {self.url}: telemetry is not streamed there; "
                       f"{self._others}; the bridge connects when a viewer listens there")
        if self.stream is not None:
            self._seen = progress

    @staticmethod
    def _not_reading(stream: rr.RecordingStream) -> str | None:
        problem = flush_recording(stream, PROBE_TIMEOUT_S)
        return None if problem is None else f"does not read ({problem})"

    def _warn(self, text: str) -> None:
        self._logger.warning(text)
        self._warned = True

    def _attach(self, progress: Progress) -> None:
        self.stream = self._open_stream()
        self._recordings.attach(self.stream)
        if self._warned:
            missed = progress.samples - self._seen.samples
            self._logger.info(
                f"viewer listening at {self.url}: streaming from sim_time "
                f"{progress.time_text()} on, views and layout sent; it lacks up to {missed} "
                f"samples logged meanwhile (sim_time {self._seen.time_text()} to "
                f"{progress.time_text()})")
        self._warned = False

    def _cut(self, progress: Progress, problem: str) -> None:
        self._let_go()
        self._warn(f"the viewer at {self.url} {problem} (noticed at sim_time "
                   f"{progress.time_text()}): telemetry is no longer streamed there; "
                   f"{self._others}; the bridge reconnects when a viewer listens there again")

    def _let_go(self) -> None:
        """Detach the stream and disconnect it on a daemon thread (it may wait on rerun)."""
        stream, self.stream = self.stream, None
        self._recordings.detach(stream)
        self._letting_go = threading.Thread(target=stream.disconnect, daemon=True,
                                            name="viewer_disconnect")
        self._letting_go.start()

    def closing(self) -> bool:
        """True while a stream let go still waits for its viewer (which holds data unread)."""
        return self._letting_go is not None and self._letting_go.is_alive()

    def close(self, timeout_s: float) -> str | None:
        """Flush the viewer's stream for up to ``timeout_s`` and let it go; None, or why not
        everything reached the viewer."""
        if self.stream is None:
            return None
        problem = flush_recording(self.stream, timeout_s)
        self._let_go()
        self._letting_go.join(timeout=timeout_s if problem is None else 0.0)
        return problem
