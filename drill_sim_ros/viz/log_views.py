"""One ``log_*`` function per view, each sending a batch with ``send_columns``.

Every function takes an explicit :class:`rerun.RecordingStream`; nothing here calls a
global ``rr.init``. Times go on the ``sim_time`` duration timeline (seconds).
2D views use image coordinates (y down), so their stored y is the plotted quantity negated.
"""

from __future__ import annotations

import numpy as np
import rerun as rr

from drill_sim_ros.topics import MODE_NAMES
from drill_sim_ros.viz import entities as ent
from drill_sim_ros.viz.paper_units import PaperUnits
from drill_sim_ros.viz.running_stats import RunningStats
from drill_sim_ros.viz.telemetry import TelemetryBatch

_PALETTE = np.array([(*rgb, 255) for rgb in ent.MODE_COLORS], dtype=np.uint8)


def _index(t: np.ndarray) -> list[rr.TimeColumn]:
    return [rr.TimeColumn(ent.TIMELINE, duration=t)]


def send_scalars(rec: rr.RecordingStream, path: str, t: np.ndarray, values: np.ndarray) -> None:
    """One scalar per time; nothing is sent for an empty batch."""
    if len(t):
        rec.send_columns(path, indexes=_index(t), columns=rr.Scalars.columns(scalars=values))


def send_points(rec: rr.RecordingStream, path: str, t: np.ndarray, x: np.ndarray,
                y: np.ndarray, colors: np.ndarray | None = None) -> None:
    """One 2D point per time at (x, y) in plot axes (stored as (x, -y))."""
    if not len(t):
        return
    positions = np.column_stack((x, -y))
    columns = rr.Points2D.columns(positions=positions, colors=colors)
    rec.send_columns(path, indexes=_index(t), columns=columns)


def mode_colors(mode: np.ndarray) -> np.ndarray:
    """RGBA (n, 4) per sample from the kernel mode (unknown modes: grey)."""
    idx = np.clip(np.nan_to_num(mode, nan=-1).astype(np.int64), -1, len(MODE_NAMES))
    known = (idx >= 0) & (idx < len(MODE_NAMES))
    colors = np.full((len(mode), 4), 128, dtype=np.uint8)
    colors[known] = _PALETTE[idx[known]]
    return colors


def _ref(value: float) -> float:
    return value if value > 0.0 else 1.0


def log_time_series(rec: rr.RecordingStream, batch: TelemetryBatch) -> None:
    """WOB, applied WOB, TOB, surface torque, ROP, bit and surface rpm, mode."""
    t = batch.sim_time_s
    for path, field, factor, _ in ent.SCALAR_SERIES:
        send_scalars(rec, path, t, batch.column(field) * factor)


def log_phase_markers(rec: rr.RecordingStream, batch: TelemetryBatch) -> None:
    """Markers on the rpm plot at stuck samples and on the WOB plot when off bottom."""
    t, mode = batch.sim_time_s, batch.column("mode")
    for path, field, factor, marked, _ in ent.PHASE_MARKERS:
        sel = mode == marked
        send_scalars(rec, path, t[sel], batch.column(field)[sel] * factor)


def log_phase_portrait(rec: rr.RecordingStream, batch: TelemetryBatch,
                       units: PaperUnits) -> None:
    """Fig. 5: omega/omega0 against v/v0, coloured by mode."""
    x = units.velocity(batch.column("rop_m_s")) / _ref(units.v0)
    y = units.omega(batch.column("bit_rpm")) / _ref(units.omega0)
    send_points(rec, ent.PHASE_TRAJECTORY, batch.sim_time_s, x, y,
                mode_colors(batch.column("mode")))


def log_bottom_hole(rec: rr.RecordingStream, batch: TelemetryBatch, units: PaperUnits) -> None:
    """Fig. 7: polar plot, r = max(delta, 0)/delta0 at theta = bit angle mod 2 pi."""
    r = np.maximum(units.depth_of_cut(batch.column("depth_of_cut_m")), 0.0) / _ref(units.delta0)
    theta = np.mod(batch.column("bit_angle_rad"), 2.0 * np.pi)
    send_points(rec, ent.BOTTOM_HOLE_PATTERN, batch.sim_time_s, r * np.cos(theta),
                r * np.sin(theta), mode_colors(batch.column("mode")))


def log_es_state(rec: rr.RecordingStream, t: np.ndarray, stats: RunningStats) -> None:
    """Fig. 12: the running (E, S) point, where <delta> > 0."""
    ok = np.isfinite(stats.specific_energy) & np.isfinite(stats.drilling_strength)
    send_points(rec, ent.ES_RUNNING, t[ok], stats.drilling_strength[ok],
                stats.specific_energy[ok])


def log_severity(rec: rr.RecordingStream, t: np.ndarray, stats: RunningStats) -> None:
    """SSI (NaN while the window's mean rpm is 0) and the stick fraction."""
    send_scalars(rec, ent.SSI, t, stats.ssi)
    send_scalars(rec, ent.STICK_FRACTION, t, stats.stick_fraction)
