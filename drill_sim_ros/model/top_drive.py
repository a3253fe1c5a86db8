"""The top drive: what turns the top of the drill string (RGD07 eq. 12, extended).

RGD07 imposes the top-of-string angle Omega0 t (the ``kinematic`` mode). A real top drive is
an inertia J (motor, gearbox and quill, referred to the quill) turned by a motor torque:

    J dOmega_s/dt = tau_motor - C (PHI_S - PHI)                      (dimensional)
    j domega_s/dtau = m - (PHI_S - PHI),  j = J / I,  m = tau_motor / C  (paper's scaling)

with the scales of RGD07 eqs. (19)-(20): time t* = sqrt(I/C), torque unit C. So the drive adds
one group, the inertia ratio ``j = J / I``. Modes, one small compiled function each:

* ``kinematic`` (0): the paper's boundary condition, the drive speed follows the (ramped)
  setpoint exactly; the motor torque is whatever that takes.
* ``speed`` (1): the drive's own PI speed loop, ``m = kp e + ki int e dtau`` with
  ``e = omega_ref - omega_s``, anti-windup by conditional integration, ``|m| <= max_torque``.
* ``torque`` (2): the motor torque is commanded from outside, ``|m| <= max_torque``.

Scaled gains: ``kp = kp_SI / (C t*)``, ``ki = ki_SI / C``, ``max_torque = max_SI / C``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields, replace
from typing import Any

from numba import njit

from drill_sim_ros.model.errors import ParameterError
from drill_sim_ros.model.params import Scales

TD_KINEMATIC = 0
TD_SPEED = 1
TD_TORQUE = 2
MODES = ("kinematic", "speed", "torque")


def mode_index(mode: str) -> int:
    """The integer of ``mode`` in the parameter vector; ParameterError if unknown."""
    if mode not in MODES:
        raise ParameterError(f"parameter 'top_drive.mode' = {mode!r} must be one of {MODES}")
    return MODES.index(mode)


# ---- the modes (compiled) -------------------------------------------------------------
@njit(cache=True, inline="always")
def ramp(current: float, target: float, max_rate: float, dt: float) -> float:
    """Move ``current`` toward ``target`` by at most ``max_rate * dt``."""
    step = max_rate * dt
    if target > current + step:
        return current + step
    if target < current - step:
        return current - step
    return target


@njit(cache=True, inline="always")
def kinematic_torque(omega_s: float, omega_next: float, t_string: float, inertia: float,
                     dt: float) -> float:
    """Motor torque that moves the drive from ``omega_s`` to ``omega_next`` in one step
    against the string torque (eq. 12 extended, solved for the motor torque)."""
    return t_string + inertia * (omega_next - omega_s) / dt


@njit(cache=True, inline="always")
def speed_loop(omega_ref: float, omega_s: float, integral: float, kp: float, ki: float,
               max_torque: float, dt: float) -> tuple[float, float]:
    """PI speed loop with a torque limit: ``(motor torque, new integral)``.

    The integral (in torque units) is held while the output saturates in the direction the
    error pushes (conditional integration), and never exceeds the limit itself (a limit
    lowered at run time clamps it too).
    """
    err = omega_ref - omega_s
    held = min(max(integral, -max_torque), max_torque)
    integral_new = min(max(integral + ki * err * dt, -max_torque), max_torque)
    motor = kp * err + integral_new
    if motor > max_torque:
        motor = max_torque
        if err > 0.0:
            integral_new = held
    elif motor < -max_torque:
        motor = -max_torque
        if err < 0.0:
            integral_new = held
    return motor, integral_new


@njit(cache=True, inline="always")
def torque_command(command: float, max_torque: float) -> float:
    """The commanded motor torque within the drive's limit."""
    return min(max(command, -max_torque), max_torque)


@njit(cache=True, inline="always")
def drive_acceleration(motor: float, t_string: float, inertia: float) -> float:
    """j domega_s/dtau = m - (PHI_S - PHI): the drive's angular acceleration."""
    return (motor - t_string) / inertia


