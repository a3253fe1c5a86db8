"""What the dashboard should hold for given telemetry rows, computed independently.

Written from the issue and the paper (RGD07 eqs. 21, 34, 48), not from drill_sim_ros.viz:
display units, the dimensionless 2D coordinates and brute-force window statistics.
"""

from __future__ import annotations

import math

import numpy as np

from drill_sim_ros import topics
from drill_sim_ros.model.analysis import severity, trivial_solution
from drill_sim_ros.model.presets import Preset

F = topics.TELEMETRY_INDEX
# entity path -> (telemetry field, factor SI -> display unit)
SCALARS = {
    "/timeseries/wob/bit": ("wob_n", 1e-3),
    "/timeseries/wob/applied": ("applied_wob_n", 1e-3),
    "/timeseries/torque/bit": ("tob_nm", 1e-3),
    "/timeseries/torque/surface": ("surface_torque_nm", 1e-3),
    "/timeseries/rop/bit": ("rop_m_s", 3600.0),
    "/timeseries/rpm/bit": ("bit_rpm", 1.0),
    "/timeseries/rpm/bha": ("bha_rpm", 1.0),
    "/timeseries/rpm/surface": ("surface_rpm", 1.0),
    "/timeseries/mode/mode": ("mode", 1.0),
}
VIEW_ORIGINS = {"/timeseries/wob", "/timeseries/torque", "/timeseries/rop", "/timeseries/rpm",
                "/timeseries/mode", "/phase_portrait", "/bottom_hole", "/es_diagram",
                "/severity", "/info"}
STUCK, OFF_BOTTOM = 2, 3
MIN_MAX = 5      # rerun's AggregationPolicy.MinMax: min and max of the samples in a pixel


def phase_portrait(rows: np.ndarray, preset: Preset) -> np.ndarray:
    """(v/v0, -omega/omega0), Fig. 5 (y down; the view scales each axis)."""
    triv, ts, ls = trivial_solution(preset.params), preset.scales.time_s, preset.scales.length_m
    v = rows[:, F["rop_m_s"]] * ts / ls
    omega = rows[:, F["bit_rpm"]] * 2.0 * math.pi / 60.0 * ts
    return np.column_stack((v / triv.v, -omega / triv.omega))


def bottom_hole(rows: np.ndarray, preset: Preset) -> np.ndarray:
    """(r cos theta, -r sin theta), r = max(delta, 0)/delta0, Fig. 7 (y down)."""
    delta0 = trivial_solution(preset.params).depth_of_cut
    r = np.maximum(rows[:, F["depth_of_cut_m"]] / preset.scales.length_m, 0.0) / delta0
    theta = rows[:, F["bit_angle_rad"]] % (2.0 * math.pi)
    return np.column_stack((r * np.cos(theta), -r * np.sin(theta)))


def revolutions(rows: np.ndarray) -> list[np.ndarray]:
    """Row indices of each whole bit revolution (angle in [2 pi k, 2 pi (k + 1))), each
    closed by the first row of the next one; the last, unfinished one is left out."""
    turn = np.floor(rows[:, F["bit_angle_rad"]] / (2.0 * math.pi))
    out, first = [], 0
    for i in range(1, len(rows)):
        if turn[i] != turn[i - 1]:
            out.append(np.arange(first, i + 1))
            first = i
    return out


def stored_points(data: object) -> np.ndarray:
    """Every stored 2D position of an entity (points or strips, temporal and static)."""
    parts = []
    for columns in (data.columns, data.static):
        for row in columns.get("Points2D:positions", []):
            parts.append(np.array(row, dtype=np.float64).reshape(-1, 2))
        for row in columns.get("LineStrips2D:strips", []):
            parts += [np.array(s, dtype=np.float64).reshape(-1, 2) for s in row]
    return np.vstack(parts)


def window(rows: np.ndarray, i: int, window_s: float) -> np.ndarray:
    t = rows[:, F["sim_time_s"]]
    return rows[(t > t[i] - window_s) & (t <= t[i])]


def severity_at(rows: np.ndarray, i: int, window_s: float) -> tuple[float, float]:
    """(SSI, stick fraction) over the window ending at sample i."""
    w = window(rows, i, window_s)
    ssi = severity(w[:, F["bit_rpm"]], 1.0).ssi
    return ssi, float(np.mean(w[:, F["mode"]] == STUCK))


def es_at(rows: np.ndarray, i: int, window_s: float, preset: Preset) -> tuple[float, float]:
    """(E, S) from the SI form of eq. 48: E = 2<T>/(eps a^2 <d>), S = <W>/(zeta eps a <d>)."""
    phys = preset.physical
    w = window(rows, i, window_s)
    d = w[:, F["depth_of_cut_m"]].mean()
    eps, a = phys.intrinsic_specific_energy_pa, phys.bit_radius_m
    energy = 2.0 * w[:, F["tob_nm"]].mean() / (eps * a * a * d)
    strength = w[:, F["wob_n"]].mean() / (phys.zeta * eps * a * d)
    return energy, strength
