"""Expected means of the RGD07 model over a window, from its equations of motion.

Axial (eq. 25 left, in SI): M dv/dt = W_app - W, so over [a, b] of length T
    <W> = W_app - M (v(b) - v(a)) / T          (exact; ~W_app over whole cycles)
Torsional: the top drive turns at Omega_s and the pipe twist theta = PHI_S - PHI is bounded, so
    <Omega_bit> = Omega_s - (theta(b) - theta(a)) / T   (exact; ~Omega_s over whole cycles)
A mean of N samples differs from the time mean by at most the signal's variation between
samples, summed: sum |f(t_i+1) - f(t_i)| / N (exact for signals monotone between samples).
"""

from __future__ import annotations

import math

import numpy as np

from drill_sim_ros import topics
from drill_sim_ros.model.params import RPM_PER_RAD_S, structure
from drill_sim_ros.model.presets import Preset

F = topics.TELEMETRY_INDEX


def axial_mass_kg(preset: Preset) -> float:
    """M of eq. (1) (1/psi in the units of a dimensionless preset)."""
    if preset.physical is not None:
        return structure(preset.physical).mass_kg
    return 1.0 / preset.params.psi


def sampling_bound(values: np.ndarray) -> float:
    """Bound on |sample mean - time mean| over the window of ``values`` (incl. end point)."""
    return float(np.abs(np.diff(values)).sum() / (values.size - 1))


def cycle_window(rows: np.ndarray, setpoint_rpm: float, t_from_s: float) -> tuple[int, int]:
    """Indices (a, b) of the first and last upward crossings of the setpoint after t_from.

    Whole stick-slip cycles; falls back to [t_from, end] when the bit does not cycle.
    """
    t, rpm = rows[:, F["sim_time_s"]], rows[:, F["bit_rpm"]]
    up = np.nonzero((rpm[:-1] < setpoint_rpm) & (rpm[1:] >= setpoint_rpm))[0] + 1
    up = up[t[up] >= t_from_s]
    if up.size >= 2:
        return int(up[0]), int(up[-1])
    return int(np.searchsorted(t, t_from_s)), rows.shape[0] - 1


def wob_expectation(rows: np.ndarray, a: int, b: int, preset: Preset) -> tuple[float, float]:
    """(expected sample mean of WOB over [a, b), tolerance) in N."""
    span_s = rows[b, F["sim_time_s"]] - rows[a, F["sim_time_s"]]
    applied = rows[a:b, F["applied_wob_n"]]
    assert np.all(applied == applied[0]), "applied WOB changed inside the window"
    dv = rows[b, F["rop_m_s"]] - rows[a, F["rop_m_s"]]
    expected = applied[0] - axial_mass_kg(preset) * dv / span_s
    return expected, sampling_bound(rows[a:b + 1, F["wob_n"]]) + 1e-9 * abs(expected)


def rpm_expectation(rows: np.ndarray, a: int, b: int, preset: Preset) -> tuple[float, float]:
    """(expected sample mean of bit rpm over [a, b), tolerance) in rev/min."""
    span_s = rows[b, F["sim_time_s"]] - rows[a, F["sim_time_s"]]
    surface = rows[a:b, F["surface_rpm"]]
    assert np.all(surface == surface[0]), "surface rpm changed inside the window"
    torque_per_rad = preset.scales.torque_nm      # C: twist theta = surface torque / C
    twist = (rows[b, F["surface_torque_nm"]] - rows[a, F["surface_torque_nm"]]) / torque_per_rad
    expected = surface[0] - twist / span_s * RPM_PER_RAD_S
    return expected, sampling_bound(rows[a:b + 1, F["bit_rpm"]]) + 1e-9 * abs(expected)


def telemetry_rows(messages: list) -> np.ndarray:
    """Float64MultiArray telemetry messages -> array (n, len(TELEMETRY_FIELDS))."""
    rows = np.array([m.data for m in messages], dtype=float)
    assert rows.ndim == 2 and rows.shape[1] == len(topics.TELEMETRY_FIELDS)
    assert np.all(np.isfinite(rows))
    return rows


def consecutive(stamps_s: np.ndarray, period_s: float) -> bool:
    """True if the stamps advance by exactly one period each (no lost sample)."""
    return bool(np.all(np.abs(np.diff(stamps_s) - period_s) < 1e-9 * max(1.0, math.fabs(
        stamps_s[-1]))))
