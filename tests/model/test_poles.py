"""The matrix pencil finds the poles of damped exponentials, heavy damping included.

The records are synthetic sums of damped cosines with known poles (plus an offset), so
the expected damping ratios are the ones the records were made with.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from drill_sim_ros.model import poles

SAMPLE_HZ = 200.0


def ring_down(modes_hz: list[float], zetas: list[float], seconds: float) -> np.ndarray:
    """3 + sum of A_k exp(-zeta_k w_k t) cos(w_k sqrt(1 - zeta_k^2) t + phase_k)."""
    t = np.arange(0.0, seconds, 1.0 / SAMPLE_HZ)
    y = np.full(t.size, 3.0)
    for i, (f, zeta) in enumerate(zip(modes_hz, zetas, strict=True)):
        w = 2 * math.pi * f
        y += 0.5**i * np.exp(-zeta * w * t) * np.cos(w * math.sqrt(1 - zeta**2) * t + 0.7 * i)
    return y


def test_damping_ratios_of_a_heavily_damped_record() -> None:
    """zeta 0.4 (two cycles to decay), 0.08 and 0.03: each found to 1e-6 through the
    difference, the low-pass and the decimation; a frequency with no mode finds none."""
    modes_hz, zetas = [0.3, 1.1, 2.4], [0.4, 0.08, 0.03]
    sigma_max = max(2 * math.pi * f * z for f, z in zip(modes_hz, zetas, strict=True))
    plan = poles.plan_decimation(SAMPLE_HZ, max(modes_hz), 1.5 / sigma_max)
    assert plan.every > 1 and plan.cutoff_hz > max(modes_hz)
    found = poles.damping_ratios(ring_down(modes_hz, zetas, 30.0), SAMPLE_HZ, plan,
                                 [*modes_hz, 1.7], len(modes_hz))
    assert found[:3] == pytest.approx(zetas, rel=1e-6)
    assert found[3] is None


def test_an_undamped_record_gives_zero() -> None:
    modes_hz = [0.2, 0.7, 1.3]
    plan = poles.plan_decimation(SAMPLE_HZ, max(modes_hz), math.inf)
    found = poles.damping_ratios(ring_down(modes_hz, [0.0, 0.0, 0.0], 60.0), SAMPLE_HZ,
                                 plan, modes_hz, len(modes_hz))
    assert all(abs(z) < 1e-8 for z in found)
