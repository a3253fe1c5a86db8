"""The reference controllers on the field preset, in process (issue 12).

Expectations come from the physics, not from earlier runs:
- stick-slip is a bit that stops: with ``stiff`` (a stiff speed loop, the top a nearly fixed
  speed end) the bit still stops in every 20 s window after the switch-on;
- ``soft_torque`` and ``z_torque`` make the top a damper of the torsional mode (the drive
  moves as the impedance they emulate, checked against a drive written from its physics): after
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


@pytest.mark.parametrize("controller", [SoftTorque, ZTorque])
def test_the_drive_moves_as_the_emulated_impedance(controller: type) -> None:
    """The controller in the loop of a drive written here from its physics (J dw/dt =
    kp e + ki int e - T, semi-implicit at 0.1 ms, the setpoint held over each 10 ms period):
    under a string torque T = T0 + A sin(w t) the drive's speed swings by A |Y(iw)| with
    Y = 1 / (J_v s + kp_d + ki_d / s), the emulated admittance (a zero-order hold's error,
    w P / 2, is below 1 % here)."""
    ctrl = controller(RIG, Schedule(RPM0, 60e3), period_s=0.01)
    j_v, kp_d, ki_d = ctrl.virtual_gains()
    j, kp, ki = RIG.drive_inertia_kg_m2, RIG.drive_kp_nm_s, RIG.drive_ki_nm
    omega0 = RPM0 * 2 * math.pi / 60
    for w_rad_s in (0.5, RIG.first_mode_rad_s, 3.0):
        ctrl.reset()
        speed, integral, t0, amp, dt = omega0, 3000.0, 3000.0, 500.0, 1e-4
        ref, speeds = omega0, []
        for k in range(int(120.0 / dt)):
            t = k * dt
            if k % 100 == 0:
                torque = t0 + amp * math.sin(w_rad_s * t)
                ref = ctrl.update(measurement(t, speed, 0.0, torque)).speed_rad_s
            torque = t0 + amp * math.sin(w_rad_s * t)
            integral += ki * (ref - speed) * dt
            speed += (kp * (ref - speed) + integral - torque) * dt / j
            speeds.append(speed)
        tail = np.array(speeds[-int(4 * math.pi / w_rad_s / dt):])
        s = 1j * w_rad_s
        expected = amp / abs(j_v * s + kp_d + ki_d / s)
        assert (tail.max() - tail.min()) / 2 == pytest.approx(expected, rel=0.03), w_rad_s
        assert tail.mean() == pytest.approx(omega0, rel=1e-3)       # the mean is the setpoint


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


@pytest.mark.parametrize("controller", [SoftTorque, ZTorque])
def test_a_held_bit_does_not_wind_up_the_emulated_loop(controller: type) -> None:
    """The bit held with the string torque at the drive's limit: the emulated drive's PI
    loop sits at the limit, and its integral is held there (conditional integration, as the
    drive's own loop, model.top_drive.speed_loop). So once the bit is free, the speed
    reference is the same whether the hold lasted 60 s or 120 s; an integral that kept
    integrating the speed error would hold the reference at the limit for longer the
    longer the hold, and overspeed the top after the release."""
    omega0, limit, drilling_nm = RPM0 * 2 * math.pi / 60, RIG.max_torque_nm, 3000.0

    def after_release(hold_s: float) -> np.ndarray:
        ctrl = controller(RIG, Schedule(RPM0, 60e3), period_s=0.01)
        refs, t = [], 0.0
        for torque, lasts_s in ((drilling_nm, 10.0), (limit, hold_s), (drilling_nm, 30.0)):
            for _ in range(round(lasts_s / 0.01)):
                t += 0.01
                refs.append(ctrl.update(measurement(t, omega0, torque, torque)).speed_rad_s)
        return np.array(refs[-3000:])

    short, long = after_release(60.0), after_release(120.0)
    assert np.max(np.abs(short - long)) < 1e-3 * omega0
