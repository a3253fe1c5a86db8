"""A recorded run (MCAP written by mcap_ros2 from the real Simulator) through mcap_to_rerun."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from mcap.reader import make_reader

from drill_sim_ros import topics
from drill_sim_ros.model.presets import DEFAULT_PRESET, load_preset
from drill_sim_ros.viz.mcap_to_rerun import recorded_units
from tests.viz import expected as ex
from tests.viz.rrd_read import (
    read_recording,
    series_aggregation,
    tick_scale,
    view_bounds,
    view_origins,
)
from tests.viz.sim_telemetry import telemetry_rows, write_mcap

PRESET = "field_8p5in_shale_lumped"
SECONDS = 40.0
F = topics.TELEMETRY_INDEX


def run_cli(*args: str) -> subprocess.CompletedProcess:
    exe = Path(sys.prefix) / "bin" / "mcap_to_rerun"
    return subprocess.run([str(exe), *args], capture_output=True, text=True, timeout=120,
                          check=False)


@pytest.fixture(scope="module")
def run(tmp_path_factory: pytest.TempPathFactory) -> dict:
    tmp = tmp_path_factory.mktemp("mcap_to_rerun")
    preset = load_preset(PRESET)
    rows = telemetry_rows(preset, SECONDS)
    mcap, rrd = tmp / "run.mcap", tmp / "run.rrd"
    write_mcap(mcap, rows, metadata={"preset": PRESET})     # the views take its scales
    proc = run_cli(str(mcap), "-o", str(rrd))
    assert proc.returncode == 0, proc.stderr
    with open(mcap, "rb") as stream:
        summary = make_reader(stream).get_summary()
    channel = next(c.id for c in summary.channels.values() if c.topic == topics.TELEMETRY)
    count = summary.statistics.channel_message_counts[channel]
    return {"rows": rows, "preset": preset, "rrd": rrd, "count": count,
            "data": read_recording(rrd), "window_s": 20.0 * preset.scales.time_s}


def test_input_is_a_stick_slip_run(run: dict) -> None:
    modes = run["rows"][:, F["mode"]]
    assert run["count"] == len(run["rows"]) > 1000
    assert np.any(modes == ex.STUCK), "the test run should contain stick phases"


def test_blueprint_is_stored_and_every_view_has_data(run: dict) -> None:
    origins = set(view_origins(run["rrd"]).values())
    assert origins == ex.VIEW_ORIGINS
    for origin in origins:
        assert any(path == origin or path.startswith(origin + "/") for path in run["data"]), origin


@pytest.mark.parametrize("path", [*ex.SCALARS, "/phase_portrait/trajectory",
                                  "/severity/ssi", "/severity/stick_fraction"])
def test_sample_counts_equal_message_count(run: dict, path: str) -> None:
    data = run["data"][path]
    assert len(data.time_ns) == run["count"]
    assert np.all(np.abs(data.time_ns - run["rows"][:, F["sim_time_s"]] * 1e9) <= 1.0)


@pytest.mark.parametrize("path", list(ex.SCALARS))
def test_scalar_values_round_trip(run: dict, path: str) -> None:
    field, factor = ex.SCALARS[path]
    np.testing.assert_allclose(run["data"][path].scalars(), run["rows"][:, F[field]] * factor,
                               rtol=1e-15, atol=0.0)


def test_phase_markers_sit_on_stick_and_off_bottom_samples(run: dict) -> None:
    rows, data = run["rows"], run["data"]
    for path, field, factor, mode in (("/timeseries/rpm/stick", "bit_rpm", 1.0, ex.STUCK),
                                      ("/timeseries/wob/off_bottom", "wob_n", 1e-3,
                                       ex.OFF_BOTTOM)):
        sel = rows[:, F["mode"]] == mode
        got = data[path].scalars()
        np.testing.assert_array_equal(got, rows[sel, F[field]] * factor)


def test_every_time_series_keeps_min_and_max_per_pixel(run: dict) -> None:
    for path in [*ex.SCALARS, "/severity/ssi", "/severity/stick_fraction"]:
        assert series_aggregation(run["data"], path) == ex.MIN_MAX, path


def test_phase_portrait_is_a_path_coloured_by_mode_on_its_ticks(run: dict) -> None:
    data = run["data"]
    trajectory = data["/phase_portrait/trajectory"]
    scale = np.array([tick_scale(data, "/phase_portrait/reference/x_ticks", 0),
                      tick_scale(data, "/phase_portrait/reference/y_ticks", 1)])
    expected = ex.phase_portrait(run["rows"], run["preset"]) * scale
    ends = trajectory.segment_ends()
    np.testing.assert_allclose(ends, expected, rtol=1e-6, atol=1e-6 * np.abs(expected).max())
    np.testing.assert_array_equal(trajectory.segment_starts()[1:], ends[:-1])  # unbroken
    colors = np.array([c[0] for c in trajectory.columns["LineStrips2D:colors"]])
    stuck = run["rows"][:, F["mode"]] == ex.STUCK
    assert len(np.unique(colors[stuck])) == 1
    assert not np.isin(colors[~stuck], colors[stuck]).any()


def test_bottom_hole_shows_the_last_two_revolutions(run: dict) -> None:
    data, rows = run["data"], run["rows"]
    turns = ex.revolutions(rows)
    last, previous = data["/bottom_hole/last_turn"], data["/bottom_hole/previous_turn"]
    assert len(turns) > 10 and len(last.time_ns) == len(turns)
    unit = np.abs(data["/bottom_hole/reference"].static["LineStrips2D:strips"][0][0]).max()
    pattern = ex.bottom_hole(rows, run["preset"]) * unit        # circle 1 = delta0
    times = np.round(rows[:, F["sim_time_s"]] * 1e9).astype(np.int64)
    for k, strips in enumerate(last.strips()):
        want = pattern[turns[k]]
        assert abs(last.time_ns[k] - times[turns[k][-1]]) <= 1
        got = np.vstack([strips[0], *[s[1:] for s in strips[1:]]])   # joints shared
        np.testing.assert_allclose(got, want, rtol=1e-5, atol=1e-6)
    np.testing.assert_array_equal(previous.time_ns, last.time_ns[1:])
    for k, strips in enumerate(previous.strips()):            # the turn before, pale
        np.testing.assert_allclose(np.vstack(strips), np.vstack(last.strips()[k]))


def test_2d_views_are_framed_by_their_data(run: dict) -> None:
    data, bounds = run["data"], view_bounds(run["rrd"])
    for origin, paths in (("/phase_portrait", ["/phase_portrait/trajectory"]),
                          ("/bottom_hole", ["/bottom_hole/last_turn"]),
                          ("/es_diagram", ["/es_diagram/running_average",
                                           "/es_diagram/reference_points"])):
        (x_lo, x_hi), (y_lo, y_hi) = bounds[origin]
        points = np.vstack([ex.stored_points(data[p]) for p in paths])
        assert np.all((points[:, 0] >= x_lo) & (points[:, 0] <= x_hi)), origin
        assert np.all((points[:, 1] >= y_lo) & (points[:, 1] <= y_hi)), origin
        spread = np.ptp(points, axis=0) / np.array([x_hi - x_lo, y_hi - y_lo])
        assert spread.max() > 0.5, f"{origin}: the data fill {spread} of the view"


def test_severity_matches_analysis_severity_over_the_window(run: dict) -> None:
    rows, data, window_s = run["rows"], run["data"], run["window_s"]
    ssi, stick = data["/severity/ssi"].scalars(), data["/severity/stick_fraction"].scalars()
    for i in np.linspace(10, len(rows) - 1, 25).astype(int):
        want_ssi, want_stick = ex.severity_at(rows, i, window_s)
        assert stick[i] == pytest.approx(want_stick, abs=1e-12)
        if np.isfinite(want_ssi):
            assert ssi[i] == pytest.approx(want_ssi, rel=1e-9)
        else:
            assert np.isnan(ssi[i])


def test_es_running_average_matches_eq_48_in_si(run: dict) -> None:
    rows, data, window_s = run["rows"], run["data"], run["window_s"]
    es = data["/es_diagram/running_average"]
    scale = np.array([tick_scale(data, "/es_diagram/reference/x_ticks", 0),
                      -tick_scale(data, "/es_diagram/reference/y_ticks", 1)])   # y down
    t_ns = es.time_ns
    points = es.segment_ends() / scale
    index = {t: k for k, t in enumerate(t_ns)}
    times = np.round(rows[:, F["sim_time_s"]] * 1e9).astype(np.int64)
    checked = 0
    for i in np.linspace(100, len(rows) - 1, 25).astype(int):
        energy, strength = ex.es_at(rows, i, window_s, run["preset"])
        k = index.get(times[i], index.get(times[i] - 1, index.get(times[i] + 1)))
        if not (np.isfinite(energy) and ex.window(rows, i, window_s)[:, F["depth_of_cut_m"]]
                .mean() > 0):
            assert k is None
            continue
        assert points[k] == pytest.approx([strength, energy], rel=1e-5)
        checked += 1
    assert checked > 0


def test_friction_line_follows_eq_50(run: dict) -> None:
    data = run["data"]
    sx = tick_scale(data, "/es_diagram/reference/x_ticks", 0)
    sy = tick_scale(data, "/es_diagram/reference/y_ticks", 1)
    (strip,) = data["/es_diagram/friction_line"].static["LineStrips2D:strips"][0]
    (s1, e1), (s2, e2) = np.array(strip) / np.array([sx, -sy])
    beta = run["preset"].params.beta
    assert (s1, e1) == pytest.approx((1.0, 1.0), rel=1e-6)
    assert e2 == pytest.approx(1.0 - beta + beta * s2, rel=1e-6)


def test_missing_telemetry_is_a_clear_error(tmp_path: Path) -> None:
    empty = tmp_path / "empty.mcap"
    write_mcap(empty, np.empty((0, len(topics.TELEMETRY_FIELDS))))
    proc = run_cli(str(empty), "-o", str(tmp_path / "x.rrd"))
    assert proc.returncode == 1
    assert "/drill/telemetry" in proc.stderr


def test_preset_comes_from_the_file_metadata(tmp_path: Path) -> None:
    rows = telemetry_rows(load_preset("fig5_8a"), 5.0)
    mcap, rrd = tmp_path / "fig5.mcap", tmp_path / "fig5.rrd"
    write_mcap(mcap, rows, metadata={"preset": "fig5_8a"})
    assert run_cli(str(mcap), "-o", str(rrd)).returncode == 0
    data = read_recording(rrd)
    assert "fig5_8a" in data["/info"].static["TextDocument:text"][0][0]
    scale = np.array([tick_scale(data, "/phase_portrait/reference/x_ticks", 0),
                      tick_scale(data, "/phase_portrait/reference/y_ticks", 1)])
    expected = ex.phase_portrait(rows, load_preset("fig5_8a")) * scale
    np.testing.assert_allclose(data["/phase_portrait/trajectory"].segment_ends(), expected,
                               rtol=1e-6, atol=1e-6)


def test_the_scales_come_from_the_recorded_run_info(tmp_path, capsys):
    """A recording that says what it ran needs no --preset; one that does not falls back to
    the default preset, with a warning naming it."""
    preset = load_preset("fig5_8a")
    sc = preset.scales
    groups = {g: float(getattr(preset.params, g)) for g in ("n", "psi", "beta", "lam", "w0",
                                                              "omega0")}
    info = {"preset": "fig5_8a", "groups": groups, "t_star_s": sc.time_s,
            "l_star_m": sc.length_m, "force_unit_n": sc.force_n, "torque_unit_nm": sc.torque_nm}
    rows = telemetry_rows(preset, 1.0)
    with_info, without = tmp_path / "with.mcap", tmp_path / "without.mcap"
    write_mcap(with_info, rows, run_info=info)
    write_mcap(without, rows)
    units = recorded_units(with_info, None)
    assert (units.scales, units.beta, units.n) == (sc, preset.params.beta, preset.params.n)
    assert capsys.readouterr().err == ""
    fallback = recorded_units(without, None)
    assert fallback.preset == DEFAULT_PRESET
    assert f"no {topics.RUN_INFO} and names no preset" in capsys.readouterr().err
    lumped = "field_8p5in_shale_lumped"
    assert recorded_units(with_info, lumped).preset == lumped
