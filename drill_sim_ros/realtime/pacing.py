"""Wall-clock pacing of the simulation, without drift (plain Python, no ROS).

Tick ``i`` (counted from the last :meth:`Pacer.anchor`) is due at ``anchor_ns + i *
period_ns`` on the monotonic clock, so after N s of wall time at real-time factor r the
simulation has published N r seconds to within one period, whatever the jitter: lateness
never accumulates. A tick published more than one period after its deadline is an overrun.
"""

from __future__ import annotations

import math

import numpy as np


class Pacer:
    """Deadlines of a periodic tick on an integer-nanosecond monotonic clock."""

    def __init__(self, period_ns: int, lateness_window: int = 2000) -> None:
        if period_ns <= 0:
            raise ValueError(f"period_ns = {period_ns!r} must be > 0")
        self.period_ns = period_ns
        self.overruns = 0
        self._anchor_ns = 0
        self._done = 0                   # ticks done since the anchor
        self._recorded = 0               # lateness values recorded (the ring keeps the last)
        self._ring = [0] * lateness_window   # a list: numpy's item assignment costs more

    def anchor(self, first_deadline_ns: int) -> None:
        """Restart the schedule: the next tick is due at ``first_deadline_ns``."""
        self._anchor_ns = first_deadline_ns
        self._done = 0

    def deadline_ns(self) -> int:
        """Deadline of the next tick."""
        return self._anchor_ns + self._done * self.period_ns

    def due(self, now_ns: int, limit: int) -> int:
        """Ticks due at ``now_ns`` and not done yet, at most ``limit``."""
        behind = now_ns - self._anchor_ns
        if behind < 0:
            return 0
        return min(behind // self.period_ns + 1 - self._done, limit)

    def complete(self, count: int, now_ns: int) -> None:
        """Record ``count`` ticks published at ``now_ns``: their lateness, the overruns (more
        than one period late)."""
        for _ in range(count):
            late = now_ns - self.deadline_ns()
            self._ring[self._recorded % len(self._ring)] = late
            self._recorded += 1
            self.overruns += late > self.period_ns
            self._done += 1

    def lateness_ns(self) -> np.ndarray:
        """A copy of the recent tick lateness, ns, in no particular order."""
        return np.array(self._ring[:min(self._recorded, len(self._ring))], dtype=np.int64)


def lateness_percentiles_ms(lateness_ns: np.ndarray, *percents: float) -> tuple[float, ...]:
    """Percentiles of tick lateness values (ns) in ms; nan for none."""
    if len(lateness_ns) == 0:
        return tuple(math.nan for _ in percents)
    values = np.percentile(np.asarray(lateness_ns, dtype=float), percents) * 1e-6
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
