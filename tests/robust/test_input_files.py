"""Scenario files, preset files and sim_node params files: a wrong type, an unknown or a
missing key is one line naming the file, the key and what is allowed (exit 2)."""

from __future__ import annotations

from pathlib import Path

import pytest
import yaml

from drill_sim_ros.model.errors import ParameterError
from drill_sim_ros.model.presets import available_presets, preset_path
from drill_sim_ros.model.validate_input import read_preset_file
from drill_sim_ros.ros.parameters import check_params_files
from tests.robust.helpers import ROOT, one_error_line, run_cli

FIELD = yaml.safe_load((ROOT / "config/presets/field_8p5in_shale.yaml").read_text())


@pytest.mark.parametrize(("text", "names"), [
    ("params: [1, 2]\n", ("'params'", "[1, 2]", "mapping")),
    ("schedule: 5\n", ("'schedule'", "5", "list of mappings")),
    ("sensors: {string_torque_nm: {noise: 5}}\n", ("noise", "sensors.string_torque_nm",
                                                  "noise_std")),
    ("sensors: {torque_sensor: {noise_std: 5}}\n", ("sensors.torque_sensor", "known")),
    ("controller: 5\n", ("'controller'", "5", "string")),
    ("sensors: {seed: abc}\n", ("sensors.seed", "'abc'", "whole number")),
    ("preset: 5\n", ("'preset'", "5", "string")),
    ("control_rate_hz: 1.0e7\n", ("control_rate_hz", "1e+07", "[1, 1000] Hz")),
    ("duration_s: abc\n", ("duration_s", "'abc'", "number")),
])
def test_a_wrong_scenario_value_is_one_line(capsys, tmp_path: Path, text: str,
                                            names: tuple[str, ...]) -> None:
    path = tmp_path / "scenario.yaml"
    path.write_text(text)
    rc, out, err = run_cli(capsys, "closed-loop", "--scenario", str(path), "--no-baseline")
    one_error_line(rc, err, str(path), *names)
    assert out == ""


def test_a_run_too_long_to_hold_is_refused_before_it_starts(capsys) -> None:
    # 1e7 s at 100 Hz: 1e9 rows of 24 float64 = 192 GB
    rc, _, err = run_cli(capsys, "closed-loop", "--t-end", "1e7", "--no-baseline")
    one_error_line(rc, err, "--t-end", "1e+07", "at most 2,000,000")


def _preset(tmp_path: Path, section: str, change: dict | None = None,
            drop: str | None = None, top: dict | None = None) -> Path:
    data = yaml.safe_load(yaml.safe_dump(FIELD))
    data[section].update(change or {})
    if drop:
        del data[section][drop]
    data.update(top or {})
    path = tmp_path / "my_preset.yaml"
    path.write_text(yaml.safe_dump(data))
    return path


@pytest.mark.parametrize(("kwargs", "names"), [
    ({"section": "physical", "change": {"bit_radius_m": "abc"}},
     ("physical.bit_radius_m", "'abc'", "number")),
    ({"section": "numerics", "change": {"dtau": "x"}}, ("numerics.dtau", "'x'", "number")),
    ({"section": "numerics", "change": {"dtau": 5.0}}, ("numerics.dtau", "[1e-07, 0.1]")),
    ({"section": "physical", "drop": "bit_radius_m"}, ("missing bit_radius_m",)),
    ({"section": "physical", "change": {"n_blades": 6.5}}, ("n_blades", "6.5", "whole")),
    ({"section": "physical", "change": {"bit_radius": 0.1}}, ("bit_radius", "known")),
    ({"section": "top_drive", "change": {"kp_nms": 1.0}}, ("kp_nms", "top_drive")),
    ({"section": "physical", "top": {"numerix": {"dtau": 1e-4}}}, ("numerix", "known")),
])
def test_a_wrong_preset_is_one_line(capsys, tmp_path: Path, kwargs: dict,
                                    names: tuple[str, ...]) -> None:
    path = _preset(tmp_path, **kwargs)
    rc, out, err = run_cli(capsys, "info", str(path))
    one_error_line(rc, err, str(path), *names)
    assert out == ""


def test_every_shipped_preset_passes_the_checks() -> None:
    names = available_presets()
    assert len(names) >= 10
    for name in names:
        read_preset_file(preset_path(name))


@pytest.mark.parametrize(("text", "names"), [
    ("drill_sim:\n  ros__parameters:\n    publish_rate_hzz: 50.0\n",
     ("publish_rate_hzz", "did you mean publish_rate_hz")),
    ("drilsim:\n  ros__parameters:\n    publish_rate_hz: 50.0\n",
     ("no section for node drill_sim", "drilsim")),
    ("just a string\n", ("expected",)),
    ("drill_sim:\n  ros__parameters:\n    model: 5\n", ("'model'", "group")),
    ("drill_sim:\n  publish_rate_hz: 50.0\n", ("ros__parameters",)),
])
def test_a_params_file_setting_nothing_real_is_refused(tmp_path: Path, text: str,
                                                       names: tuple[str, ...]) -> None:
    path = tmp_path / "sim.yaml"
    path.write_text(text)
    with pytest.raises(ParameterError) as caught:
        check_params_files(["sim_node", "--ros-args", "--params-file", str(path)])
    message = str(caught.value)
    assert "\n" not in message and str(path) in message
    for name in names:
        assert name in message, (name, message)


def test_the_shipped_and_multi_node_params_files_pass(tmp_path: Path) -> None:
    check_params_files(["sim_node", "--ros-args", "--params-file",
                        str(ROOT / "config/sim.yaml")])
    both = tmp_path / "launch.yaml"
    both.write_text("top_drive_controller:\n  ros__parameters:\n    controller: stiff\n"
                    "/**:\n  ros__parameters:\n    use_sim_time: false\n"
                    "/rig/drill_sim:\n  ros__parameters:\n    model:\n      preset: fig5_8a\n")
    check_params_files(["sim_node", "--ros-args", "--params-file", str(both)])


def test_a_lumped_preset_must_give_its_geometry(capsys, tmp_path: Path) -> None:
    data = yaml.safe_load((ROOT / "config/presets/field_8p5in_shale_lumped.yaml").read_text())
    del data["physical"]["pipe_length_m"]
    path = tmp_path / "lumped.yaml"
    path.write_text(yaml.safe_dump(data))
    rc, _, err = run_cli(capsys, "info", str(path))
    one_error_line(rc, err, str(path), "missing pipe_length_m")
