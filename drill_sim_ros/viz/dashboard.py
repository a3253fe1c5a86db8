"""The code path shared by the live bridge and mcap_to_rerun: TelemetryBatch -> rerun."""

from __future__ import annotations

from collections.abc import Iterable

import rerun as rr

from drill_sim_ros.viz import log_views as lv
from drill_sim_ros.viz.frames import Extents, ViewFrames, view_frames
from drill_sim_ros.viz.paper_units import PaperUnits
from drill_sim_ros.viz.plot_values import pattern_point, pattern_radius, phase_point
from drill_sim_ros.viz.recording import Recordings
from drill_sim_ros.viz.running_stats import default_window_s, new_window, running_stats
from drill_sim_ros.viz.static_views import log_static
from drill_sim_ros.viz.string_views import StringBatch, StringViews
from drill_sim_ros.viz.telemetry import TelemetryBatch
from drill_sim_ros.viz.turns import TurnTracker

MAX_ROWS = 20_000   # bounds the sliding-window work arrays for large offline batches


class Dashboard:
    """Logs telemetry batches to a recording stream (or to the
    :class:`~drill_sim_ros.viz.recording.Recordings` attached now); keeps the sliding window."""

    def __init__(self, rec: rr.RecordingStream | Recordings, units: PaperUnits,
                 window_s: float | None = None, frames: ViewFrames | None = None) -> None:
        self.rec = rec
        self.units = units
        self.window_s = default_window_s(units) if window_s is None else float(window_s)
        self.frames = view_frames(units, Extents.typical()) if frames is None else frames
        self._window = new_window(self.window_s)
        self._phase_trail, self._es_trail = lv.Trail(), lv.Trail()
        self._turns = TurnTracker()
        self._last_turn: list = []
        self.samples = 0
        self.last_time_s: float | None = None
        self.strings = StringViews(rec)
        self.log_static(rec)

    def log_static(self, rec: rr.RecordingStream | Recordings) -> None:
        """The static parts (series styles, reference geometry, run notes) on ``rec``."""
        log_static(rec, self.units, self.window_s, self.frames)

    def log_batch(self, batch: TelemetryBatch) -> None:
        """Log every sample of ``batch``; a backwards jump in sim time restarts the window."""
        for part in batch.monotonic_parts():
            for start in range(0, len(part), MAX_ROWS):
                self._log_part(TelemetryBatch(part.rows[start:start + MAX_ROWS]))

    def log_strings(self, batch: StringBatch) -> None:
        """The string views of ``batch`` (drill/string/torsion profiles)."""
        self.strings.log(batch)

    def _restart(self) -> None:
        """Sim time went back (a reset): new window, new paths, new revolutions."""
        self._window.reset()
        self._phase_trail, self._es_trail = lv.Trail(), lv.Trail()
        self._turns.reset()
        self._last_turn = []

    def _log_part(self, batch: TelemetryBatch) -> None:
        t = batch.sim_time_s
        last = self._window.last_time
        if last is not None and t[0] < last:
            self._restart()
        frames = self.frames
        lv.log_time_series(self.rec, batch)
        lv.log_phase_markers(self.rec, batch)
        lv.log_phase_portrait(self.rec, batch, self.units, frames.phase, self._phase_trail)
        turns = self._turns.add(t, batch.column("bit_angle_rad"),
                                *pattern_point(batch, self.units), batch.column("mode"))
        lv.log_turns(self.rec, turns, frames.bottom_hole, self._last_turn)
        stats = running_stats(self._window, batch, self.units)
        lv.log_es_state(self.rec, t, stats, frames.es, self._es_trail)
        lv.log_severity(self.rec, t, stats)
        self.samples += len(batch)
        self.last_time_s = float(t[-1])


def data_extents(batches: Iterable[TelemetryBatch], units: PaperUnits,
                 window_s: float) -> Extents:
    """What the 2D views will plot for these batches (a first pass over a recording)."""
    extents = Extents()
    window = new_window(window_s)
    for batch in batches:
        for part in batch.monotonic_parts():
            last = window.last_time
            if last is not None and part.sim_time_s[0] < last:
                window.reset()
            stats = running_stats(window, part, units)
            extents.add(*phase_point(part, units), pattern_radius(part, units),
                        stats.drilling_strength, stats.specific_energy)
    return extents
