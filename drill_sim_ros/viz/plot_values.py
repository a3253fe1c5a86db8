"""What the 2D views plot, in the paper's variables (RGD07 eqs. 21, 34, 48), per sample."""

from __future__ import annotations

import numpy as np

from drill_sim_ros.viz.paper_units import PaperUnits
from drill_sim_ros.viz.telemetry import TelemetryBatch


def _ref(value: float) -> float:
    return value if value > 0.0 else 1.0


def phase_point(batch: TelemetryBatch, units: PaperUnits) -> tuple[np.ndarray, np.ndarray]:
    """Fig. 5: (v/v0, omega/omega0), each shape (n,)."""
    v = units.velocity(batch.column("rop_m_s")) / _ref(units.v0)
    omega = units.omega(batch.column("bit_rpm")) / _ref(units.omega0)
    return v, omega


def pattern_radius(batch: TelemetryBatch, units: PaperUnits) -> np.ndarray:
    """Fig. 7: r = max(delta, 0)/delta0 (the bit above the rock cuts nothing), shape (n,)."""
    delta = units.depth_of_cut(batch.column("depth_of_cut_m"))
    return np.maximum(delta, 0.0) / _ref(units.delta0)


def pattern_point(batch: TelemetryBatch, units: PaperUnits) -> tuple[np.ndarray, np.ndarray]:
    """Fig. 7 as (r cos theta, r sin theta), theta the bit angle."""
    r, theta = pattern_radius(batch, units), batch.column("bit_angle_rad")
    return r * np.cos(theta), r * np.sin(theta)
