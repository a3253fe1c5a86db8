"""Sliding-window statistics over sim time, carried across batches.

The window of sample i holds the samples j with t_i - L < t_j <= t_i. Means come from
cumulative sums, maxima and minima from a sparse table (O(n log n), vectorised), so that
a 100k-sample recording and a 25-sample live batch take the same path.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Windows:
    """Samples (tail + new) and, per new sample i, its window rows starts[i]:ends[i]."""

    t: np.ndarray
    x: np.ndarray          # shape (len(t), width)
    starts: np.ndarray
    ends: np.ndarray

    def mean(self, col: int) -> np.ndarray:
        sums = np.concatenate(([0.0], np.cumsum(self.x[:, col])))
        return (sums[self.ends] - sums[self.starts]) / (self.ends - self.starts)

    def maximum(self, col: int) -> np.ndarray:
        return window_max(self.x[:, col], self.starts, self.ends)

    def minimum(self, col: int) -> np.ndarray:
        return -window_max(-self.x[:, col], self.starts, self.ends)


def window_max(x: np.ndarray, starts: np.ndarray, ends: np.ndarray) -> np.ndarray:
    """max(x[starts[i]:ends[i]]) for every i (all windows non-empty)."""
    lengths = ends - starts
    levels = [x]                      # levels[j][i] = max(x[i : i + 2**j])
    while 2 ** len(levels) <= lengths.max():
        prev, half = levels[-1], 2 ** (len(levels) - 1)
        levels.append(np.maximum(prev[:-half], prev[half:]))
    order = np.floor(np.log2(lengths)).astype(np.int64)
    out = np.empty(len(starts))
    for j in np.unique(order):
        sel = order == j
        level = levels[j]
        out[sel] = np.maximum(level[starts[sel]], level[ends[sel] - 2 ** j])
    return out


class SlidingWindow:
    """Keeps the last ``length_s`` seconds of ``width`` channels between batches."""

    def __init__(self, length_s: float, width: int) -> None:
        if not length_s > 0.0:
            raise ValueError(f"window length {length_s!r} s must be > 0")
        self.length_s = float(length_s)
        self.width = width
        self.reset()

    def reset(self) -> None:
        self._t = np.empty(0)
        self._x = np.empty((0, self.width))

    @property
    def last_time(self) -> float | None:
        return float(self._t[-1]) if len(self._t) else None

    def extend(self, t: np.ndarray, x: np.ndarray) -> Windows:
        """Append samples (t non-decreasing, after the tail); return their windows."""
        t_all = np.concatenate((self._t, t))
        x_all = np.concatenate((self._x, x.reshape(len(t), self.width)))
        ends = np.arange(len(self._t) + 1, len(t_all) + 1)
        starts = np.searchsorted(t_all, t_all[ends - 1] - self.length_s, side="right")
        starts = np.minimum(starts, ends - 1)
        keep = np.searchsorted(t_all, t_all[-1] - self.length_s, side="right") if len(t) else 0
        self._t, self._x = t_all[keep:], x_all[keep:]
        return Windows(t_all, x_all, starts, ends)
