"""The code path shared by the live bridge and mcap_to_rerun: TelemetryBatch -> rerun."""

from __future__ import annotations

import rerun as rr

from drill_sim_ros.viz import log_views as lv
from drill_sim_ros.viz.paper_units import PaperUnits
from drill_sim_ros.viz.running_stats import default_window_s, new_window, running_stats
from drill_sim_ros.viz.static_views import log_static
from drill_sim_ros.viz.telemetry import TelemetryBatch

MAX_ROWS = 20_000   # bounds the sliding-window work arrays for large offline batches


class Dashboard:
    """Logs telemetry batches to one recording stream; keeps the sliding window."""

    def __init__(self, rec: rr.RecordingStream, units: PaperUnits,
                 window_s: float | None = None) -> None:
        self.rec = rec
        self.units = units
        self.window_s = default_window_s(units) if window_s is None else float(window_s)
        self._window = new_window(self.window_s)
        self.samples = 0
        self.last_time_s: float | None = None
        log_static(rec, units, self.window_s)

    def log_batch(self, batch: TelemetryBatch) -> None:
        """Log every sample of ``batch``; a backwards jump in sim time restarts the window."""
        for part in batch.monotonic_parts():
            for start in range(0, len(part), MAX_ROWS):
                self._log_part(TelemetryBatch(part.rows[start:start + MAX_ROWS]))

    def _log_part(self, batch: TelemetryBatch) -> None:
        t = batch.sim_time_s
        last = self._window.last_time
        if last is not None and t[0] < last:
            self._window.reset()
        lv.log_time_series(self.rec, batch)
        lv.log_phase_markers(self.rec, batch)
        lv.log_phase_portrait(self.rec, batch, self.units)
        lv.log_bottom_hole(self.rec, batch, self.units)
        stats = running_stats(self._window, batch, self.units)
        lv.log_es_state(self.rec, t, stats)
        lv.log_severity(self.rec, t, stats)
        self.samples += len(batch)
        self.last_time_s = float(t[-1])