@njit(cache=True, inline="always")
def motor_lag(previous: float, command: float, alpha: float) -> float:
    """First-order motor torque lag (the drive's torque bandwidth): the torque moves by
    ``alpha = 1 - exp(-dtau / lag)`` of the way to the command each step (1: no lag)."""
    if alpha >= 1.0:
        return command
    return previous + alpha * (command - previous)


@njit(cache=True, inline="always")
def drive_step(mode: int, omega_s: float, omega_ref: float, integral: float, motor: float,
               t_string: float, tgt_omega: float, tgt_torque: float, omega_rate: float,
               inertia: float, kp: float, ki: float, max_torque: float, lag_alpha: float,
               dt: float) -> tuple[float, float, float, float]:
    """One step of the drive in its mode, against the string torque ``t_string`` at the
    quill: ``(omega_s at the end of the step, omega_ref, integral, motor torque)``."""
    if mode == TD_KINEMATIC:                  # the paper's imposed speed
        omega_next = ramp(omega_s, tgt_omega, omega_rate, dt)
        return omega_next, omega_next, integral, kinematic_torque(omega_s, omega_next,
                                                                  t_string, inertia, dt)
    omega_ref = ramp(omega_ref, tgt_omega, omega_rate, dt)   # an inertia turned by a motor
    if mode == TD_SPEED:
        command, integral = speed_loop(omega_ref, omega_s, integral, kp, ki, max_torque, dt)
    else:
        command = torque_command(tgt_torque, max_torque)
    motor = motor_lag(motor, command, lag_alpha)
    return (omega_s + drive_acceleration(motor, t_string, inertia) * dt, omega_ref, integral,
            motor)


# ---- parameters -------------------------------------------------------------------------
@dataclass(frozen=True)
class TopDrive:
    """The drive in the paper's scaling (see the module docstring).

    mode: 'kinematic' | 'speed' | 'torque'; inertia_ratio: J / I; kp: kp_SI / (C t*);
    ki: ki_SI / C; max_torque: max_SI / C (inf: no limit); motor_lag: time constant of the
    first-order motor torque lag (the drive's torque bandwidth), in t* (0: none).
    The defaults are the field preset's drive (J = 2900 kg m^2 on I = 207 kg m^2).
    """

    mode: str = "kinematic"
    inertia_ratio: float = 14.0
    kp: float = 83.0
    ki: float = 123.0
    max_torque: float = math.inf
    motor_lag: float = 0.0

    def __post_init__(self) -> None:
        mode_index(self.mode)
        if not (math.isfinite(self.motor_lag) and self.motor_lag >= 0.0):
            raise ParameterError(f"parameter 'top_drive.motor_lag' = {self.motor_lag!r} must "
                                 "be finite and >= 0")
        for name in ("inertia_ratio", "max_torque"):
            value = getattr(self, name)
            if math.isnan(value) or value <= 0.0:
                raise ParameterError(f"parameter 'top_drive.{name}' = {value!r} must be > 0")
        for name in ("kp", "ki"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value >= 0.0):
                raise ParameterError(f"parameter 'top_drive.{name}' = {value!r} must be "
                                     "finite and >= 0")
        if not math.isfinite(self.inertia_ratio):
            raise ParameterError("parameter 'top_drive.inertia_ratio' must be finite")

    def with_(self, **changes: Any) -> TopDrive:
        """A copy with ``changes`` applied (validated)."""
        return replace(self, **changes)

    def physical(self, scales: Scales) -> TopDrivePhysical:
        """The same drive in SI (inverse of :meth:`TopDrivePhysical.scaled`)."""
        c, t_star = scales.torque_nm, scales.time_s
        return TopDrivePhysical(mode=self.mode, inertia_kg_m2=self.inertia_ratio * c * t_star**2,
                                kp_nm_s=self.kp * c * t_star, ki_nm=self.ki * c,
                                max_torque_nm=self.max_torque * c,
                                motor_lag_s=self.motor_lag * t_star)

    def lag_alpha(self, dtau: float) -> float:
        """The lag's share per step, 1 - exp(-dtau / lag) (1: no lag)."""
        return 1.0 if self.motor_lag == 0.0 else -math.expm1(-dtau / self.motor_lag)


