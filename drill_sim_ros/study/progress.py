"""The progress line of a map: points done, rate and time left."""

from __future__ import annotations

import sys
import time

from drill_sim_ros.terminal import StatusLine


class MapProgress:
    """Points done, rate and time left on one terminal line."""

    def __init__(self, enabled: bool) -> None:
        self.line = StatusLine(force=True) if enabled else StatusLine()
        self.started = time.perf_counter()
        self.first: tuple[int, float] | None = None

    def __call__(self, done: int, total: int, _seconds: float) -> None:
        now = time.perf_counter()
        if self.first is None:
            self.first = (done, now)
        d0, t0 = self.first
        rate = (done - d0) / (now - t0) if now > t0 and done > d0 else 0.0
        eta = (total - done) / rate if rate > 0 else float("nan")
        frac = done / total if total else 1.0
        self.line.show(f"[{'#' * int(30 * frac):<30}] {done:,}/{total:,} points  "
                       f"{rate:6.2f} points/s  eta {eta:6.0f} s")

    def say(self, text: str) -> None:
        """One line on stderr (the map's size, its estimate), kept above the live line."""
        self.line.close()
        print(text, file=sys.stderr, flush=True)

    def close(self) -> None:
        self.line.close()
