"""drill_sim fit: the log's checks, the replay of a logged speed, the drift-free objective,
the command end to end on a log made by the simulator."""

from __future__ import annotations

import contextlib
import io
import json
from collections.abc import Iterator

import numpy as np
import pytest
import yaml

from drill_sim_ros import cli
from drill_sim_ros.fit import engine, objective, synthetic
from drill_sim_ros.fit.log import LogError, find_startups, read_log
from drill_sim_ros.fit.params import parse_fit
from drill_sim_ros.model.presets import load_preset, preset_from_dict, preset_path
from drill_sim_ros.model.replay import replay_speed
from drill_sim_ros.model.startup import RPM_PER_RAD_S, run_startup
from drill_sim_ros.model.validate_input import read_preset_file
from tests.model import fv_cases

PRESET = "field_8p5in_deviated"
# The static fit at the tool's default, twelve replays a point (fit.engine): some 1150
# replays, 5-6 min of CPU, up to 15 min of wall time on a loaded machine: a study
# (``make bench``, marker ``study``), with this timeout instead of the suite's 300 s. The
# fit that tests the machinery and the 10 % bar in ``make test`` averages TEST_REPLAYS.
FIT_TIMEOUT_S = 1800
TEST_REPLAYS = 2
# The fits here run the preset's string at a 2.0 ms wave step (the preset: 1.0 ms), half the
# cost of every replay: they test the fit's machinery on a log of the same model, not the
# preset's convergence in the wave step (docs/string.md).
COARSE_SUBSTEPS = 54
# The log: 30 rpm after a 10 s ramp, 45 s (the first slip at 20.8 s, then about three
# cycles); the fit below lands where it did on a 60 s log (0.857 and 0.857 against the truth
# 0.885, measured 2026-12-06) for 70 % of the replays' cost.
LOG_S = 45.0


def coarse_data() -> dict:
    """The preset's mapping at the tests' wave step."""
    data = read_preset_file(preset_path(PRESET))
    data["string"]["bit_substeps"] = COARSE_SUBSTEPS
    return data


@pytest.fixture(scope="module")
def log_csv(tmp_path_factory: pytest.TempPathFactory) -> str:
    path = tmp_path_factory.mktemp("fit") / "log.csv"
    log = synthetic.synthetic_log(preset_from_dict(PRESET, coarse_data()), 30.0, 10.0, LOG_S,
                                  synthetic.scenario_sensors(1))
    synthetic.write_csv(log, str(path))
    return str(path)


def _write(path, header: str, rows: list[list[float]]) -> str:
    path.write_text(header + "\n" + "\n".join(",".join(map(str, r)) for r in rows) + "\n")
    return str(path)


@pytest.mark.parametrize(("header", "rows", "words"), [
    ("time_s,surface_rpm", [[0, 0], [0.01, 0], [0.02, 1]], "no string torque column"),
    ("time_s,surface_rpm,torque_knm", [[0, 0, 0], [0.02, 0, 0], [0.01, 1, 1]], "unsorted"),
    ("time_s,surface_rpm,torque_knm", [[0, 0, 0], [0.01, 0, 0], [0.01, 1, 1]], "repeated"),
    ("time_s,surface_rpm,torque_knm", [[0, 0, 0], [0.01, "nan", 0], [0.02, "nan", 1],
                                       [0.03, 1, 1]], "NaN or infinite in samples 1 to 2"),
])
def test_a_bad_log_is_refused_in_one_line(tmp_path, header, rows, words) -> None:
    kind = "motor" if "torque_knm" in header else "string"
    with pytest.raises(LogError, match=words):
        read_log(_write(tmp_path / "bad.csv", header, rows), kind)


@pytest.mark.parametrize("count", ["0", "65"])
def test_replays_outside_their_range_are_refused_in_one_line(count: str, capsys) -> None:
    code = cli.main(["fit", "--params", PRESET, "--log", "unread.csv", "--fit",
                     "well.side_friction.static", "--replays", count])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1 and f"--replays {count}: must be within 1..64" in err[0]


