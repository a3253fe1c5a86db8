"""A live run through ``rerun_bridge --save``: publisher -> bridge -> .rrd -> RrdReader."""

from __future__ import annotations

import numpy as np
import pytest

from drill_sim_ros import topics
from drill_sim_ros.model.presets import load_preset
from tests.viz import expected as ex
from tests.viz.bridge_process import bridge_logs
from tests.viz.rrd_read import read_recording, series_aggregation, tick_scale, view_origins
from tests.viz.sim_telemetry import telemetry_rows

pytestmark = pytest.mark.ros
F = topics.TELEMETRY_INDEX
PRESET = "field_8p5in_shale_lumped"


@pytest.fixture(scope="module")
def live(tmp_path_factory: pytest.TempPathFactory) -> dict:

    preset = load_preset(PRESET)
    rows = telemetry_rows(preset, 8.0)
    rrd = tmp_path_factory.mktemp("bridge") / "live.rrd"
    bridge, code = bridge_logs(rows, "--save", str(rrd), "--preset", PRESET)
    assert code == 0, bridge.output()
    return {"rows": rows, "preset": preset, "rrd": rrd, "data": read_recording(rrd),
            "log": bridge.output()}


def test_blueprint_is_stored_and_every_view_has_data(live: dict) -> None:
    origins = set(view_origins(live["rrd"]).values())
    assert origins == ex.VIEW_ORIGINS
    for origin in origins:
        assert any(p == origin or p.startswith(origin + "/") for p in live["data"]), origin


def test_every_published_sample_is_logged_once(live: dict) -> None:
    rows = live["rows"]
    for path in [*ex.SCALARS, "/phase_portrait/trajectory", "/severity/ssi",
                 "/severity/stick_fraction"]:
        t_ns = live["data"][path].time_ns
        assert len(t_ns) == len(rows), path
        assert np.all(np.abs(t_ns - rows[:, F["sim_time_s"]] * 1e9) <= 1.0), path


def test_values_round_trip(live: dict) -> None:
    rows, data = live["rows"], live["data"]
    for path, (field, factor) in ex.SCALARS.items():
        np.testing.assert_allclose(data[path].scalars(), rows[:, F[field]] * factor,
                                   rtol=1e-15, atol=0.0, err_msg=path)
    scale = np.array([tick_scale(data, "/phase_portrait/reference/x_ticks", 0),
                      tick_scale(data, "/phase_portrait/reference/y_ticks", 1)])
    expected = ex.phase_portrait(rows, live["preset"]) * scale
    np.testing.assert_allclose(data["/phase_portrait/trajectory"].segment_ends(), expected,
                               rtol=1e-6, atol=1e-6 * np.abs(expected).max())
    turns = ex.revolutions(rows)
    assert len(data["/bottom_hole/last_turn"].time_ns) == len(turns) > 3
    stick = rows[:, F["mode"]] == ex.STUCK
    np.testing.assert_array_equal(data["/timeseries/rpm/stick"].scalars(),
                                  rows[stick, F["bit_rpm"]])


def test_live_series_keep_min_and_max(live: dict) -> None:
    for path in ex.SCALARS:
        assert series_aggregation(live["data"], path) == ex.MIN_MAX, path


def test_status_line_reports_the_final_count(live: dict) -> None:
    assert f"{len(live['rows'])} telemetry samples logged" in live["log"]
