"""One number parser on every input path, and nothing silently ignored (issue 52, points 4
and 5): YAML 1.1's exponent text (``6.0e4``, ``1e1``) is its number everywhere; an integer
beyond a double is the one line naming the user's key, never OverflowError; a schedule point
past the run's end, a ``ramp_s`` with nothing to ramp, a key given twice and an empty block
are refused with one line (exit 2)."""

from __future__ import annotations

from pathlib import Path

import pytest
import yaml

from drill_sim_ros.control.scenario import load_scenario
from drill_sim_ros.model.checks import as_number
from drill_sim_ros.model.errors import ParameterError
from drill_sim_ros.model.presets import load_preset
from drill_sim_ros.ros.parameters import check_params_files
from tests.robust.helpers import ROOT, one_error_line, run_cli

HUGE = "1" + "0" * 400                      # an integer beyond a double (1e308)
DEVIATED = (ROOT / "config/presets/field_8p5in_deviated.yaml").read_text()


def test_the_parser_reads_yaml_exponent_text_and_bounds_huge_integers() -> None:
    assert as_number("6.0e4") == 60000.0 and as_number("1e1") == 10.0
    assert as_number(10**400) == float("inf") and as_number(-(10**400)) == float("-inf")
    assert as_number(True) is None and as_number("abc") is None and as_number([1]) is None


def test_yaml_exponent_text_counts_as_its_number_in_a_schedule(tmp_path: Path) -> None:
    path = tmp_path / "s.yaml"
    path.write_text("duration_s: 2.0e1\nenable_at_s: 5\nschedule:\n"
                    "  - {t_s: 0, rpm: 60, wob_n: 6.0e4}\n  - {t_s: 1e1, rpm: 7.0e1}\n"
                    "drive: {max_torque_rate_nm_s: 2.0e6}\n")
    assert yaml.safe_load(path.read_text())["schedule"][0]["wob_n"] == "6.0e4"  # YAML 1.1
    scenario = load_scenario(path)
    schedule = scenario.setpoints(load_preset())
    assert schedule.wob0_n == 60000.0 and schedule.rpm_at(10.0) == 70.0
    assert schedule.rpm_at(9.99) == 60.0
    assert scenario.drive == {"max_torque_rate_nm_s": 2.0e6}


def _scenario_file(tmp_path: Path, text: str) -> str:
    path = tmp_path / "scenario.yaml"
    path.write_text(text)
    return str(path)


@pytest.mark.parametrize(("text", "names"), [
    # overflow: the user's key, no OverflowError
    (f"duration_s: {HUGE}\n", ("'duration_s'", "~1e400", "finite")),
    (f"schedule: [{{t_s: {HUGE}, rpm: 60}}]\n", ("'schedule[0].t_s'", "~1e400")),
    (f"schedule: [{{t_s: 0, wob_n: {HUGE}}}]\n", ("'schedule[0].wob_n'", "~1e400")),
    (f"drive: {{max_torque_nm: {HUGE}}}\n", ("drive.max_torque_nm", "~1e400")),
    (f"params: {{gain: {HUGE}}}\n", ("'params.gain'", "~1e400")),
    (f"sensors: {{seed: {HUGE}}}\n", ("'sensors.seed'", "~1e400")),
    # the schedule's own rpm named, not the model's omega0
    ("schedule: [{t_s: 0, rpm: 1.0e+308}]\n", ("'schedule[0].rpm'", "1e+308", "[0, 10000]")),
    ("schedule: [{t_s: 0, wob_n: 6.0e4x}]\n", ("'schedule[0].wob_n'", "'6.0e4x'")),
    # nothing silently ignored
    ("duration_s: 20\nenable_at_s: 5\nschedule: [{t_s: 500, off_bottom: true}]\n",
     ("'schedule[0].t_s' = 500", "duration_s = 20", "never act")),
    ("schedule: [{t_s: 200, rpm: 50}]\n", ("'schedule[0].t_s' = 200", "duration_s = 180")),
    ("schedule: [{t_s: 10, off_bottom: true, ramp_s: 5}]\n",
     ("'schedule[0].ramp_s' = 5", "no effect", "off_bottom")),
    ("schedule: [{t_s: 10}]\n", ("'schedule[0]'", "sets nothing")),
    ("duration_s: 20\nduration_s: 30\n", ("twice", "'duration_s'", "line 1")),
    ("drive:\n", ("'drive' is empty",)),
    ("schedule:\n", ("'schedule' is empty",)),
])
def test_a_scenario_number_or_silent_entry_is_one_line(
        capsys: pytest.CaptureFixture[str], tmp_path: Path, text: str,
        names: tuple[str, ...]) -> None:
    path = _scenario_file(tmp_path, text)
    rc, out, err = run_cli(capsys, "closed-loop", "--scenario", path, "--no-baseline")
    line = one_error_line(rc, err, path, *names)
    assert len(line) < 400, line
    assert out == ""


