"""The inputs of issue 52's reliability run, each as a user gives them: exit status 2 and
the one line naming the key (point 8). sim_node runs as a process (marked ros); the
drill_sim cases run in process."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from tests.robust.helpers import ROOT, one_error_line, run_cli

HUGE = "1" + "0" * 400
DEVIATED = (ROOT / "config/presets/field_8p5in_deviated.yaml").read_text()
LUMPED = (ROOT / "config/presets/field_8p5in_shale_lumped.yaml").read_text()
BIN = Path(sys.executable).parent


def _file(tmp_path: Path, name: str, text: str) -> str:
    path = tmp_path / name
    path.write_text(text)
    return str(path)


def _slip(tmp_path: Path, density: str = "7.85") -> str:
    """The deviated field preset with the steel's density in g/cm3 (the issue's slip)."""
    return _file(tmp_path, "slip.yaml",
                 DEVIATED.replace("density_kg_m3: 7850.0", f"density_kg_m3: {density}", 1))


def test_the_unit_slip_in_closed_loop_json(capsys: pytest.CaptureFixture[str],
                                           tmp_path: Path) -> None:
    """Issue 52: quill torque 1.9e9 N m, motor energy -10722 MJ, exit 0."""
    path = _slip(tmp_path)
    rc, out, err = run_cli(capsys, "closed-loop", "--params", path, "--t-end", "5",
                           "--no-baseline", "--json")
    one_error_line(rc, err, path, "'physical.density_kg_m3' = 7.85",
                   "'well.mud_density_kg_m3' = 1200", "g/cm3")
    assert out == ""


def test_785_in_startup(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    """Issue 52: the bit at 4598 rpm, mean motor torque -42 kN m, exit 0."""
    path = _slip(tmp_path, "785")
    rc, out, err = run_cli(capsys, "startup", "--params", path, "--seconds", "2")
    one_error_line(rc, err, path, "'physical.density_kg_m3' = 785",
                   "'well.mud_density_kg_m3' = 1200")
    assert out == ""


def test_785_without_a_well_names_the_default_mud(capsys: pytest.CaptureFixture[str],
                                                  tmp_path: Path) -> None:
    """Issue 52: 'model.submerged_string_weight_n = -38341.8 is outside [0, 1e+10]'."""
    path = _file(tmp_path, "lumped.yaml",
                 LUMPED.replace("density_kg_m3: 7850.0", "density_kg_m3: 785", 1))
    rc, _, err = run_cli(capsys, "info", path)
    one_error_line(rc, err, path, "'physical.density_kg_m3' = 785", "MUD_DENSITY_KG_M3")


def _sim_node(*ros_args: str) -> str:
    """sim_node refusing to start: exit 2 and one FATAL line, returned."""
    done = subprocess.run([str(BIN / "sim_node"), "--ros-args", *ros_args],
                          capture_output=True, text=True, timeout=120,
                          env={**os.environ, "PYTHONPATH": str(ROOT)})
    lines = [line for line in (done.stdout + done.stderr).splitlines() if line.strip()]
    assert done.returncode == 2, done.stdout + done.stderr
    assert len(lines) == 1 and "[FATAL]" in lines[0], lines
    assert "Traceback" not in done.stderr
    return lines[0]


@pytest.mark.ros
@pytest.mark.parametrize(("args", "names"), [
    (("-p", f"model.applied_wob_n:={HUGE}"), ("model.applied_wob_n", "~1e400",
                                              "beyond a double")),
    (("-p", "publish_rate_hz:=1e400"), ("publish_rate_hz", "'1e400'", "beyond a double")),
    (("-p", "model.preset:=field_8p5in_deviated", "-p", "model.applied_wob_n:=2e6"),
     ("'model.applied_wob_n' = 2e+06", "buoyed weight")),
    (("-p", "model.preset:=field_8p5in_deviated", "-p", "model.surface_rpm:=3.0"),
     ("'model.surface_rpm' = 3", "stick_speed_rad_s")),
])
def test_sim_node_refuses_in_one_line(args: tuple[str, ...], names: tuple[str, ...]) -> None:
    line = _sim_node(*args)
    for name in names:
        assert name in line, (name, line)


@pytest.mark.ros
def test_sim_node_refuses_the_unit_slip_and_a_duplicate_key(tmp_path: Path) -> None:
    line = _sim_node("-p", f"model.preset:={_slip(tmp_path)}")
    assert "'physical.density_kg_m3' = 7.85" in line and "g/cm3" in line
    twice = _file(tmp_path, "sim.yaml", "drill_sim:\n  ros__parameters:\n"
                  "    publish_rate_hz: 50.0\n    publish_rate_hz: 100.0\n")
    line = _sim_node("--params-file", twice)
    assert "'publish_rate_hz' twice" in line and twice in line


@pytest.mark.parametrize(("text", "names"), [
    ("{gain: 1, gain: 2}", ("not valid YAML", "'gain' twice")),
    ("{gain: [}", ("not valid YAML",)),
    ("[1, 2]", ("must be a YAML mapping",)),
    ("{gain: abc}", ("params.gain = 'abc'", "finite number")),
    (f"{{gain: {HUGE}}}", ("params.gain = ~1e400", "finite number")),
])
def test_the_controller_nodes_params_text_is_one_line(text: str,
                                                      names: tuple[str, ...]) -> None:
    """top_drive_controller's ``params`` parameter (a YAML mapping in a string); before, a
    bad text was a traceback."""
    from drill_sim_ros.model.errors import ParameterError
    from drill_sim_ros.ros.controller_node import params_from_text
    with pytest.raises(ParameterError) as caught:
        params_from_text(text)
    message = str(caught.value)
    assert "\n" not in message and len(message) < 400, message
    for name in names:
        assert name in message, (name, message)
    assert params_from_text("{gain: 2.0e1}") == {"gain": 20.0}       # YAML 1.1's text
