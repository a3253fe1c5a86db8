"""The closed-loop picture's WOB panel: the applied WOB and the operator's setpoint are drawn
only while the bit is on bottom (a picked-up bit has no WOB applied)."""

from __future__ import annotations

import numpy as np

from drill_sim_ros.control.plot import PlotContext, _wob, pyplot
from drill_sim_ros.control.rig import rig_physics
from drill_sim_ros.control.schedule import schedule_from_list
from drill_sim_ros.model.presets import load_preset
from drill_sim_ros.model.telemetry import N_FIELDS, TELEMETRY_INDEX

F = TELEMETRY_INDEX


def test_the_applied_wob_is_not_drawn_off_bottom() -> None:
    """Picked up at 20 s, back on bottom at 60 s: the two reference lines are blank in
    between (the telemetry's applied WOB stays at the driller's 60 kN), the bit's WOB is
    drawn throughout."""
    t_s = np.arange(0.0, 80.0, 0.5)
    rows = np.zeros((t_s.size, N_FIELDS))
    rows[:, F["sim_time_s"]] = t_s
    rows[:, F["applied_wob_n"]] = 60e3
    schedule = schedule_from_list([{"t_s": 0, "rpm": 35, "wob_n": 60e3},
                                   {"t_s": 20, "off_bottom": True},
                                   {"t_s": 60, "off_bottom": False}], 35.0, 60e3)
    ctx = PlotContext("", schedule, 10.0, rig_physics(load_preset("field_8p5in_deviated")))
    plt = pyplot()
    fig, ax = plt.subplots()
    try:
        _wob(ax, t_s, rows, ctx)
        lines = {line.get_label(): np.asarray(line.get_ydata(), float) for line in ax.lines}
    finally:
        plt.close(fig)
    off = (t_s >= 20.0) & (t_s < 60.0)
    applied, operator = lines["applied WOB"], lines["operator setpoint"]
    for drawn in (applied, operator):
        assert np.isnan(drawn[off]).all()
        np.testing.assert_array_equal(drawn[~off], 60.0)
    assert np.isfinite(lines["WOB at bit"]).all()
