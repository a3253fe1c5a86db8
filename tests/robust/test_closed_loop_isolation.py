"""closed-loop, in process: a controller's failure is one line with the controller, the sim
time and the value (exit 2); a huge finite command is clamped; a slow step warns once;
Ctrl-C is a clean stop."""

from __future__ import annotations

import json
import logging
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from drill_sim_ros.control.bench import command_limits, run_in_process
from drill_sim_ros.control.rig import rig_physics
from drill_sim_ros.control.scenario import Scenario
from drill_sim_ros.model.telemetry import TELEMETRY_INDEX
from tests.robust.faulty_controllers import FAIL_AT_S
from tests.robust.helpers import FAULTY, ROOT, one_error_line, run_cli

SHORT = ("--t-end", "1", "--no-baseline", "--json")
AT = f"t = {FAIL_AT_S:.3f} s"


@pytest.fixture(autouse=True)
def _from_root(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(ROOT)


@pytest.mark.parametrize(("cls", "names"), [
    ("RaisesInInit", ("RaisesInInit", "cannot be built", "RuntimeError", "no gain for you")),
    ("RaisesInStep", ("RaisesInStep", AT, "ValueError", "step exploded")),
    ("ReturnsNone", ("ReturnsNone", AT, "returned None", "Command")),
    ("ReturnsFloat", ("ReturnsFloat", AT, "returned 6.0", "float")),
    ("ReturnsString", ("ReturnsString", AT, "'fast please'", "str")),
    ("ReturnsNaN", ("ReturnsNaN", AT, "speed_rad_s = nan", "finite")),
])
def test_a_failing_controller_is_one_line(capsys, cls: str, names: tuple[str, ...]) -> None:
    rc, out, err = run_cli(capsys, "closed-loop", "--controller", f"{FAULTY}:{cls}", *SHORT)
    one_error_line(rc, err, *names)
    assert out == ""                         # no score of a run that failed


def test_a_huge_finite_command_is_clamped_not_refused(capsys) -> None:
    rc, out, err = run_cli(capsys, "closed-loop", "--controller", f"{FAULTY}:ReturnsHuge",
                           *SHORT)
    assert rc == 0, err
    assert json.loads(out)["periods"] == 100
    scenario = Scenario(controller=f"{FAULTY}:ReturnsHuge", duration_s=1.0, enable_at_s=0.0)
    run = run_in_process(scenario)
    preset = scenario.load_preset()
    limit_rpm = command_limits(preset, rig_physics(preset)).max_surface_rpm
    t = run.rows[:, TELEMETRY_INDEX["sim_time_s"]]
    setpoint = run.rows[:, TELEMETRY_INDEX["speed_setpoint_rpm"]]
    # the first 1e308 rad/s command reacts to the sample at FAIL_AT_S, applied from the next;
    # the telemetry's setpoint has been through the kernel's time scale and back (an ulp)
    np.testing.assert_allclose(setpoint[t > FAIL_AT_S + 0.015], limit_rpm, rtol=1e-12, atol=0)
    assert (setpoint[(t > 0) & (t < FAIL_AT_S)] < limit_rpm).all()


def test_a_slow_controller_warns_once_with_its_time_per_step(capsys, caplog) -> None:
    with caplog.at_level(logging.WARNING, logger="drill_sim_ros.control.isolation"):
        rc, _, err = run_cli(capsys, "closed-loop", "--controller", f"{FAULTY}:Slow", *SHORT)
    assert rc == 0, err
    warnings = [r.getMessage() for r in caplog.records if "slow" in r.getMessage()]
    assert len(warnings) == 1, warnings
    assert "Slow" in warnings[0] and AT in warnings[0] and "of wall time" in warnings[0]


def test_a_controller_file_that_does_not_exist_is_one_line(capsys) -> None:
    rc, _, err = run_cli(capsys, "closed-loop", "--controller", "no/such/file.py:Class", *SHORT)
    one_error_line(rc, err, "no/such/file.py", "no such file")


def test_a_huge_controller_parameter_names_its_range(capsys) -> None:
    rc, _, err = run_cli(capsys, "closed-loop", "--controller", "soft_torque", "--set",
                         "impedance_factor=1e308", *SHORT)
    one_error_line(rc, err, "impedance_factor", "1e+308", "(0, 1e+09]")


def test_ctrl_c_in_a_run_is_a_clean_stop(tmp_path: Path) -> None:
    flag = tmp_path / "stalled"
    process = subprocess.Popen(
        [sys.executable, "-m", "drill_sim_ros.cli", "closed-loop", "--controller",
         f"{FAULTY}:Stalls", *SHORT], cwd=ROOT, stdout=subprocess.PIPE,
        stderr=subprocess.PIPE, text=True, env={**os.environ, "STALL_FLAG": str(flag)})
    deadline = time.monotonic() + 90
    while not flag.exists() and time.monotonic() < deadline and process.poll() is None:
        time.sleep(0.05)
    assert flag.exists(), process.communicate(timeout=10)
    process.send_signal(signal.SIGINT)
    out, err = process.communicate(timeout=30)
    assert process.returncode == 130, err
    assert "Traceback" not in err and out == ""
    lines = err.strip().splitlines()
    assert len(lines) == 1 and f"interrupted at t = {FAIL_AT_S:g} s of 1 s" in lines[0], lines
