"""Static parts of the dashboard: series styles, reference geometry, the run description.

Logged once per recording with ``static=True`` on an explicit RecordingStream. 2D geometry
is stored with y negated, like the data (image coordinates, y down).
"""

from __future__ import annotations

import numpy as np
import rerun as rr

from drill_sim_ros.topics import MODE_NAMES
from drill_sim_ros.viz import entities as ent
from drill_sim_ros.viz.paper_units import PaperUnits

GREY = (150, 150, 150)
_LINE_COLORS = {ent.WOB_BIT: (31, 119, 180), ent.WOB_APPLIED: (90, 90, 90),
                ent.TORQUE_BIT: (44, 160, 44), ent.TORQUE_SURFACE: (90, 90, 90),
                ent.ROP: (140, 86, 75), ent.RPM_BIT: (31, 119, 180),
                ent.RPM_SURFACE: (90, 90, 90), ent.MODE: (127, 127, 127)}


def _flip(points: np.ndarray) -> np.ndarray:
    return np.column_stack((points[:, 0], -points[:, 1]))


def log_series_styles(rec: rr.RecordingStream) -> None:
    """Legend names and colours of every time series; the mode as a step line."""
    for path, _, _, name in ent.SCALAR_SERIES:
        step = "StepAfter" if path == ent.MODE else None
        rec.log(path, rr.SeriesLines(names=name, colors=_LINE_COLORS[path],
                                     interpolation_mode=step), static=True)
    for path, _, _, mode, name in ent.PHASE_MARKERS:
        rec.log(path, rr.SeriesPoints(names=name, colors=ent.MODE_COLORS[mode],
                                      markers="circle", marker_sizes=3.0), static=True)
    rec.log(ent.SSI, rr.SeriesLines(names="SSI (max-min)/(2 mean) bit rpm",
                                    colors=(214, 39, 40)), static=True)
    rec.log(ent.STICK_FRACTION, rr.SeriesLines(names="stick fraction",
                                               colors=(148, 103, 189)), static=True)


def _axes(x_max: float, y_max: float, x_label: str, y_label: str) -> rr.LineStrips2D:
    strips = [np.array([[0.0, 0.0], [x_max, 0.0]]), np.array([[0.0, 0.0], [0.0, y_max]])]
    return rr.LineStrips2D([_flip(s) for s in strips], labels=[x_label, y_label],
                           colors=GREY, radii=rr.Radius.ui_points(1.0))


def log_phase_reference(rec: rr.RecordingStream) -> None:
    """Axes of Fig. 5 and the trivial solution at (1, 1)."""
    rec.log(ent.PHASE_REFERENCE, _axes(3.0, 2.5, "v / v0 (axial)", "omega / omega0"),
            static=True)
    rec.log(f"{ent.PHASE_REFERENCE}/trivial",
            rr.Points2D(_flip(np.array([[1.0, 1.0]])), labels="trivial", colors=GREY,
                        radii=rr.Radius.ui_points(5.0)), static=True)


def log_bottom_hole_reference(rec: rr.RecordingStream, units: PaperUnits) -> None:
    """Circles at delta = delta0 and 2 delta0, and the blade directions at tau = 0."""
    angle = np.linspace(0.0, 2.0 * np.pi, 181)
    circle = np.column_stack((np.cos(angle), np.sin(angle)))
    rays = [np.array([[0.0, 0.0], [2.0 * np.cos(a), 2.0 * np.sin(a)]])
            for a in 2.0 * np.pi * np.arange(units.n) / units.n]
    strips = [_flip(circle), _flip(2.0 * circle)] + [_flip(r) for r in rays]
    labels = ["delta0", "2 delta0"] + [""] * len(rays)
    rec.log(ent.BOTTOM_HOLE_REFERENCE,
            rr.LineStrips2D(strips, labels=labels, colors=GREY,
                            radii=rr.Radius.ui_points(0.75)), static=True)


def log_es_reference(rec: rr.RecordingStream, units: PaperUnits) -> None:
    """Friction line E = 1 - beta + beta S (eq. 50), the cutting point and the trivial state."""
    s0 = units.w0 / units.delta0 if units.delta0 > 0 else 1.0
    s_max = max(5.0, 3.0 * s0)
    s = np.array([1.0, s_max])
    line = np.column_stack((s, units.friction_line(s)))
    rec.log(ent.ES_FRICTION_LINE,
            rr.LineStrips2D([_flip(line)], labels=f"friction line, beta = {units.beta:.3g}",
                            colors=GREY, radii=rr.Radius.ui_points(1.0)), static=True)
    points = np.array([[1.0, 1.0], [s0, units.t0 / units.delta0 if units.delta0 > 0 else 1.0]])
    rec.log(ent.ES_POINTS, rr.Points2D(_flip(points), labels=["cutting point", "trivial"],
                                       colors=GREY, radii=rr.Radius.ui_points(5.0)),
            static=True)
    rec.log(f"{ent.ES_DIAGRAM}/axes", _axes(s_max, units.friction_line(s_max), "S", "E"),
            static=True)


def info_markdown(units: PaperUnits, window_s: float) -> str:
    """The run description shown next to the plots."""
    colors = ", ".join(f"{n} {ent.MODE_COLOR_NAMES[i]}"
                       for i, n in enumerate(MODE_NAMES))
    return "\n".join([
        f"## drill_sim_ros run (preset `{units.preset}`)",
        f"- 2D views use the preset's scales: t* = {units.scales.time_s:.4g} s, "
        f"L* = {units.scales.length_m:.4g} m; beta = {units.beta:.3g}.",
        f"- Phase portrait: omega/omega0 vs v/v0, trivial v0 = {units.v0:.4g}, "
        f"omega0 = {units.omega0:.4g} (RGD07 Fig. 5). Colours: {colors}.",
        f"- Bottom-hole pattern: r = max(delta, 0)/delta0 (delta0 = {units.delta0:.4g}) at "
        "the bit angle (Fig. 7).",
        f"- E-S and severity: sliding window of {window_s:.3g} s of sim time (eq. 48, 50).",
    ])


def log_static(rec: rr.RecordingStream, units: PaperUnits, window_s: float) -> None:
    """Everything static, once per recording."""
    log_series_styles(rec)
    log_phase_reference(rec)
    log_bottom_hole_reference(rec, units)
    log_es_reference(rec, units)
    rec.log(ent.INFO, rr.TextDocument(info_markdown(units, window_s),
                                      media_type=rr.MediaType.MARKDOWN), static=True)
