"""sim_node's /diagnostics levels from its figures (issue 26): a level above OK is a fault
of the simulation now; stick-slip is reported at OK. The live checks (names per rig,
stick-slip in the field preset, a silent controller): tests/ros/test_ros_native.py; a full
disk: tests/archive/test_sim_node_faults.py."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from diagnostic_msgs.msg import DiagnosticStatus

from drill_sim_ros.model.analysis import Severity
from drill_sim_ros.ros.diagnostics import Diagnostics, Figures, Source, source_of

QUIET = Figures(state="running", fault=None, sim_time_s=10.0, rtf=1.0, achieved=1.0,
                overruns=0, lateness_ns=np.zeros(4, dtype=np.int64), rejected=0, saturated=0,
                dropped=0, record_error=None, written=100,
                severity=Severity(ssi=0.1, utr=0.05, omega_min=5.9, omega_max=6.6,
                                  omega_mean=6.28),
                stick_fraction=0.0, mode="cutting", window_s=20.0)


def levels(builder: Diagnostics, figures: Figures) -> tuple[bytes, bytes, str, str]:
    simulation, dynamics = builder.message(figures, 0).status
    return simulation.level, dynamics.level, simulation.message, dynamics.message


def test_quiet_drilling_is_ok() -> None:
    assert levels(Diagnostics(), QUIET) == (DiagnosticStatus.OK, DiagnosticStatus.OK,
                                            "running", "smooth drilling")


@pytest.mark.parametrize(("ssi", "stick_fraction", "word"),
                         [(0.7, 0.0, "mild"), (0.4, 0.1, "mild"), (1.0, 0.3, "severe")])
def test_stick_slip_is_the_message_not_the_level(ssi, stick_fraction, word) -> None:
    figures = dataclasses.replace(QUIET, severity=dataclasses.replace(QUIET.severity, ssi=ssi),
                                  stick_fraction=stick_fraction)
    simulation, dynamics, _, message = levels(Diagnostics(), figures)
    assert (simulation, dynamics) == (DiagnosticStatus.OK, DiagnosticStatus.OK)
    assert message == f"stick-slip ({word})"


def test_faults_raise_the_level() -> None:
    fault = dataclasses.replace(QUIET, fault="non-finite state", state="fault")
    assert levels(Diagnostics(), fault)[0] == DiagnosticStatus.ERROR
    lost = dataclasses.replace(QUIET, record_error="No space left on device")
    assert levels(Diagnostics(), lost)[0] == DiagnosticStatus.ERROR
    silent = dataclasses.replace(QUIET, command_silence_s=1.5, command_timeout_s=1.0)
    level, _, message, _ = levels(Diagnostics(), silent)
    assert level == DiagnosticStatus.WARN and message.startswith("controller silent")
    for heard in (dataclasses.replace(silent, command_silence_s=0.5),
                  dataclasses.replace(silent, command_timeout_s=0.0),
                  dataclasses.replace(silent, command_silence_s=None)):
        assert levels(Diagnostics(), heard)[0] == DiagnosticStatus.OK


def test_overruns_and_drops_warn_while_they_grow_not_for_ever() -> None:
    builder = Diagnostics()
    reports = [dataclasses.replace(QUIET, overruns=o, dropped=d)
               for o, d in ((0, 0), (3, 0), (3, 0), (3, 2), (3, 2))]
    assert [levels(builder, f)[0] for f in reports] == [
        DiagnosticStatus.OK, DiagnosticStatus.WARN, DiagnosticStatus.OK, DiagnosticStatus.WARN,
        DiagnosticStatus.OK]


def test_names_and_hardware_id_follow_the_node() -> None:
    assert source_of("/rig1/drill_sim", "/rig1") == Source("rig1/drill_sim", "rig1")
    assert source_of("/a/b/drill_sim", "/a/b") == Source("a/b/drill_sim", "a/b")
    assert source_of("/drill_sim", "/") == Source("drill_sim", "drill_sim_ros")
    statuses = Diagnostics(source_of("/rig1/drill_sim", "/rig1")).message(QUIET, 0).status
    assert [(s.name, s.hardware_id) for s in statuses] == [
        ("rig1/drill_sim: simulation", "rig1"), ("rig1/drill_sim: bit dynamics", "rig1")]