def test_a_schedule_point_cut_off_by_t_end_is_named_once(
        capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    """A file's valid late point under a shorter --t-end: a warning (refusing would break
    every short run of a full-length scenario), the run goes on."""
    path = _scenario_file(tmp_path, "duration_s: 30\nenable_at_s: 1\ncontroller: none\n"
                          "schedule: [{t_s: 0, rpm: 60}, {t_s: 20, rpm: 70}]\n")
    rc, _, err = run_cli(capsys, "closed-loop", "--scenario", path, "--no-baseline",
                         "--t-end", "2", "--json")
    assert rc == 0, err
    warnings = [line for line in err.splitlines() if "warning" in line]
    assert len(warnings) == 1 and "t_s = 20" in warnings[0] and "never act" in warnings[0]


def _preset_file(tmp_path: Path, text: str) -> str:
    path = tmp_path / "preset.yaml"
    path.write_text(text)
    return str(path)


@pytest.mark.parametrize(("change", "names"), [
    (("zeta: 0.729", f"zeta: {HUGE}"), ("'physical.zeta'", "~1e400", "finite")),
    (("n_blades: 6", f"n_blades: {HUGE}"), ("'physical.n_blades'", "~1e400")),
    (("length_m: 200.0}", f"length_m: {HUGE}}}"), ("'string.sections[1].length_m'",
                                                   "~1e400")),
    (("{md_m: 300,", f"{{md_m: {HUGE},"), ("'well.survey[1].md_m'", "~1e400")),
    (("kp_nm_s: 23200.0", f"kp_nm_s: {HUGE}"), ("'top_drive.kp_nm_s'", "~1e400")),
    (("numerics: {dtau: 5.0e-5}", "numerics: {dtau: 5.0e-5, dtau: 1.0e-4}"),
     ("twice", "'dtau'")),
    (("  mud_density_kg_m3: 1200.0\n", "  mud_density_kg_m3: 1200.0\n"
      "  mud_density_kg_m3: 1.2\n"), ("twice", "'mud_density_kg_m3'")),
])
def test_a_preset_number_or_duplicate_is_one_line(
        capsys: pytest.CaptureFixture[str], tmp_path: Path, change: tuple[str, str],
        names: tuple[str, ...]) -> None:
    assert change[0] in DEVIATED
    path = _preset_file(tmp_path, DEVIATED.replace(change[0], change[1], 1))
    rc, out, err = run_cli(capsys, "info", path)
    line = one_error_line(rc, err, path, *names)
    assert len(line) < 600, line
    assert out == ""


def test_an_empty_well_block_is_not_read_as_no_well(capsys: pytest.CaptureFixture[str],
                                                    tmp_path: Path) -> None:
    text = DEVIATED[:DEVIATED.index("\nwell:")] + "\nwell:\n"
    path = _preset_file(tmp_path, text)
    rc, _, err = run_cli(capsys, "info", path)
    one_error_line(rc, err, path, "'well' is empty")
    sections = DEVIATED.replace("  sections:\n", "  sections:\n  old_sections:\n", 1)
    path = _preset_file(tmp_path, sections)
    rc, _, err = run_cli(capsys, "info", path)
    one_error_line(rc, err, path, "'string.sections' is empty")


def test_a_params_file_with_a_key_twice_is_refused(tmp_path: Path) -> None:
    path = tmp_path / "sim.yaml"
    path.write_text("drill_sim:\n  ros__parameters:\n    publish_rate_hz: 50.0\n"
                    "    publish_rate_hz: 100.0\n")
    with pytest.raises(ParameterError) as caught:
        check_params_files(["sim_node", "--ros-args", "--params-file", str(path)])
    assert "\n" not in str(caught.value)
    assert "'publish_rate_hz' twice" in str(caught.value)
