"""``drill_sim fit --log run.mcap``: a sim_node recording read as a rig's surface log
(fit/mcap_log.py), against the telemetry recorded beside it (another topic, another reader:
viz.mcap_telemetry), and refused in one line when it holds no start-up."""

from __future__ import annotations

import os
import subprocess

import numpy as np
import pytest

from drill_sim_ros import cli
from drill_sim_ros.fit.log import read_log
from drill_sim_ros.model.params import RPM_PER_RAD_S
from drill_sim_ros.model.presets import DEFAULT_PRESET, load_preset
from drill_sim_ros.model.telemetry import TELEMETRY_INDEX as F
from drill_sim_ros.viz.mcap_telemetry import read_telemetry
from tests.archive.helpers import BIN

pytestmark = pytest.mark.ros


@pytest.fixture(scope="module")
def recording(tmp_path_factory: pytest.TempPathFactory):
    """Two wall seconds of sim_node on the default preset, recorded (perfect sensors: the
    measured surface signals are the telemetry's own)."""
    path = tmp_path_factory.mktemp("mcap") / "run.mcap"
    done = subprocess.run([str(BIN / "sim_node"), "--ros-args", "-p", f"record.path:={path}",
                           "-p", "run_seconds:=2", "-p", "status_line:=false"],
                          capture_output=True, text=True, timeout=120, env=os.environ.copy())
    assert done.returncode == 0, done.stderr[-2000:]
    return path


def test_the_recordings_surface_signals_are_the_telemetrys(recording) -> None:
    log = read_log(recording, "string")
    rows = np.concatenate([b.rows for b in read_telemetry(recording)])
    assert log.t_s.size > 50 and np.all(np.diff(log.t_s) > 0)
    index = np.searchsorted(rows[:, F["sim_time_s"]], log.t_s - 1e-6)
    np.testing.assert_allclose(rows[index, F["sim_time_s"]], log.t_s, rtol=0, atol=1e-6)
    row = rows[index]
    np.testing.assert_allclose(log.speed_rad_s, row[:, F["surface_rpm"]] / RPM_PER_RAD_S,
                               rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(log.torque_nm, row[:, F["surface_torque_nm"]], rtol=1e-12)
    np.testing.assert_allclose(log.hook_load_n, row[:, F["hook_load_n"]], rtol=1e-12)
    motor = read_log(recording, "motor")
    np.testing.assert_allclose(motor.torque_nm, row[:, F["motor_torque_nm"]], rtol=1e-12)


def test_the_recordings_setpoint_is_the_presets_speed(recording) -> None:
    """``--follow setpoint`` reads the drive's setpoint from the telemetry recorded beside:
    the default run holds its preset's surface speed from the first sample."""
    log = read_log(recording, "string")
    rpm = load_preset(DEFAULT_PRESET).physical.surface_rpm
    assert log.setpoint_rad_s is not None and log.setpoint_rad_s.size == log.t_s.size
    np.testing.assert_allclose(log.setpoint_rad_s * RPM_PER_RAD_S, rpm, rtol=1e-9)


def test_a_recording_without_a_start_up_is_refused_in_one_line(recording, capsys) -> None:
    """The default run drills at 35 rpm from its first sample: nothing starts from rest."""
    code = cli.main(["fit", "--params", "field_8p5in_deviated", "--log", str(recording),
                     "--fit", "well.side_friction.static", "--in-process"])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1 and "no start-up" in err[0], err
