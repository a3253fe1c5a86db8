"""Static parts of the dashboard: series styles, reference geometry, the run description.

Logged once per recording with ``static=True`` on an explicit RecordingStream. 2D geometry
goes through the view's Frame2D, like the data (scaled per axis, y negated: y points down).
"""

from __future__ import annotations

import numpy as np
import rerun as rr

from drill_sim_ros.topics import MODE_NAMES
from drill_sim_ros.viz import entities as ent
from drill_sim_ros.viz.frames import Frame2D, ViewFrames, es_reference
from drill_sim_ros.viz.paper_units import PaperUnits

GREY = (150, 150, 150)
GRID = (150, 150, 150, 60)
GRID_STRONG = (150, 150, 150, 140)
LABEL = (55, 55, 55)         # label box; rerun writes the text in a contrasting colour
_LINE_COLORS = {ent.WOB_BIT: (31, 119, 180), ent.WOB_APPLIED: (170, 170, 170),
                ent.TORQUE_BIT: (44, 160, 44), ent.TORQUE_SURFACE: (170, 170, 170),
                ent.ROP: (196, 130, 100), ent.RPM_BIT: (31, 119, 180),
                ent.RPM_BHA: (23, 190, 207),
                ent.RPM_SURFACE: (170, 170, 170), ent.MODE: (200, 200, 200)}
SSI_COLOR, STICK_COLOR = (214, 39, 40), (148, 103, 189)
# Several samples sharing a pixel column keep both their min and their max: the peaks a
# user judges stick-slip by stay on screen at any width.
AGGREGATION = "MinMax"


def log_series_styles(rec: rr.RecordingStream) -> None:
    """Names, colours and min/max aggregation of every time series; mode as a step line."""
    for path, _, _, name in ent.SCALAR_SERIES:
        step = "StepAfter" if path == ent.MODE else None
        rec.log(path, rr.SeriesLines(names=name, colors=_LINE_COLORS[path],
                                     interpolation_mode=step,
                                     aggregation_policy=AGGREGATION), static=True)
    for path, _, _, mode, name in ent.PHASE_MARKERS:
        rec.log(path, rr.SeriesPoints(names=name, colors=ent.MODE_COLORS[mode],
                                      markers="circle", marker_sizes=3.0), static=True)
    rec.log(ent.SSI, rr.SeriesLines(names="SSI (max-min)/(2 mean) bit rpm", colors=SSI_COLOR,
                                    aggregation_policy=AGGREGATION), static=True)
    rec.log(ent.STICK_FRACTION, rr.SeriesLines(names="stick fraction", colors=STICK_COLOR,
                                               aggregation_policy=AGGREGATION), static=True)


def log_labels(rec: rr.RecordingStream, path: str, xy: list[tuple[float, float]],
               labels: list[str], static: bool = True) -> None:
    """Labels at stored positions (invisible anchor points): rerun puts a strip's label at
    its centre, so every label here is placed on purpose; ``static``: once per recording,
    else at the stream's current time."""
    rec.log(path, rr.Points2D(np.array(xy, dtype=np.float64), labels=labels, colors=LABEL,
                              radii=rr.Radius.ui_points(0.0), show_labels=True),
            static=static)


def _fmt(value: float) -> str:
    return f"{value:.10g}"


def log_box_axes(rec: rr.RecordingStream, path: str, frame: Frame2D, x_title: str,
                 y_title: str) -> None:
    """Axes on the left and bottom of the box, a faint grid, tick labels, axis titles."""
    (x_lo, x_hi), (y_lo, y_hi) = frame.x_range, frame.y_range
    xs, ys = frame.ticks("x"), frame.ticks("y")
    grid = [frame.stored([x, x], [y_lo, y_hi]) for x in xs[1:]]
    grid += [frame.stored([x_lo, x_hi], [y, y]) for y in ys[1:]]
    rec.log(f"{path}/grid", rr.LineStrips2D(grid, colors=GRID,
                                            radii=rr.Radius.ui_points(0.5)), static=True)
    axes = [frame.stored([x_lo, x_hi], [y_lo, y_lo]), frame.stored([x_lo, x_lo], [y_lo, y_hi])]
    rec.log(f"{path}/axes", rr.LineStrips2D(axes, colors=GREY,
                                            radii=rr.Radius.ui_points(1.0)), static=True)
    h = frame.height
    left, bottom = frame.stored([x_lo], [y_lo])[0]
    log_labels(rec, f"{path}/x_ticks", [(x * frame.x_scale, bottom + 0.05 * h) for x in xs],
               [_fmt(x) for x in xs])
    log_labels(rec, f"{path}/y_ticks", [(left - 0.08 * h, -y * frame.y_scale) for y in ys],
               [_fmt(y) for y in ys])
    right = x_hi * frame.x_scale
    top = -y_hi * frame.y_scale
    log_labels(rec, f"{path}/titles", [(right - 0.1 * h, bottom + 0.13 * h),
                                       (left + 0.12 * h, top - 0.06 * h)], [x_title, y_title])


def log_phase_reference(rec: rr.RecordingStream, frame: Frame2D) -> None:
    """Axes of Fig. 5 and the trivial solution at (1, 1)."""
    log_box_axes(rec, ent.PHASE_REFERENCE, frame, "v / v₀ (axial)", "ω / ω₀")
    rec.log(f"{ent.PHASE_REFERENCE}/trivial",
            rr.Points2D(frame.stored([1.0], [1.0]), colors=GREY,
                        radii=rr.Radius.ui_points(4.0)), static=True)