def test_a_log_without_a_start_up_is_refused(tmp_path, capsys) -> None:
    rows = [[0.01 * i, 30.0, 10.0] for i in range(500)]        # turning all along
    path = _write(tmp_path / "steady.csv", "time_s,surface_rpm,torque_knm", rows)
    code = cli.main(["fit", "--params", PRESET, "--log", path, "--fit",
                     "well.side_friction.static", "--in-process"])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1 and "no start-up" in err[0]


def test_a_preset_naming_a_survey_file_is_read_from_any_directory(tmp_path, capsys,
                                                                    monkeypatch) -> None:
    """Its survey CSV is found beside the preset (the log's error, not the survey's)."""
    rows = [[0.01 * i, 30.0, 10.0] for i in range(500)]
    path = _write(tmp_path / "steady.csv", "time_s,surface_rpm,torque_knm", rows)
    monkeypatch.chdir(tmp_path)
    code = cli.main(["fit", "--params", "field_8p5in_build_turn", "--log", path, "--fit",
                     "well.side_friction.static", "--in-process"])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1 and "no start-up" in err[0], err


def test_a_logged_hook_load_is_checked_against_the_hanging_weight() -> None:
    """Off bottom the hook holds the string's buoyed weight along the hole: a log within 5 %
    of it passes, one 10 % heavier is named in a warning (not in the misfit)."""
    from types import SimpleNamespace

    from drill_sim_ros import fit_cli
    from drill_sim_ros.model.presets import submerged_string_weight_n
    hanging_n = submerged_string_weight_n(load_preset(PRESET))
    assert 3e5 < hanging_n < 2e6                  # some 800 kN of 5-in pipe and collars
    for factor, warned in ((1.0, False), (1.04, False), (1.10, True)):
        hook = np.full(100, factor * hanging_n)
        target = SimpleNamespace(log=SimpleNamespace(hook_load_n=hook))
        check = fit_cli._hook_load(target, hanging_n)
        assert check["share"] == pytest.approx(factor - 1.0)
        warning = fit_cli._hook_warning(12.0, check)
        assert bool(warning) == warned
        if warned:
            assert "+10 %" in warning[0] and "12.0 s" in warning[0]
    target = SimpleNamespace(log=SimpleNamespace(hook_load_n=None))
    assert fit_cli._hook_load(target, hanging_n) is None


def _startup_speed(rpm: float) -> np.ndarray:
    """A drive's logged speed: 1 s at rest, a 2 s ramp, then ``rpm``, 100 Hz, noisy."""
    t_s = np.arange(0.0, 60.0, 0.01)
    ramp = np.clip((t_s - 1.0) / 2.0, 0.0, 1.0)
    noise = 0.02 * np.random.default_rng(1).standard_normal(t_s.size)
    return ramp * rpm / RPM_PER_RAD_S + noise


@pytest.mark.parametrize(("fitted", "rpms", "warned"), [
    ("well.side_friction.dynamic,string.torsional_damping_per_s", (40,), True),
    ("well.side_friction.dynamic,string.torsional_damping_per_s", (40, 40, 80), True),
    ("well.side_friction.dynamic,string.torsional_damping_per_s", (40, 120), False),
    ("well.side_friction.dynamic,string.torsional_damping_per_s", (120, 40), False),
    ("well.side_friction.static,string.torsional_damping_per_s", (40,), False),
    ("well.side_friction.dynamic", (40,), False),
])
def test_the_viscous_loss_and_the_dynamic_friction_at_one_speed_are_warned(
        fitted: str, rpms: tuple[float, ...], warned: bool) -> None:
    """A torque rate x inertia x speed and a torque that does not depend on speed cannot be
    told apart at one speed: fitting both to start-ups less than three times apart in speed
    is warned of, naming the speed and both paths."""
    params = parse_fit(fitted, coarse_data())
    warnings = engine.one_speed_warning(params, [_startup_speed(r) for r in rpms])
    assert bool(warnings) is warned
    if warned:
        low, high = min(rpms), max(rpms)
        at = f"{low:.0f} rpm" if low == high else f"{low:.0f} to {high:.0f} rpm"
        assert f"every start-up turns at {at}:" in warnings[0]
        assert "string.torsional_damping_per_s" in warnings[0]
        assert "well.side_friction.dynamic" in warnings[0]