@dataclass(frozen=True)
class TopDrivePhysical:
    """The drive in SI, referred to the quill.

    mode; inertia_kg_m2: J; kp_nm_s: proportional gain, N m per rad/s; ki_nm: integral gain,
    N m per rad; max_torque_nm: motor torque limit, N m; motor_lag_s: time constant of the
    first-order lag of the motor torque behind its command (VFD torque bandwidth), s.
    """

    mode: str = "speed"
    inertia_kg_m2: float = 2900.0
    kp_nm_s: float = 23_200.0
    ki_nm: float = 46_400.0
    max_torque_nm: float = 50_000.0
    motor_lag_s: float = 0.0

    def scaled(self, scales: Scales) -> TopDrive:
        """The paper's scaling: I = C t*^2, so j = J / (C t*^2) (eqs. 19-20)."""
        c, t_star = scales.torque_nm, scales.time_s
        return TopDrive(mode=self.mode, inertia_ratio=self.inertia_kg_m2 / (c * t_star**2),
                        kp=self.kp_nm_s / (c * t_star), ki=self.ki_nm / c,
                        max_torque=self.max_torque_nm / c,
                        motor_lag=self.motor_lag_s / t_star)


def check_speed_loop(drive: TopDrive, dtau: float, scales: Scales) -> None:
    """The speed loop as stepped (explicit, on the drive's inertia) is stable: with
    a = kp dtau / j and b = ki dtau^2 / j, the closed loop's poles lie inside the unit circle
    when a < 2 and 2 a + b < 4 (Jury's test on z^2 - (2 - a - b) z + (1 - a)); else one line
    naming the gain, its value and the largest kp that holds at this step."""
    a = drive.kp * dtau / drive.inertia_ratio
    b = drive.ki * dtau**2 / drive.inertia_ratio
    if a < 2.0 and 2.0 * a + b < 4.0:
        return
    si = drive.physical(scales)
    if b < 4.0:       # a smaller kp is stable at this ki
        kp_max = min(2.0, (4.0 - b) / 2.0) * drive.inertia_ratio / dtau * scales.torque_nm \
            * scales.time_s
        bound = f"kp_nm_s < {kp_max:.6g} holds at this ki_nm"
    else:             # no kp is: ki alone breaks the second condition
        bound = f"ki_nm < {4.0 * drive.inertia_ratio / dtau**2 * scales.torque_nm:.6g} is needed"
    raise ParameterError(
        f"top_drive.kp_nm_s = {si.kp_nm_s:.6g} (ki_nm = {si.ki_nm:.6g}) makes the drive's "
        f"speed loop unstable at this time step: kp dt / J = {a:.3g} must be < 2 and "
        f"2 kp dt / J + ki dt^2 / J = {2 * a + b:.3g} must be < 4; {bound}")


def _from_dict(cls: type, values: dict[str, Any]) -> Any:
    known = {f.name for f in fields(cls)}
    unknown = sorted(set(values) - known)
    if unknown:
        raise ParameterError(f"unknown top_drive parameter(s) {unknown}; known: {sorted(known)}")
    return cls(**{key: (str(v) if key == "mode" else float(v)) for key, v in values.items()})


def top_drive_from_dict(values: dict[str, Any], scales: Scales, physical: bool) -> TopDrive:
    """A preset's ``top_drive`` mapping: SI keys (:class:`TopDrivePhysical`) for a physical
    preset, scaled keys (:class:`TopDrive`) for a dimensionless one."""
    if physical:
        return _from_dict(TopDrivePhysical, values).scaled(scales)
    return _from_dict(TopDrive, values)
