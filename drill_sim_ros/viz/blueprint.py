"""The default dashboard layout, stored in every .rrd the bridge or mcap_to_rerun writes.

Panels (blueprint tree, selection, streams) start collapsed, so the plots get the screen.
Plot legends are off: each view's title names its lines and their colours instead, so no
legend sits on the data. The 2D views' visual bounds are their frames (see frames.py).
"""

from __future__ import annotations

import rerun.blueprint as rrb

from drill_sim_ros.topics import MODE_NAMES
from drill_sim_ros.viz import entities as ent
from drill_sim_ros.viz.frames import Frame2D, ViewFrames
from drill_sim_ros.viz.string_views import FRAME_BOUNDS, IMAGE_PROFILES

NO_LEGEND = rrb.PlotLegend(visible=False)
MODE_TITLE = "mode: " + " \u00b7 ".join(f"{i} {n.replace('_', ' ')}"
                                        for i, n in enumerate(MODE_NAMES))


def recent(window_s: float) -> rrb.VisibleTimeRange:
    """The last ``window_s`` seconds of sim time before the time cursor."""
    return rrb.VisibleTimeRange(
        ent.TIMELINE,
        start=rrb.TimeRangeBoundary.cursor_relative(seconds=-window_s),
        end=rrb.TimeRangeBoundary.cursor_relative())


def since_start() -> rrb.VisibleTimeRange:
    return rrb.VisibleTimeRange(ent.TIMELINE, start=rrb.TimeRangeBoundary.infinite(),
                                end=rrb.TimeRangeBoundary.cursor_relative())


def series(origin: str, name: str, **kwargs: object) -> rrb.TimeSeriesView:
    return rrb.TimeSeriesView(origin=origin, name=name, plot_legend=NO_LEGEND, **kwargs)


def time_series_column() -> rrb.Vertical:
    """WOB, torque, ROP, rpm and mode against sim time; stick and off-bottom marked."""
    return rrb.Vertical(
        series("/timeseries/wob", "WOB [kN]: bit (blue), applied (grey), off bottom (purple)"),
        series("/timeseries/torque", "torque [kN m]: on bit (green), surface (grey)"),
        series("/timeseries/rop", "ROP [m/h]"),
        series("/timeseries/rpm", "speed [rpm]: bit (blue), BHA (cyan), top drive (grey), "
                                    "stuck (red)"),
        series("/timeseries/mode", MODE_TITLE,
               axis_y=rrb.ScalarAxis(range=(-0.3, len(MODE_NAMES) - 0.7), zoom_lock=True)),
        row_shares=[2, 2, 2, 2, 1.4],
    )


def frame_view(origin: str, name: str, frame: Frame2D,
               time_range: rrb.VisibleTimeRange | None) -> rrb.Spatial2DView:
    """A 2D view framed by ``frame``; no time range: the latest value of each entity."""
    x_range, y_range = frame.bounds()
    return rrb.Spatial2DView(origin=origin, name=name, time_ranges=time_range,
                             visual_bounds=rrb.VisualBounds2D(x_range=x_range, y_range=y_range))


def paper_views(window_s: float, frames: ViewFrames) -> rrb.Vertical:
    """Phase portrait, bottom-hole pattern, E-S diagram, severity and the run notes."""
    return rrb.Vertical(
        rrb.Horizontal(
            frame_view(ent.PHASE_PORTRAIT, f"phase portrait, last {window_s:.3g} s (Fig. 5)",
                       frames.phase, recent(window_s)),
            frame_view(ent.BOTTOM_HOLE, "bottom-hole pattern, last 2 turns (Fig. 7)",
                       frames.bottom_hole, None),
        ),
        rrb.Horizontal(
            frame_view(ent.ES_DIAGRAM, "E\u2013S diagram, running averages (Fig. 12)",
                       frames.es, since_start()),
            rrb.Vertical(
                series(ent.SEVERITY, "severity: SSI (red), stick fraction (purple)"),
                rrb.TextDocumentView(origin=ent.INFO, name="run notes"),
                row_shares=[1, 1.3],
            ),
        ),
        row_shares=[1, 1],
    )


def string_views() -> rrb.Horizontal:
    """The distributed string: depth x time picture of its speed, speed and torque profiles."""
    x_range, y_range = FRAME_BOUNDS
    return rrb.Horizontal(
        rrb.Spatial2DView(origin=ent.STRING_DEPTH_TIME,
                          name=f"string speed over depth and the last {IMAGE_PROFILES} "
                               "profiles: white at the mean, blue slower, red faster",
                          visual_bounds=rrb.VisualBounds2D(x_range=x_range, y_range=y_range)),
        rrb.BarChartView(origin=ent.STRING_SPEED, name="string speed [rpm] over depth [m]",
                         plot_legend=NO_LEGEND),
        rrb.BarChartView(origin=ent.STRING_TORQUE, name="string torque [kN m] over depth [m]",
                         plot_legend=NO_LEGEND),
        column_shares=[2, 1, 1],
    )


def build_blueprint(window_s: float, frames: ViewFrames, string: bool = False
                    ) -> rrb.Blueprint:
    """Time series on the left, the paper's figures on the right; with ``string`` (a
    distributed string), its views below; side panels collapsed."""
    top = rrb.Horizontal(time_series_column(), paper_views(window_s, frames),
                         column_shares=[1, 1.15])
    return rrb.Blueprint(
        rrb.Vertical(top, string_views(), row_shares=[3, 1]) if string else top,
        rrb.BlueprintPanel(state="collapsed"),
        rrb.SelectionPanel(state="collapsed"),
        rrb.TimePanel(state="collapsed"),
    )


def has_string_views(run_info: dict | None) -> bool:
    """The run info (``/drill/run_info``) names a distributed string."""
    string = (run_info or {}).get("string") or {}
    return isinstance(string, dict) and string.get("model") == "distributed"