def test_start_ups_are_found_from_rest_to_turning() -> None:
    t = np.arange(0.0, 30.0, 0.01)
    rpm = np.where((t % 15.0) < 3.0, 0.0, np.minimum(30.0, 10.0 * ((t % 15.0) - 3.0)))
    from drill_sim_ros.fit.log import SurfaceLog
    log = SurfaceLog("two", t, rpm / RPM_PER_RAD_S, np.zeros_like(t), "motor")
    spans = find_startups(log)
    assert len(spans) == 2
    for (a, b), rise_s in zip(spans, (3.0, 18.0), strict=True):
        assert t[a] < rise_s < t[b - 1]
        assert abs(rpm[a]) < 1e-9


def test_the_replay_follows_the_logged_speed() -> None:
    """The drive of a replay goes through every logged speed (it is prescribed), and a
    replay of a run's own drive speed turns the string as that run did until it first
    slips: the same torque at the top, within 2 % of its peak."""
    preset = load_preset(PRESET)
    run = run_startup(preset, 30.0, 10.0, 15.0)
    replay = replay_speed(preset, run.t_s, run.drive_rpm / RPM_PER_RAD_S)
    assert np.allclose(replay.drive_rpm, np.maximum(run.drive_rpm, 0.0), atol=1e-6)
    peak = np.max(np.abs(run.surface_torque_nm))
    early = run.t_s < 8.0
    assert np.max(np.abs(replay.surface_torque_nm - run.surface_torque_nm)[early]) < 0.02 * peak


def test_a_replay_of_the_drive_speed_at_every_wave_step_is_the_run() -> None:
    """The kinematic replay is the same system as the run of the drive's speed loop: fed the
    run's drive speed at every wave step, it gives the run's torque at the top after the
    first slip too, within 1 N m (round-off), where the wall's friction makes the cycle
    jump to another branch with the smallest change of what the string is turned by
    (docs/fit.md: a 100 Hz speed, interpolated, already does)."""
    preset = preset_from_dict(PRESET, coarse_data())
    wave_step_s = COARSE_SUBSTEPS * preset.dtau * preset.scales.time_s
    run = run_startup(preset, 30.0, 10.0, 30.0, sample_hz=1.0 / wave_step_s)
    replay = replay_speed(preset, run.t_s, run.drive_rpm / RPM_PER_RAD_S)
    late = run.t_s > 25.0
    assert np.ptp(run.surface_torque_nm[late]) > 1e3      # it cycles there
    assert np.max(np.abs(replay.surface_torque_nm - run.surface_torque_nm)) < 1.0


def test_the_cycle_features_do_not_see_a_phase_drift() -> None:
    """A saw-tooth cycle and the same cycle shifted by a third of its period give the same
    period (within a sample), mean and std (within 1 %)."""
    dt, period = 0.01, 7.0
    t = np.arange(0.0, 42.0, dt)
    a = objective.cycle_features(np.mod(t, period), dt)
    b = objective.cycle_features(np.mod(t + period / 3.0, period), dt)
    assert abs(a[0] - period) < 2 * dt and abs(b[0] - period) < 2 * dt
    assert np.allclose(a[1:3], b[1:3], rtol=0.01)


def test_noise_std_reads_white_noise_under_a_ramp() -> None:
    rng = np.random.default_rng(3)
    x = np.linspace(0.0, 1e4, 20_000) + 50.0 * rng.standard_normal(20_000)
    assert abs(objective.noise_std(x) - 50.0) < 2.5


@pytest.fixture(scope="module")
def static_fit(log_csv: str, tmp_path_factory: pytest.TempPathFactory) -> dict:
    """``drill_sim fit --replays 2`` (TEST_REPLAYS) of the wall's static coefficient from
    15 % below the truth on a log of the simulator (its sensors' noise and quantisation):
    the truth, the argv, the report, the preset written."""
    return _static_fit(log_csv, tmp_path_factory, ["--replays", str(TEST_REPLAYS)])


@pytest.fixture(scope="module")
def static_fit_default(log_csv: str, tmp_path_factory: pytest.TempPathFactory) -> dict:
    """The same fit at the tool's default replays a point (a study: minutes)."""
    return _static_fit(log_csv, tmp_path_factory, [])


