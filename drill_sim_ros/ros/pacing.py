"""Wall-clock pacing of the simulation, without drift (numpy/numba, no rclpy).

Tick ``i`` (counted from the last :meth:`Pacer.anchor`) is due at ``anchor_ns + i *
period_ns`` on the monotonic clock, so after N s of wall time at real-time factor r the
simulation has published N r seconds to within one period, whatever the jitter: lateness
never accumulates. A tick published more than one period after its deadline is an overrun.

The schedule lives in an int64 array and a ring of recent lateness values, so that the
compiled tick loop of :mod:`drill_sim_ros.ros.engine` keeps it with the same functions
(:func:`due`, :func:`complete`) as :class:`Pacer` does in Python.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

# Pacer.state: the anchor (deadline of tick 0, ns), ticks done since, overruns, lateness
# values recorded (the ring holds the last len(ring) of them), the period (ns)
P_ANCHOR, P_DONE, P_OVERRUNS, P_RECORDED, P_PERIOD = range(5)


class Pacer:
    """Deadlines of a periodic tick on an integer-nanosecond monotonic clock."""

    def __init__(self, period_ns: int, lateness_window: int = 2000) -> None:
        if period_ns <= 0:
            raise ValueError(f"period_ns = {period_ns!r} must be > 0")
        self.state = np.zeros(5, dtype=np.int64)
        self.state[P_PERIOD] = period_ns
        self.ring = np.zeros(lateness_window, dtype=np.int64)

    @property
    def period_ns(self) -> int:
        return int(self.state[P_PERIOD])

    @property
    def overruns(self) -> int:
        return int(self.state[P_OVERRUNS])

    def anchor(self, first_deadline_ns: int) -> None:
        """Restart the schedule: the next tick is due at ``first_deadline_ns``."""
        self.state[P_ANCHOR] = first_deadline_ns
        self.state[P_DONE] = 0

    def deadline_ns(self) -> int:
        """Deadline of the next tick."""
        return int(deadline(self.state))

    def due(self, now_ns: int, limit: int) -> int:
        """Ticks due at ``now_ns`` and not done yet, at most ``limit``."""
        return int(due(self.state, now_ns, limit))

    def complete(self, count: int, now_ns: int) -> None:
        """Record ``count`` ticks published at ``now_ns`` (lateness, overruns)."""
        complete(self.state, self.ring, count, now_ns)

    def lateness_ns(self) -> np.ndarray:
        """A copy of the recent tick lateness, ns, in no particular order (for
        :func:`lateness_percentiles_ms`)."""
        return self.ring[:min(int(self.state[P_RECORDED]), len(self.ring))].copy()


@njit(cache=True, nogil=True)
def deadline(state: np.ndarray) -> int:
    """Deadline of the next tick, ns."""
    return state[P_ANCHOR] + state[P_DONE] * state[P_PERIOD]


@njit(cache=True, nogil=True)
def due(state: np.ndarray, now_ns: int, limit: int) -> int:
    """Ticks due at ``now_ns`` and not done yet, at most ``limit``."""
    behind = now_ns - state[P_ANCHOR]
    if behind < 0:
        return 0
    return min(behind // state[P_PERIOD] + 1 - state[P_DONE], limit)


@njit(cache=True, nogil=True)
def complete(state: np.ndarray, ring: np.ndarray, count: int, now_ns: int) -> None:
    """Record ``count`` ticks published at ``now_ns``: their lateness into ``ring``, the
    overruns (more than one period late)."""
    for _ in range(count):
        late = now_ns - deadline(state)
        ring[state[P_RECORDED] % ring.shape[0]] = late
        state[P_RECORDED] += 1
        if late > state[P_PERIOD]:
            state[P_OVERRUNS] += 1
        state[P_DONE] += 1


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
