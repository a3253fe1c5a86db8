"""The string along depth at a few evenly spaced depths, sampled at a low rate.

ROS-free. What sim_node publishes on ``drill/string/torsion`` and the dashboard draws as a
depth x time picture: the torsional angular speed (rad/s) and torque (N m) of the
distributed string, read from :meth:`Simulator.string_profile` (one value per cell of its
delay lines) and linearly interpolated at the middles of ``count`` equal intervals of the
string's length, top to bottom. A lumped string has no profile.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit

from drill_sim_ros.model.errors import ParameterError

MAX_DEPTHS = 64


@dataclass(slots=True)
class StringSample:
    """The torsional string at one instant: ``speed_rad_s`` and ``torque_nm``, shape
    (depths,), at the sampler's ``depths_m``, stamped ``stamp_ns`` of simulated time."""

    stamp_ns: int
    speed_rad_s: np.ndarray
    torque_nm: np.ndarray


def sample_depths_m(length_m: float, count: int) -> np.ndarray:
    """The middles of ``count`` equal intervals of ``[0, length_m]``, m, shape (count,)."""
    return (np.arange(count) + 0.5) * (length_m / count)


def depth_name(depth_m: float) -> str:
    """The joint name of a depth on drill/string/torsion, e.g. ``string_0021.1m``."""
    return f"string_{depth_m:06.1f}m"


def check_depth_count(count: int) -> None:
    """A number of depths outside 1..MAX_DEPTHS is one ParameterError line."""
    if not 1 <= count <= MAX_DEPTHS:
        raise ParameterError(f"string.depths = {count!r} must be an integer in "
                             f"[1, {MAX_DEPTHS}]")


@dataclass(frozen=True)
class Interpolation:
    """Linear interpolation at fixed points ``x`` of values given at fixed nodes ``xp``
    (ascending), as ``np.interp`` computes it, bit for bit: ``(y[hi] - y[lo]) / span *
    offset + y[lo]`` with ``lo`` the last node at or below the point, ``hi`` the next one,
    ``offset = x - xp[lo]`` and ``span = xp[hi] - xp[lo]``; at a node or beyond the ends,
    ``lo = hi`` is that node or the end's, offset 0 and span 1. ``nodes`` are the nodes
    it reads (ascending), ``lo`` and ``hi`` indices into them."""

    nodes: np.ndarray
    lo: np.ndarray
    hi: np.ndarray
    offset: np.ndarray
    span: np.ndarray

    @classmethod
    def at(cls, x: np.ndarray, xp: np.ndarray) -> Interpolation:
        j = np.clip(np.searchsorted(xp, x, side="right") - 1, 0, len(xp) - 1)
        inside = (x > xp[0]) & (x < xp[-1]) & (xp[j] != x)
        hi = np.where(inside, j + 1, j)
        nodes = np.unique(np.concatenate((j, hi)))
        return cls(nodes, np.searchsorted(nodes, j), np.searchsorted(nodes, hi),
                   np.where(inside, x - xp[j], 0.0),
                   np.where(inside, xp[hi] - xp[j], 1.0))

    def __call__(self, y: np.ndarray) -> np.ndarray:
        """The values at the points of ``y`` at :attr:`nodes`."""
        out = np.empty(self.lo.size)
        _interpolate(y, self.lo, self.hi, self.offset, self.span, out)
        return out


@njit(cache=True)
def _interpolate(y: np.ndarray, lo: np.ndarray, hi: np.ndarray, offset: np.ndarray,
                 span: np.ndarray, out: np.ndarray) -> None:
    for i in range(out.size):
        out[i] = (y[hi[i]] - y[lo[i]]) / span[i] * offset[i] + y[lo[i]]


class DepthSampler:
    """Samples the torsional profile of a distributed string at fixed depths.

    ``cell_depths_m`` is the depth of every cell (``string_profile()[0]``); at most one
    depth per cell is sampled, so there are ``min(count, cells)`` depths. Each depth reads
    the two cells around it (:attr:`cells`, indices into the profile's arrays), so a sample
    needs only those (:meth:`Simulator.string_cells`).
    """

    def __init__(self, cell_depths_m: np.ndarray, length_m: float, count: int) -> None:
        check_depth_count(count)
        cells_m = np.asarray(cell_depths_m, dtype=float)
        self.depths_m = sample_depths_m(length_m, min(count, cells_m.size))
        self.names = [depth_name(d) for d in self.depths_m]
        self._interpolation = Interpolation.at(self.depths_m, cells_m)
        self.cells = self._interpolation.nodes

    def sample(self, profile: tuple[np.ndarray, np.ndarray, np.ndarray],
               stamp_ns: int) -> StringSample:
        """``profile`` = ``string_profile()`` (depth m, speed rad/s, torque N m per cell),
        interpolated at :attr:`depths_m` (beyond the first or last cell's middle: its
        value)."""
        _, speed, torque = profile
        return self.sample_cells(speed[self.cells], torque[self.cells], stamp_ns)

    def sample_cells(self, speed_rad_s: np.ndarray, torque_nm: np.ndarray,
                     stamp_ns: int) -> StringSample:
        """The sample of the speeds and torques at :attr:`cells` only."""
        return StringSample(stamp_ns, self._interpolation(speed_rad_s),
                            self._interpolation(torque_nm))
