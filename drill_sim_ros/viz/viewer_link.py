"""The live bridge's stream to a viewer at a ``--connect`` URL, watched while the bridge runs.

The viewer gets a recording stream of its own (same application and recording id as the
.rrd / --serve one), attached to the dashboard's :class:`~drill_sim_ros.viz.recording.Recordings`
while a viewer accepts TCP connections at the URL. Every ``CHECK_PERIOD_S`` (monotonic clock)
the link probes the URL. When nothing listens any more it warns once, detaches the stream and
drops it (rerun 0.41's gRPC client has no memory limit, and never reconnects by itself); when
a viewer listens again it opens a new stream (blueprint and static views re-sent) and says
which samples the viewer misses.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import rerun as rr

from drill_sim_ros.viz.recording import Recordings, close_recording, viewer_listening

CHECK_PERIOD_S = 2.0
PROBE_TIMEOUT_S = 0.25     # a refused connection on loopback answers in microseconds


@dataclass(frozen=True)
class Progress:
    """How far the dashboard has logged: samples and the sim time of the last one, s."""

    samples: int = 0
    last_time_s: float | None = None

    def time_text(self) -> str:
        return "the start" if self.last_time_s is None else f"{self.last_time_s:.3f} s"


class ViewerLink:
    """Attach a viewer's stream while one listens at ``url``; detach it when none does.

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
        self._seen = Progress()       # at the last check that found a viewer listening
        self._warned = False          # about the outage going on

    def poll(self, now_s: float, progress: Progress) -> None:
        """Probe the URL if a check is due (``now_s``: monotonic clock, s)."""
        if now_s < self._next_check_s:
            return
        self._next_check_s = now_s + CHECK_PERIOD_S
        listening = viewer_listening(self.url, PROBE_TIMEOUT_S)
        if listening and self.stream is None:
            self._attach(progress)
        elif not listening and self.stream is not None:
            self._detach(progress)
        elif not listening and not self._warned:
            self._warn(f"no viewer listening at {self.url}: telemetry is not streamed there; "
                       f"{self._others}; the bridge connects when a viewer listens there")
        if listening:
            self._seen = progress

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
                f"samples logged while none listened (sim_time {self._seen.time_text()} to "
                f"{progress.time_text()})")
        self._warned = False

    def _detach(self, progress: Progress) -> None:
        stream, self.stream = self.stream, None
        self._recordings.detach(stream)
        stream.disconnect()           # rerun's client has given up on the lost server: no wait
        self._warn(f"the viewer at {self.url} stopped listening (noticed at sim_time "
                   f"{progress.time_text()}): telemetry is no longer streamed there; "
                   f"{self._others}; the bridge reconnects when a viewer listens there again")

    def close(self, timeout_s: float) -> str | None:
        """Flush and detach the viewer's stream (if attached); None or the reason it could
        not be flushed."""
        stream, self.stream = self.stream, None
        if stream is None:
            return None
        self._recordings.detach(stream)
        return close_recording(stream, timeout_s)
