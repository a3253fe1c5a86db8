"""The bit's path cut into whole revolutions, for the bottom-hole pattern (RGD07 Fig. 7).

A revolution is the samples with the same floor(bit angle / 2 pi); the bit never turns
backwards (eq. 32), so the index only grows. A completed revolution also holds the first
sample of the next one, which closes its curve.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

MAX_PENDING = 200_000   # samples kept for one revolution (a very long stick phase)


@dataclass(frozen=True)
class Turn:
    """One revolution: times (s), plot x, y and mode per sample, shape (m,) each."""

    t: np.ndarray
    x: np.ndarray
    y: np.ndarray
    mode: np.ndarray

    @property
    def end_s(self) -> float:
        return float(self.t[-1])


class TurnTracker:
    """Collects samples across batches and hands back each revolution once it is complete."""

    def __init__(self) -> None:
        self.reset()

    def reset(self) -> None:
        self._rows = np.empty((0, 5))      # t, turn index, x, y, mode

    def add(self, t: np.ndarray, angle_rad: np.ndarray, x: np.ndarray, y: np.ndarray,
            mode: np.ndarray) -> list[Turn]:
        """Append samples (time order); return the revolutions they complete, oldest first."""
        index = np.floor(angle_rad / (2.0 * np.pi))
        rows = np.concatenate((self._rows, np.column_stack((t, index, x, y, mode))))
        starts = np.flatnonzero(np.diff(rows[:, 1]) != 0.0) + 1
        turns, first = [], 0
        for start in starts:
            part = rows[first:start + 1]
            turns.append(Turn(part[:, 0], part[:, 2], part[:, 3], part[:, 4]))
            first = start
        self._rows = rows[first:][-MAX_PENDING:]
        return turns
