"""Reasons that name the value exactly, and the record.* parameters as recorder options."""

from __future__ import annotations

import subprocess

import pytest

from drill_sim_ros.control.command import clamp_command
from drill_sim_ros.model.errors import ParameterError
from drill_sim_ros.ros.parameters import (
    check_parameter_rules,
    check_params_files,
    check_plain_args,
    recording_options,
    yaml_defaults,
)
from tests.archive.helpers import BIN


def test_a_saturated_command_shows_its_value_exactly() -> None:
    applied, reason = clamp_command(600000.0001, 600000.0, "N")
    assert (applied, reason) == (600000.0, "600000.0001 N exceeds the limit 600000.0 N")
    assert clamp_command(600000.0, 600000.0, "N") == (600000.0, None)


def test_record_parameters_become_recorder_options() -> None:
    values = yaml_defaults()
    assert recording_options(values) == {"overwrite": False, "split_size_bytes": None,
                                         "split_duration_s": None}
    values.update({"record.overwrite": True, "record.split_size_mb": 2.5,
                   "record.split_duration_s": 600.0})
    assert recording_options(values) == {"overwrite": True, "split_size_bytes": 2_500_000,
                                         "split_duration_s": 600.0}


def test_params_files_are_checked_before_rcl(tmp_path) -> None:
    good = tmp_path / "good.yaml"
    good.write_text("drill_sim:\n  ros__parameters:\n    lockstep: true\n")
    check_params_files(["sim_node", "--ros-args", "--params-file", str(good)])
    with pytest.raises(ParameterError, match="No such file"):
        check_params_files(["--params-file", str(tmp_path / "absent.yaml")])
    bad = tmp_path / "bad.yaml"
    bad.write_text("a: [1,\n")
    with pytest.raises(ParameterError, match="not valid YAML"):
        check_params_files(["--ros-args", "--params-file", str(bad)])


def test_malformed_parameter_overrides_are_one_line_before_rcl() -> None:
    check_parameter_rules(["sim_node", "--ros-args", "-p", "lockstep:=true",
                           "--param", "model.preset:=fig5_8a"])
    check_parameter_rules(["sim_node", "-p", "foo"])          # not ROS arguments: rcl's own
    for args in (["--ros-args", "-p", "foo"], ["--ros-args", "-p", ":=3"],
                 ["--ros-args", "--param"]):
        with pytest.raises(ParameterError, match="NAME:=VALUE"):
            check_parameter_rules(args)


def test_plain_arguments_are_help_or_one_line(capsys) -> None:
    """A node takes its settings as ROS parameters: outside --ros-args only --help."""
    check_plain_args(["sim_node", "--ros-args", "-p", "lockstep:=true"], "USAGE")
    with pytest.raises(ParameterError, match=r"unknown argument\(s\) -p foo: .*--ros-args"):
        check_plain_args(["sim_node", "-p", "foo"], "USAGE")
    with pytest.raises(SystemExit) as stop:
        check_plain_args(["sim_node", "-h", "--ros-args", "-p", "a:=1"], "USAGE")
    assert stop.value.code == 0
    assert capsys.readouterr().out == "USAGE\n"


@pytest.mark.parametrize("command", ["sim_node", "top_drive_controller", "opcua_gateway"])
def test_a_node_given_help_or_a_stray_argument_does_not_start(command: str) -> None:
    shown = subprocess.run([str(BIN / command), "--help"], capture_output=True, text=True,
                           timeout=60)
    assert shown.returncode == 0, shown.stderr
    assert shown.stdout.startswith(f"usage: {command} [--ros-args"), shown.stdout
    refused = subprocess.run([str(BIN / command), "--bogus"], capture_output=True, text=True,
                             timeout=60)
    assert refused.returncode == 2, refused.stdout + refused.stderr
    lines = (refused.stdout + refused.stderr).strip().splitlines()
    assert len(lines) == 1 and "unknown argument(s) --bogus" in lines[0], lines
