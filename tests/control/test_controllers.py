"""The reference controllers on the field preset, in process (issue 12).

Expectations come from the physics, not from earlier runs:
- stick-slip is a bit that stops: with ``stiff`` (a stiff speed loop, the top a nearly fixed
  speed end) the bit still stops in every 20 s window after the switch-on;
- ``soft_torque`` and ``z_torque`` make the top a damper of the torsional mode: after
  settling (the last 60 s) the bit never sticks and its speed stays above half the setpoint
  (no stick-slip cycle), in both modes;
- before the switch-on every controller sends the operator's setpoint, so the run is the
  uncontrolled one, bit for bit;
- the tuning formulas, checked on hand-made signals.
"""

from __future__ import annotations

import math
from functools import cache

import numpy as np
import pytest

from drill_sim_ros.control.bench import run_in_process
from drill_sim_ros.control.command import SurfaceMeasurement
from drill_sim_ros.control.controllers import SoftTorque, Stiff, ZTorque
from drill_sim_ros.control.rig import rig_physics
from drill_sim_ros.control.scenario import Scenario
from drill_sim_ros.control.schedule import Schedule
from drill_sim_ros.model.presets import load_preset
from drill_sim_ros.model.telemetry import TELEMETRY_INDEX

F = TELEMETRY_INDEX
PRESET = load_preset("field_8p5in_shale_lumped")
RIG = rig_physics(PRESET)
RPM0 = PRESET.physical.surface_rpm
ENABLE_S, END_S = 60.0, 180.0


@cache
def run(controller: str, mode: str) -> np.ndarray:
    scenario = Scenario(
        preset="field_8p5in_shale_lumped",
        controller=controller,
        mode=mode,
        duration_s=END_S,
        enable_at_s=ENABLE_S,
    )
    return run_in_process(scenario).rows


def between(rows: np.ndarray, start_s: float, end_s: float) -> np.ndarray:
    t = rows[:, F["sim_time_s"]]
    return rows[(t > start_s) & (t <= end_s)]


@pytest.mark.parametrize("mode", ["speed", "torque"])
def test_stiff_leaves_stick_slip(mode: str) -> None:
    rows = run("stiff", mode)
    for start_s in np.arange(ENABLE_S, END_S, 20.0):
        window = between(rows, start_s, start_s + 20.0)
        assert (window[:, F["mode"]] == 2).any(), start_s  # the bit stops
        assert window[:, F["bit_rpm"]].max() > 1.5 * RPM0  # and slips (RGD07 Fig. 8: ~2 x)


@pytest.mark.parametrize("mode", ["speed", "torque"])
@pytest.mark.parametrize("controller", ["soft_torque", "z_torque"])
def test_soft_controllers_remove_stick_slip(controller: str, mode: str) -> None:
    rows = run(controller, mode)
    before = between(rows, 20.0, ENABLE_S)
    assert (before[:, F["mode"]] == 2).any()  # it was there
    settled = between(rows, END_S - 60.0, END_S)
    assert not (settled[:, F["mode"]] == 2).any()
    assert settled[:, F["bit_rpm"]].min() > 0.5 * RPM0
    # the mean drive speed stays the operator's (the high-pass keeps the mean)
    assert settled[:, F["surface_rpm"]].mean() == pytest.approx(RPM0, rel=0.02)


def test_before_the_switch_on_every_controller_is_the_uncontrolled_rig() -> None:
    none = between(run("none", "speed"), 0.0, ENABLE_S)
    for controller in ("stiff", "soft_torque", "z_torque"):
        rows = between(run(controller, "speed"), 0.0, ENABLE_S)
        assert np.array_equal(rows, none), controller
    assert np.array_equal(run("stiff", "speed"), run("none", "speed"))  # the drive's loop


def measurement(t_s: float, speed: float, motor: float, string: float) -> SurfaceMeasurement:
    return SurfaceMeasurement(t_s, speed, motor, string)


def test_soft_torque_is_a_damper_of_the_lumped_mode_by_hand() -> None:
    """c = sqrt(C I) / (2 zeta) from s^2 + (C/c) s + C/I = 0; the high-pass of a torque step
    decays as exp(-w_hp t)."""
    schedule = Schedule(RPM0, 60e3)
    ctrl = SoftTorque(RIG, schedule, period_s=0.01, damping_ratio=0.25, highpass_rad_s=0.5)
    c = math.sqrt(RIG.stiffness_nm_rad * RIG.bit_inertia_kg_m2) / 0.5
    assert ctrl.damping_nm_s == pytest.approx(c, rel=1e-12)
    omega0 = RPM0 * 2 * math.pi / 60
    ctrl.update(measurement(0.01, omega0, 3000.0, 3000.0))  # filter starts at 3000
    cmd = ctrl.update(measurement(0.02, omega0, 4000.0, 4000.0))  # a 1 kN m step
    alpha = 1 - math.exp(-0.5 * 0.01)
    assert cmd.speed_rad_s == pytest.approx(omega0 - 1000.0 * (1 - alpha) / c, rel=1e-12)
    assert cmd.wob_n == 60e3


def test_z_torque_estimates_the_string_torque_from_the_drive() -> None:
    """J domega/dt = tau_m - T: a drive accelerating at a rad/s^2 under tau_m has
    T = tau_m - J a."""
    ctrl = ZTorque(RIG, Schedule(RPM0, 60e3), period_s=0.01)
    accel, motor = 0.8, 9000.0
    speeds = 6.0 + accel * 0.01 * np.arange(5)
    estimates = [
        ctrl.string_torque_estimate_nm(measurement(0.01 * i, w, motor, 0.0))
        for i, w in enumerate(speeds)
    ]
    expected = motor - RIG.drive_inertia_kg_m2 * accel
    np.testing.assert_allclose(estimates[1:], expected, rtol=1e-9)
    assert ctrl.params["impedance_nm_s"] == pytest.approx(
        0.5 * math.pi * (0.0635**4 - 0.0543**4) * math.sqrt(79.3e9 * 7850.0), rel=1e-12
    )


def test_torque_mode_loop_is_critically_damped_on_the_drive() -> None:
    """kp = 2 J w_c, ki = J w_c^2: a speed error e gives kp e + ki e P at the first step."""
    ctrl = Stiff(RIG, Schedule(RPM0, 60e3), mode="torque", period_s=0.01, loop_bandwidth_rad_s=4.0)
    omega0 = RPM0 * 2 * math.pi / 60
    cmd = ctrl.update(measurement(0.01, omega0 - 0.1, 3000.0, 3000.0))
    j = RIG.drive_inertia_kg_m2
    assert cmd.speed_rad_s is None
    assert cmd.motor_torque_nm == pytest.approx(
        3000.0 + 2 * j * 4.0 * 0.1 + j * 16.0 * 0.1 * 0.01, rel=1e-12
    )


def test_speed_references_stay_within_the_drive_limits() -> None:
    ctrl = SoftTorque(RIG, Schedule(RPM0, 60e3), period_s=0.01)
    ctrl.update(measurement(0.01, 6.0, 0.0, 0.0))
    cmd = ctrl.update(measurement(0.02, 6.0, 0.0, 1e6))  # a huge torque: reference < 0
    assert cmd.speed_rad_s == 0.0
    assert ctrl.clamped_commands == 1
