"""A first-order lag, stepped exactly for an input held over each step (ROS-free, numba).

The one implementation of the lags of the model: the drive's motor torque following its
command (``top_drive``) and the speed the bit law reads following the bit's
(``bit_rock.BitLaw``, ``physical.friction_weakening.response_s``).
"""

from __future__ import annotations

import math

from numba import njit


def lag_share(time_constant: float, dt: float) -> float:
    """The share of the way to its input a lag of ``time_constant`` moves over a step ``dt``
    (the same time unit): 1 - exp(-dt / time_constant); 1 without a lag (0)."""
    return 1.0 if time_constant == 0.0 else -math.expm1(-dt / time_constant)


@njit(cache=True, inline="always")
def lag_step(previous: float, target: float, share: float) -> float:
    """One step of the lag from ``previous`` toward ``target`` by ``share``
    (:func:`lag_share`); exactly ``target`` at a share of 1 (no lag)."""
    if share >= 1.0:
        return target
    return previous + share * (target - previous)
