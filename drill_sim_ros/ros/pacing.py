"""Wall-clock pacing of the simulation, without drift (pure Python, no rclpy).

Tick ``i`` (counted from the last :meth:`Pacer.anchor`) is due at ``anchor_ns + i *
period_ns`` on the monotonic clock, so after N s of wall time at real-time factor r the
simulation has published N r seconds to within one period, whatever the jitter: lateness
never accumulates. A tick published more than one period after its deadline is an overrun.
"""

from __future__ import annotations

import math
from collections import deque

import numpy as np


class Pacer:
    """Deadlines of a periodic tick on an integer-nanosecond monotonic clock."""

    def __init__(self, period_ns: int, lateness_window: int = 2000) -> None:
        if period_ns <= 0:
            raise ValueError(f"period_ns = {period_ns!r} must be > 0")
        self.period_ns = int(period_ns)
        self._anchor_ns = 0
        self._done = 0          # ticks completed since the anchor
        self.overruns = 0
        self._lateness_ns: deque[int] = deque(maxlen=lateness_window)

    def anchor(self, first_deadline_ns: int) -> None:
        """Restart the schedule: the next tick is due at ``first_deadline_ns``."""
        self._anchor_ns = int(first_deadline_ns)
        self._done = 0

    def deadline_ns(self, tick: int | None = None) -> int:
        """Deadline of ``tick`` (default: the next one)."""
        return self._anchor_ns + (self._done if tick is None else tick) * self.period_ns

    def due(self, now_ns: int, limit: int) -> int:
        """Ticks due at ``now_ns`` and not done yet, at most ``limit``."""
        behind = now_ns - self._anchor_ns
        if behind < 0:
            return 0
        return min(behind // self.period_ns + 1 - self._done, limit)

    def complete(self, count: int, now_ns: int) -> None:
        """Record ``count`` ticks published at ``now_ns`` (lateness, overruns)."""
        for _ in range(count):
            late = now_ns - self.deadline_ns()
            self._lateness_ns.append(late)
            if late > self.period_ns:
                self.overruns += 1
            self._done += 1

    def lateness_ns(self) -> list[int]:
        """A copy of the recent tick lateness, ns (for :func:`lateness_percentiles_ms`)."""
        return list(self._lateness_ns)


def lateness_percentiles_ms(lateness_ns: list[int], *percents: float) -> tuple[float, ...]:
    """Percentiles of tick lateness values (ns) in ms; nan for none."""
    if not lateness_ns:
        return tuple(math.nan for _ in percents)
    values = np.percentile(np.array(lateness_ns, dtype=float), percents) * 1e-6
    return tuple(float(v) for v in values)


class RateMeter:
    """Achieved real-time factor: simulated seconds per wall second between two reads."""

    def __init__(self, wall_ns: int, sim_s: float) -> None:
        self._wall_ns, self._sim_s = wall_ns, sim_s
        self.last = math.nan

    def update(self, wall_ns: int, sim_s: float) -> float:
        """The factor since the previous update (nan when no wall time has passed)."""
        dt_ns = wall_ns - self._wall_ns
        if dt_ns > 0:
            self.last = (sim_s - self._sim_s) / (dt_ns * 1e-9)
            self._wall_ns, self._sim_s = wall_ns, sim_s
        return self.last