def _static_fit(log_csv: str, tmp_path_factory: pytest.TempPathFactory,
                options: list[str]) -> dict:
    tmp = tmp_path_factory.mktemp("static")
    data = coarse_data()
    truth = data["well"]["side_friction"]["static"]
    data["well"]["side_friction"]["static"] = 0.85 * truth
    start = tmp / "start.yaml"
    start.write_text(yaml.safe_dump(data))
    out = tmp / "fitted.yaml"
    argv = ["fit", "--params", str(start), "--log", log_csv, "--fit",
            "well.side_friction.static", "--in-process", "--json", "--out", str(out), *options]
    with _stdout() as lines:
        assert cli.main(argv) == 0
    return {"truth": truth, "argv": argv, "report": json.loads(lines[-1]), "out": out,
            "log": log_csv}


@contextlib.contextmanager
def _stdout() -> Iterator[list[str]]:
    """The lines printed to stdout inside the block."""
    buffer, lines = io.StringIO(), []
    with contextlib.redirect_stdout(buffer):
        yield lines
    lines.extend(buffer.getvalue().strip().splitlines())


def test_fit_reports_writes_its_preset_and_resumes(static_fit) -> None:
    """The report has the value inside its interval, the misfits and both cycles; the
    preset written names the log and holds the value; run again, the cache replays
    nothing."""
    fit = static_fit["report"]["fits"][0]
    value = fit["values"]["well.side_friction.static"]
    assert value["low95"] <= value["value"] <= value["high95"]
    assert fit["misfit_after"] <= fit["misfit_before"]
    cycle = fit["startups"][0]
    assert cycle["recorded"]["period_s"] > 0 and cycle["fitted"]["period_s"] > 0
    for name, spread in cycle["replays"].items():      # the recorded cycle, read back
        assert spread["mean"] + spread["recorded_z"] * spread["sd"] == pytest.approx(
            cycle["recorded"][name], rel=1e-9)
    out = static_fit["out"]
    assert static_fit["log"] in out.read_text().splitlines()[0]
    assert read_preset_file(out)["well"]["side_friction"]["static"] == pytest.approx(
        value["value"])
    load_preset(str(out))                                  # a valid preset
    with _stdout() as lines:
        assert cli.main([*static_fit["argv"], "--overwrite"]) == 0
    again = json.loads(lines[-1])["fits"][0]
    assert again["replays"] == 0
    assert again["values"] == fit["values"]


def test_fit_moves_the_static_friction_to_within_10_percent(static_fit) -> None:
    """From 15 % below, the fitted static coefficient lands within 10 % of the truth."""
    value = static_fit["report"]["fits"][0]["values"]["well.side_friction.static"]
    assert abs(value["value"] / static_fit["truth"] - 1.0) < 0.10


@pytest.mark.study
@pytest.mark.timeout(FIT_TIMEOUT_S)
@pytest.mark.xfail(strict=True, reason="on this 45 s log the fit lands 2.1 % low and its "
                   "95 % profile interval, 0.8537 to 0.8823, misses the truth 0.885 "
                   "(docs/fit.md, 2026-12-06); on the 60 s logs of benchmarks/bench_fit.py "
                   "the intervals cover it in most logs (the coverage study there)")
def test_fit_recovers_the_static_friction_within_5_percent_inside_its_interval(
        static_fit_default) -> None:
    value = static_fit_default["report"]["fits"][0]["values"]["well.side_friction.static"]
    assert abs(value["value"] / static_fit_default["truth"] - 1.0) < 0.05
    assert value["low95"] <= static_fit_default["truth"] <= value["high95"]


def test_a_las_log_is_read_by_mnemonic_and_unit(tmp_path) -> None:
    """A LAS file (written by lasio) with time in s, SURFACE in rpm and STRING_TORQUE in
    kN.m reads as the same SI log as its numbers."""
    import lasio
    las = lasio.LASFile()
    t = np.arange(0.0, 1.0, 0.01)
    las.append_curve("TIME", t, unit="s")
    las.append_curve("SURFACE", np.full(t.size, 30.0), unit="rpm")
    las.append_curve("STRING_TORQUE", np.full(t.size, 2.5), unit="kN.m")
    path = tmp_path / "log.las"
    with path.open("w") as f:
        las.write(f)
    log = read_log(path)
    assert log.torque_kind == "string"
    assert np.allclose(log.t_s, t)
    assert np.allclose(log.speed_rad_s, 30.0 / RPM_PER_RAD_S)
    assert np.allclose(log.torque_nm, 2500.0)