def log_bottom_hole_reference(rec: rr.RecordingStream, units: PaperUnits,
                              frame: Frame2D) -> None:
    """Circles at whole multiples of delta0, the blade directions at tau = 0, labels on the
    upward ray (one per circle, never on top of each other)."""
    r_max = frame.x_range[1]
    angle = np.linspace(0.0, 2.0 * np.pi, 181)
    ring = max(1.0, frame.x_step)
    radii = np.arange(ring, r_max + 1e-9, ring)
    rims = radii if radii[-1] == r_max else np.append(radii, r_max)
    circles = [frame.stored(r * np.cos(angle), r * np.sin(angle)) for r in rims]
    blades = 2.0 * np.pi * np.arange(units.n) / units.n
    rays = [frame.stored([0.0, r_max * np.cos(a)], [0.0, r_max * np.sin(a)]) for a in blades]
    rec.log(ent.BOTTOM_HOLE_REFERENCE, rr.LineStrips2D(circles + rays, colors=GRID_STRONG,
                                                       radii=rr.Radius.ui_points(0.75)),
            static=True)
    names = [("δ₀" if r == 1 else f"{r:g} δ₀") for r in radii]
    offset = 0.04 * frame.height
    log_labels(rec, f"{ent.BOTTOM_HOLE_REFERENCE}/labels",
               [(offset, -r * frame.y_scale - offset) for r in radii], names)
    log_labels(rec, f"{ent.BOTTOM_HOLE_REFERENCE}/title", [(0.0, 0.5 * frame.height + 0.08)],
               ["depth of cut at the bit angle, max(δ, 0)"])


def log_es_reference(rec: rr.RecordingStream, units: PaperUnits, frame: Frame2D) -> None:
    """Friction line E = 1 - beta + beta S (eq. 50) inside the frame, the cutting point and
    the trivial state, labelled off the line."""
    (s_lo, s_hi), e_hi = frame.x_range, frame.y_range[1]
    s = np.array([max(1.0, s_lo), s_hi])
    e = units.friction_line(s)
    if e[1] > e_hi:                                  # keep the line inside the box
        s[1] = 1.0 + (e_hi - 1.0) / units.beta if units.beta > 0 else s_hi
        e[1] = e_hi
    rec.log(ent.ES_FRICTION_LINE, rr.LineStrips2D([frame.stored(s, e)], colors=GREY,
                                                  radii=rr.Radius.ui_points(1.0)), static=True)
    ref = es_reference(units)
    rec.log(ent.ES_POINTS, rr.Points2D(frame.stored(ref[:, 0], ref[:, 1]), colors=GREY,
                                       radii=rr.Radius.ui_points(4.0)), static=True)
    h = frame.height
    cut, *trivial = frame.stored(ref[:, 0], ref[:, 1])
    end = frame.stored(s[1:], e[1:])[0]
    spots = [(cut[0] + 0.05 * h, cut[1] + 0.07 * h), (end[0] - 0.25 * h, end[1] - 0.07 * h)]
    names = ["cutting point", f"friction line, β = {units.beta:.3g}"]
    if trivial:
        spots.append((trivial[0][0] + 0.1 * h, trivial[0][1] + 0.07 * h))
        names.append("trivial (eq. 34)")
    log_labels(rec, f"{ent.ES_POINTS}/labels", spots, names)
    log_box_axes(rec, ent.ES_REFERENCE, frame, "S = ⟨W⟩/⟨δ⟩",
                 "E = ⟨T⟩/⟨δ⟩")


def info_markdown(units: PaperUnits, window_s: float) -> str:
    """The run notes shown beside the plots: what each 2D view holds, in a few lines."""
    colors = " · ".join(f"{n.replace('_', ' ')} {ent.MODE_COLOR_NAMES[i]}"
                             for i, n in enumerate(MODE_NAMES))
    return "\n".join([
        f"**Preset** `{units.preset}`: t* = {units.scales.time_s:.3g} s, "
        f"L* = {units.scales.length_m * 1e3:.3g} mm, β = {units.beta:.3g} (RGD07).",
        "",
        f"**Mode colours** {colors}.",
        "",
        f"**Phase portrait** (Fig. 5): the last {window_s:.3g} s; grey dot = steady drilling "
        f"(eq. 34, v₀ = {units.v0:.3g}, ω₀ = {units.omega0:.3g}).",
        "",
        "**Bottom-hole pattern** (Fig. 7): depth of cut at the bit angle over the last "
        f"revolution, the one before pale; δ₀ = {units.delta0:.3g}.",
        "",
        f"**E–S** (Fig. 12, eqs. 48, 50) and **severity**: averages over {window_s:.3g} s "
        "of sim time; the E–S path since the start.",
    ])


def log_static(rec: rr.RecordingStream, units: PaperUnits, window_s: float,
               frames: ViewFrames) -> None:
    """Everything static, once per recording."""
    log_series_styles(rec)
    log_phase_reference(rec, frames.phase)
    log_bottom_hole_reference(rec, units, frames.bottom_hole)
    log_es_reference(rec, units, frames.es)
    rec.log(ent.INFO, rr.TextDocument(info_markdown(units, window_s),
                                      media_type=rr.MediaType.MARKDOWN), static=True)
