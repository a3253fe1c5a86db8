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


class DepthSampler:
    """Samples the torsional profile of a distributed string at fixed depths.

    ``cell_depths_m`` is the depth of every cell (``string_profile()[0]``); at most one
    depth per cell is sampled, so there are ``min(count, cells)`` depths.
    """

    def __init__(self, cell_depths_m: np.ndarray, length_m: float, count: int) -> None:
        check_depth_count(count)
        self._cells_m = np.asarray(cell_depths_m, dtype=float)
        self.depths_m = sample_depths_m(length_m, min(count, self._cells_m.size))
        self.names = [depth_name(d) for d in self.depths_m]

    def sample(self, profile: tuple[np.ndarray, np.ndarray, np.ndarray],
               stamp_ns: int) -> StringSample:
        """``profile`` = ``string_profile()`` (depth m, speed rad/s, torque N m per cell),
        interpolated at :attr:`depths_m` (beyond the first or last cell's middle: its
        value)."""
        _, speed, torque = profile
        return StringSample(stamp_ns, np.interp(self.depths_m, self._cells_m, speed),
                            np.interp(self.depths_m, self._cells_m, torque))