@pytest.mark.parametrize(("low95", "high95", "note"), [
    (0.19, 0.21, ""),
    (0.19, 1.5, "; not limited above by the log: the bound"),
    (0.05, 0.21, "; not limited below by the log: the bound"),
    (0.05, 1.5, "; not limited below or above by the log: the bound"),
])
def test_a_95_percent_limit_at_the_bound_is_said_to_be_the_bound(low95: float, high95: float,
                                                                  note: str) -> None:
    """A limit the profile did not find a rise before is the parameter's bound, not a
    limit the log sets: the summary says so."""
    from drill_sim_ros.fit_cli import _open
    value = {"value": 0.2, "low95": low95, "high95": high95, "bounds": [0.05, 1.5]}
    assert _open(value) == note


def test_a_replay_of_a_runs_own_setpoint_through_its_loop_is_the_run() -> None:
    """``follow="setpoint"``: the preset's speed loop driven by the setpoint a start-up
    logged (0 then a 10 s ramp to 30 rpm, linear between the 100 Hz samples; the ramp's end
    falls between two of them) turns the string as the run did: the setpoint within
    1e-3 rpm, the drive's speed within 0.01 rpm, the string torque at the top within 0.5 N m
    of some 20 kN m. A kinematic replay of the run's own drive speed at 100 Hz misses the
    torque by more (measured 24.6 N m against 0.02): it cannot carry the loop's ripple
    between the samples."""
    preset = preset_from_dict(PRESET, coarse_data())
    run = run_startup(preset, 30.0, 10.0, 15.0)
    replay = replay_speed(preset, run.t_s, run.setpoint_rpm / RPM_PER_RAD_S, follow="setpoint")
    kinematic = replay_speed(preset, run.t_s, run.drive_rpm / RPM_PER_RAD_S)
    assert np.max(np.abs(run.setpoint_rpm - replay.setpoint_rpm)) < 1e-3
    assert np.max(np.abs(run.drive_rpm - replay.drive_rpm)) < 1e-2
    error_nm = np.max(np.abs(run.surface_torque_nm - replay.surface_torque_nm))
    assert error_nm < 0.5
    assert np.max(np.abs(run.surface_torque_nm - kinematic.surface_torque_nm)) > 10 * error_nm
    assert np.max(np.abs(run.surface_torque_nm)) > 5e3          # the string is wound up


def test_following_the_logged_setpoint_the_truth_scores_the_torque_noise_alone() -> None:
    """On a log made by the simulator (the Well B-like tangent, whose cycle does not
    branch: 40 rpm in 2 s, 30 s), replays that follow the logged setpoint through the
    preset's loop reproduce the true run at the true values, so the misfit there is the
    torque's noise alone: its square a chi-square over the residuals' count divided by it
    (within 4 standard deviations of 1), and lower than with the torsional damping 5 % off
    or the dynamic coefficient 2 % off. The replays of a point follow the setpoint shifted
    by under half a sample each (engine.shifted_setpoint), which leaves that so."""
    data = fv_cases.tangent()
    data["string"]["bit_substeps"] = COARSE_SUBSTEPS
    preset = preset_from_dict("tangent", data)
    log = synthetic.synthetic_log(preset, 40.0, 2.0, 30.0, synthetic.scenario_sensors(2))
    target = objective.make_target(log, preset)
    paths = "well.side_friction.dynamic,string.torsional_damping_per_s"
    evaluator = engine.Evaluator(data, parse_fit(paths, data), [target], follow="setpoint")
    assert evaluator.replays == engine.SETPOINT_REPLAYS
    truth = np.array([data["well"]["side_friction"]["dynamic"],
                      data["string"]["torsional_damping_per_s"]])
    at = evaluator.evaluate([truth, truth * [1.0, 1.05], truth * [1.0, 0.95],
                             truth * [1.02, 1.0], truth * [0.98, 1.0]])
    n = at[0].residuals.size
    assert abs(at[0].misfit**2 - 1.0) < 4.0 * np.sqrt(2.0 / n)
    assert all(e.misfit > at[0].misfit for e in at[1:])
    # the intervals' draws of the log's own timing (Evaluator.measure_timing): replays
    # with shifts of their own, their deviations from their mean each a whole replay (the
    # residuals side by side), not zero (different shifts), smaller than the noise they are
    # weighted by (the truth's misfit is the noise alone, above), the weights unchanged
    sigma = [w.copy() for w in evaluator.sigma]
    evaluator.measure_timing(truth)
    scatter = evaluator.sensitivity_scatter()
    assert all(np.array_equal(a, b) for a, b in zip(sigma, evaluator.sigma, strict=True))
    assert scatter.shape == (engine.SENSITIVITY_REPLAYS, n)
    np.testing.assert_allclose(scatter.sum(axis=0), 0.0, atol=1e-9)
    rms = np.sqrt(np.mean(scatter**2, axis=1))
    assert np.all(rms > 0.0) and np.all(rms < 1.0)


