"""The default dashboard layout, stored in every .rrd the bridge or mcap_to_rerun writes."""

from __future__ import annotations

import rerun.blueprint as rrb

from drill_sim_ros.viz import entities as ent


def recent(window_s: float) -> rrb.VisibleTimeRange:
    """The last ``window_s`` seconds of sim time before the time cursor."""
    return rrb.VisibleTimeRange(
        ent.TIMELINE,
        start=rrb.TimeRangeBoundary.cursor_relative(seconds=-window_s),
        end=rrb.TimeRangeBoundary.cursor_relative())


def time_series_column() -> rrb.Vertical:
    """WOB, torque, ROP, rpm and mode against sim time; stick and off-bottom marked."""
    return rrb.Vertical(
        rrb.TimeSeriesView(origin="/timeseries/wob", name="WOB & applied WOB [kN]"),
        rrb.TimeSeriesView(origin="/timeseries/torque", name="TOB & surface torque [kN m]"),
        rrb.TimeSeriesView(origin="/timeseries/rop", name="ROP [m/h]"),
        rrb.TimeSeriesView(origin="/timeseries/rpm", name="bit & surface rpm"),
        rrb.TimeSeriesView(origin="/timeseries/mode", name="mode (phases)"),
        row_shares=[2, 2, 2, 2, 1],
    )


def paper_views(window_s: float) -> rrb.Vertical:
    """Phase portrait, bottom-hole pattern, E-S diagram, severity and the run notes."""
    last = recent(window_s)
    return rrb.Vertical(
        rrb.Horizontal(
            rrb.Spatial2DView(origin=ent.PHASE_PORTRAIT, name="phase portrait (Fig. 5)",
                              time_ranges=last),
            rrb.Spatial2DView(origin=ent.BOTTOM_HOLE, name="bottom-hole pattern (Fig. 7)",
                              time_ranges=last),
        ),
        rrb.Horizontal(
            rrb.Spatial2DView(origin=ent.ES_DIAGRAM, name="E-S diagram (Fig. 12)",
                              time_ranges=rrb.VisibleTimeRange(
                                  ent.TIMELINE, start=rrb.TimeRangeBoundary.infinite(),
                                  end=rrb.TimeRangeBoundary.cursor_relative())),
            rrb.Vertical(
                rrb.TimeSeriesView(origin=ent.SEVERITY, name="stick-slip severity"),
                rrb.TextDocumentView(origin=ent.INFO, name="run"),
            ),
        ),
    )


def build_blueprint(window_s: float) -> rrb.Blueprint:
    """Time series on the left, the paper's figures on the right."""
    return rrb.Blueprint(
        rrb.Horizontal(time_series_column(), paper_views(window_s), column_shares=[1, 1]),
        collapse_panels=False,
    )
