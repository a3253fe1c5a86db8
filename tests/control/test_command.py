"""A command on its way to the drive: setpoints clamped to sim_node's limits, a motor torque
beyond the drive's limit counted but left to the drive, which applies it within its limit."""

from __future__ import annotations

import math

import numpy as np

from drill_sim_ros.control.command import Command, CommandLimits, apply_command
from drill_sim_ros.model.presets import load_preset
from drill_sim_ros.model.session import SessionConfig, SimSession
from drill_sim_ros.model.telemetry import TELEMETRY_INDEX
from drill_sim_ros.model.top_drive import TopDrivePhysical

F = TELEMETRY_INDEX
LIMITS = CommandLimits(max_surface_rpm=300.0, max_wob_n=1e5)


class RecordingSession:
    """What apply_command hands a session, as it is."""

    def __init__(self, drive: TopDrivePhysical) -> None:
        self.drive = drive
        self.torques_nm: list[float] = []
        self.rpms: list[float] = []

    def set_motor_torque_nm(self, torque_nm: float) -> None:
        self.torques_nm.append(torque_nm)

    def set_surface_rpm(self, rpm: float) -> None:
        self.rpms.append(rpm)


def test_a_torque_beyond_the_limit_is_counted_and_reaches_the_drive_as_it_is() -> None:
    session = RecordingSession(TopDrivePhysical(mode="torque", max_torque_nm=8000.0))
    problems = apply_command(session, Command(motor_torque_nm=-12_000.0), LIMITS)
    assert session.torques_nm == [-12_000.0]                 # not cut on its way
    assert [applied for applied, _ in problems] == [True]    # counted as saturated
    assert "-12000.0 N m is below -8000.0 N m" in problems[0][1]
    assert apply_command(session, Command(motor_torque_nm=7999.0), LIMITS) == []
    problems = apply_command(session, Command(motor_torque_nm=math.nan), LIMITS)
    assert session.torques_nm == [-12_000.0, 7999.0] and problems[0][0] is False
    unlimited = RecordingSession(TopDrivePhysical(mode="torque", max_torque_nm=math.inf))
    assert apply_command(unlimited, Command(motor_torque_nm=1e9), LIMITS) == []
    apply_command(session, Command(speed_rad_s=100.0), LIMITS)     # a setpoint is clamped
    assert session.rpms == [300.0]


def test_the_drive_applies_a_torque_command_within_its_limit() -> None:
    preset = load_preset("field_8p5in_shale_lumped")
    limit_nm = 8000.0
    drive = TopDrivePhysical(mode="torque", inertia_kg_m2=preset.drive.inertia_kg_m2,
                             max_torque_nm=limit_nm)
    session = SimSession(SessionConfig(preset=preset, top_drive=drive))
    for command_nm in (2.5 * limit_nm, -3.0 * limit_nm, 0.5 * limit_nm):
        apply_command(session, Command(motor_torque_nm=command_nm), LIMITS)
        rows = session.run(3).rows             # no lag: the step applies it at once
        expected = min(max(command_nm, -limit_nm), limit_nm)
        np.testing.assert_allclose(rows[:, F["motor_torque_nm"]], expected, rtol=1e-12)
    assert session.drive is drive