def test_a_shifted_setpoint_is_the_log_moved_by_under_half_a_sample() -> None:
    """The setpoints a point's replays follow (engine.shifted_setpoint): seed 0 the log's
    own; the others the same ramp moved in time by one shift each, within half a sample
    either way (read back from the ramp's straight part: its value over its slope), and
    the shifts spread over that interval (a mutant that does not shift fails)."""
    sample_s, slope = 0.01, 4.0                       # 100 Hz, rad/s per s
    t_s = np.arange(0.0, 1.0, sample_s)
    ramp = np.minimum(slope * t_s, 2.0)               # 0 to 2 rad/s in 0.5 s, then held
    assert engine.shifted_setpoint(t_s, ramp, 0) is ramp
    inside = (t_s > 0.05) & (t_s < 0.45)
    shifts = []
    for seed in range(1, 51):
        lag_s = t_s[inside] - engine.shifted_setpoint(t_s, ramp, seed)[inside] / slope
        assert np.ptp(lag_s) < 1e-12                  # one shift for the whole series
        shifts.append(lag_s[0])
    assert np.max(np.abs(shifts)) <= sample_s / 2
    assert np.ptp(shifts) > 0.6 * sample_s


def test_following_a_setpoint_the_log_does_not_have_is_refused_in_one_line(tmp_path,
                                                                          capsys) -> None:
    path = _write(tmp_path / "log.csv", "time_s,surface_rpm,torque_knm",
                  [[0.01 * i, 0.0 if i < 100 else 30.0, 1.0] for i in range(3000)])
    code = cli.main(["fit", "--params", PRESET, "--log", path, "--fit",
                     "well.side_friction.dynamic", "--follow", "setpoint", "--in-process"])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2
    assert err[-1].endswith("--follow setpoint: " + path + " has no setpoint column "
                            "(setpoint_rpm or setpoint_rad_s)")


def test_a_logs_setpoint_is_written_and_read_back(tmp_path) -> None:
    """``drill_sim startup --log-csv``'s CSV carries the drive's setpoint (a command: no
    noise) as setpoint_rpm, which the log reader reads back in rad/s."""
    preset = preset_from_dict(PRESET, coarse_data())
    log = synthetic.synthetic_log(preset, 30.0, 10.0, 5.0, synthetic.scenario_sensors(1))
    path = str(tmp_path / "log.csv")
    synthetic.write_csv(log, path)
    back = read_log(path)
    assert back.setpoint_rad_s is not None
    assert np.allclose(back.setpoint_rad_s, log.setpoint_rad_s, rtol=1e-5, atol=1e-6)
    ramp_share = (log.t_s[-1] - log.t_s[0] - 1.0) / 10.0       # 1 s at rest, then the ramp
    assert back.setpoint_rad_s[-1] == pytest.approx(ramp_share * 30.0 / RPM_PER_RAD_S,
                                                    rel=1e-3)


