"""One ``log_*`` function per view, each sending a batch with ``send_columns``.

Every function takes an explicit :class:`rerun.RecordingStream`; nothing here calls a
global ``rr.init``. Times go on the ``sim_time`` duration timeline (seconds).
2D views store Frame2D.stored positions (scaled per axis, y negated: rerun's y points down);
their lines are drawn one segment per sample, so a view's time range shows a piece of path.
"""

from __future__ import annotations

import itertools

import numpy as np
import rerun as rr

from drill_sim_ros.topics import MODE_NAMES
from drill_sim_ros.viz import entities as ent
from drill_sim_ros.viz.frames import Frame2D
from drill_sim_ros.viz.paper_units import PaperUnits
from drill_sim_ros.viz.plot_values import phase_point
from drill_sim_ros.viz.running_stats import RunningStats
from drill_sim_ros.viz.telemetry import TelemetryBatch
from drill_sim_ros.viz.turns import Turn

ES_COLOR = (148, 103, 189)
PATH_RADIUS_UI = 0.6      # line half-width of the phase portrait's path, UI points
_PALETTE = np.array([(*rgb, 255) for rgb in ent.MODE_COLORS], dtype=np.uint8)


def _index(t: np.ndarray) -> list[rr.TimeColumn]:
    return [rr.TimeColumn(ent.TIMELINE, duration=t)]


def send_scalars(rec: rr.RecordingStream, path: str, t: np.ndarray, values: np.ndarray) -> None:
    """One scalar per time; nothing is sent for an empty batch."""
    if len(t):
        rec.send_columns(path, indexes=_index(t), columns=rr.Scalars.columns(scalars=values))


def send_segments(rec: rr.RecordingStream, path: str, t: np.ndarray, start: np.ndarray,
                  points: np.ndarray, colors: np.ndarray | None = None,
                  radius_ui: float = PATH_RADIUS_UI) -> None:
    """One 2D segment per time, from the previous stored point to this one.

    start: stored point before the batch, shape (2,); points: stored positions, shape (n, 2).
    """
    if not len(t):
        return
    strips = np.stack((np.vstack((start, points[:-1])), points), axis=1)
    columns = rr.LineStrips2D.columns(strips=strips, colors=colors,
                                      radii=np.full(len(t), -radius_ui, dtype=np.float32))
    rec.send_columns(path, indexes=_index(t), columns=columns)


def send_strips(rec: rr.RecordingStream, path: str, t_s: float, strips: list[np.ndarray],
                colors: np.ndarray, radius_ui: float) -> None:
    """Several 2D strips as one row at time ``t_s`` (replacing the previous row on screen)."""
    columns = rr.LineStrips2D.columns(strips=strips, colors=colors,
                                      radii=np.full(len(strips), -radius_ui, dtype=np.float32))
    rec.send_columns(path, indexes=_index(np.array([t_s])),
                     columns=columns.partition([len(strips)]))


def mode_colors(mode: np.ndarray) -> np.ndarray:
    """RGBA (n, 4) per sample from the kernel mode (unknown modes: grey)."""
    idx = np.clip(np.nan_to_num(mode, nan=-1).astype(np.int64), -1, len(MODE_NAMES))
    known = (idx >= 0) & (idx < len(MODE_NAMES))
    colors = np.full((len(mode), 4), 128, dtype=np.uint8)
    colors[known] = _PALETTE[idx[known]]
    return colors


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


class Trail:
    """The last stored point of a line drawn one segment per sample, across batches."""

    def __init__(self) -> None:
        self.last: np.ndarray | None = None

    def segments_from(self, points: np.ndarray) -> np.ndarray:
        """Start point of the batch's first segment (its own first point if none yet)."""
        start = points[0] if self.last is None else self.last
        self.last = points[-1].copy()
        return start


def log_phase_portrait(rec: rr.RecordingStream, batch: TelemetryBatch, units: PaperUnits,
                       frame: Frame2D, trail: Trail) -> None:
    """Fig. 5: the path in (v/v0, omega/omega0), one segment per sample, coloured by mode."""
    points = frame.stored(*phase_point(batch, units))
    send_segments(rec, ent.PHASE_TRAJECTORY, batch.sim_time_s, trail.segments_from(points),
                  points, mode_colors(batch.column("mode")))


def turn_strips(points: np.ndarray, mode: np.ndarray) -> tuple[list[np.ndarray], np.ndarray]:
    """A revolution split where the mode changes: strips (each also holding the next run's
    first point, so the curve is unbroken) and the mode of each strip."""
    cuts = np.flatnonzero(np.diff(mode) != 0.0) + 1
    bounds = [0, *cuts.tolist(), len(points)]
    strips = [points[a:min(b + 1, len(points))] for a, b in itertools.pairwise(bounds)]
    return strips, mode[bounds[:-1]]


def log_turns(rec: rr.RecordingStream, turns: list[Turn], frame: Frame2D,
              previous: list) -> None:
    """Fig. 7: each completed revolution becomes the last turn; the one before it is drawn
    pale. ``previous`` holds the last turn's strips between calls: [strips, modes] or []."""
    for turn in turns:
        strips, modes = turn_strips(frame.stored(turn.x, turn.y), turn.mode)
        if previous:
            pale = mode_colors(previous[1])
            pale[:, :3] = (0.45 * pale[:, :3] + 0.55 * 120.0).astype(np.uint8)
            send_strips(rec, ent.BOTTOM_HOLE_PREVIOUS, turn.end_s, previous[0], pale, 1.0)
        send_strips(rec, ent.BOTTOM_HOLE_LAST, turn.end_s, strips, mode_colors(modes), 1.5)
        previous[:] = [strips, modes]


def log_es_state(rec: rr.RecordingStream, t: np.ndarray, stats: RunningStats,
                 frame: Frame2D, trail: Trail) -> None:
    """Fig. 12: the running (S, E) point's path, where <delta> > 0."""
    ok = np.isfinite(stats.specific_energy) & np.isfinite(stats.drilling_strength)
    if not ok.any():
        return
    points = frame.stored(stats.drilling_strength[ok], stats.specific_energy[ok])
    send_segments(rec, ent.ES_RUNNING, t[ok], trail.segments_from(points), points,
                  np.tile(np.array([[*ES_COLOR, 255]], dtype=np.uint8), (len(points), 1)),
                  radius_ui=1.5)


def log_severity(rec: rr.RecordingStream, t: np.ndarray, stats: RunningStats) -> None:
    """SSI (NaN while the window's mean rpm is 0) and the stick fraction."""
    send_scalars(rec, ent.SSI, t, stats.ssi)
    send_scalars(rec, ent.STICK_FRACTION, t, stats.stick_fraction)