def test_a_setpoint_fit_draws_the_logs_timing_for_its_interval() -> None:
    """``fit`` following the logged setpoint (the tangent's 30 s start-up to 40 rpm, the
    damping from 10 % below): within 5 % of the truth, its 95 % interval covering it, and
    the interval built with the replays of the setpoint's timing measured at the optimum
    (Evaluator.measure_timing: eight rows, one per shift)."""
    data = fv_cases.tangent()
    data["string"]["bit_substeps"] = COARSE_SUBSTEPS
    log = synthetic.synthetic_log(preset_from_dict("tangent", data), 40.0, 2.0, 30.0,
                                  synthetic.scenario_sensors(2))
    truth = data["string"]["torsional_damping_per_s"]
    data["string"]["torsional_damping_per_s"] = 0.9 * truth
    target = objective.make_target(log, preset_from_dict("tangent", data))
    evaluator = engine.Evaluator(data, parse_fit("string.torsional_damping_per_s", data),
                                 [target], follow="setpoint")
    result = engine.fit(evaluator)
    assert abs(result.x[0] / truth - 1.0) < 0.05
    assert result.low95[0] < truth < result.high95[0]
    assert evaluator.sensitivity_scatter().shape[0] == engine.SENSITIVITY_REPLAYS


@pytest.mark.parametrize(("noise_times", "warned"), [(1.0, False), (3.0, True)])
def test_a_fit_that_missed_the_log_is_warned(noise_times: float, warned: bool) -> None:
    """The residuals are weighted by the log's noise: residuals of the noise's own size (a
    model that reproduces the log) give no warning, three times it a warning that the fit
    missed the log, naming its misfit."""
    params = parse_fit("well.side_friction.static,well.side_friction.dynamic", coarse_data())
    residuals = noise_times * np.random.default_rng(3).standard_normal(4000)
    best = engine.Evaluation(np.array([0.3, 0.2]), residuals, None)
    warnings = engine._warnings(params, best, np.eye(4000, 2), np.eye(2))
    missed = [w for w in warnings if w.startswith("the fit missed the log")]
    assert bool(missed) is warned
    if warned:
        assert f"its misfit is {best.misfit:.3g} times the log's noise" in missed[0]


class _StandIn:
    """An evaluator whose residuals are a formula, not replays (``fit``'s search alone):
    the parameters' offsets from ``truth`` in units of 1 % of their range, beside a floor of
    ``floor`` that no parameter moves (a model that cannot reproduce the log)."""

    follow, replays, computed, reused, targets = "speed", 1, 0, 0, ()

    def __init__(self, params: list, truth: np.ndarray, floor: float) -> None:
        self.params, self.truth, self.floor = params, truth, floor
        self.span = np.array([p.high - p.low for p in params])
        self.started, self.seen = 0.0, []

    def evaluate(self, xs: list[np.ndarray]) -> list[engine.Evaluation]:
        self.seen += [np.array(x) for x in xs]
        return [engine.Evaluation(np.array(x), np.concatenate(
            (100.0 * (x - self.truth) / self.span, np.full(8, self.floor)))) for x in xs]

    def measure_sensitivity(self, x: np.ndarray) -> None:
        pass

    measure_timing = measure_sensitivity

    def sensitivity_scatter(self) -> np.ndarray:
        return np.zeros((0, 0))

    def misfit_sd(self, x: np.ndarray) -> float:
        return 0.0

    def replayed_cycles(self, x: np.ndarray) -> list:
        return []


@pytest.mark.parametrize(("floor", "rescued"), [(1.0, False), (3.0, True)])
def test_a_lost_search_starts_again_from_the_given_values(floor: float, rescued: bool) -> None:
    """A search that ends above ``MISFIT_LOST`` runs least squares again from the given
    values at ``RESCUE_STEP`` (its Jacobian's first point beside them, the step from them,
    is evaluated); one that ends below does not (no other stage steps that little in the
    speed mode)."""
    params = parse_fit("well.side_friction.static,well.side_friction.dynamic", coarse_data())
    x0 = np.array([p.initial for p in params])
    stand_in = _StandIn(params, 1.2 * x0, floor)
    engine.fit(stand_in)
    beside = x0 + engine.RESCUE_STEP * stand_in.span * np.array([1.0, 0.0])
    assert any(np.allclose(x, beside, rtol=0.0, atol=1e-12) for x in stand_in.seen) is rescued
