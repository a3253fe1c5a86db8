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

In the speed and torque modes the motor torque follows its command through a first-order
lag (the drive's torque bandwidth) and then a rate limit (the largest dm/dtau), each off
when its setting says none.

Scaled gains: ``kp = kp_SI / (C t*)``, ``ki = ki_SI / C``, ``max_torque = max_SI / C``,
``max_torque_rate = rate_SI t* / C``.

A limit's "none" is inf here; where a setting cannot hold inf (a ROS double parameter, a
command-line number) it is written 0, and :func:`limit_of_setting` and
:func:`setting_of_limit` are the one decoding of it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields, replace
from typing import Any

from numba import njit

from drill_sim_ros.model.checks import as_number
from drill_sim_ros.model.errors import ParameterError
from drill_sim_ros.model.lag import lag_share, lag_step
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


NO_LIMIT_SETTING = 0.0      # a limit's "none" where a setting has no inf (module doc)


def limit_of_setting(value: float) -> float:
    """The limit of a setting: 0 (``NO_LIMIT_SETTING``) or inf -> inf (none), else itself."""
    return math.inf if value == NO_LIMIT_SETTING else value


def setting_of_limit(limit: float) -> float:
    """The setting of a limit (inverse of :func:`limit_of_setting`): inf -> 0."""
    return NO_LIMIT_SETTING if math.isinf(limit) else limit


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
def within_limit(torque: float, max_torque: float) -> float:
    """``torque`` within the drive's limit, ``|m| <= max_torque`` (inf: no limit): the one
    clip of the motor torque (the speed loop's output and integral, the torque mode's
    command, the motor's torque after its lag and rate limit, the bumpless switch's held
    torque)."""
    return min(max(torque, -max_torque), max_torque)


@njit(cache=True, inline="always")
def speed_loop(omega_ref: float, omega_s: float, integral: float, kp: float, ki: float,
               max_torque: float, dt: float) -> tuple[float, float]:
    """PI speed loop with a torque limit: ``(motor torque, new integral)``.

    The integral (in torque units) is held while the output saturates in the direction the
    error pushes (conditional integration), and never exceeds the limit itself (a limit
    lowered at run time clamps it too).
    """
    err = omega_ref - omega_s
    integral_new = within_limit(integral + ki * err * dt, max_torque)
    unlimited = kp * err + integral_new
    if (unlimited > max_torque and err > 0.0) or (unlimited < -max_torque and err < 0.0):
        integral_new = within_limit(integral, max_torque)   # held (within a lowered limit)
    return within_limit(unlimited, max_torque), integral_new


@njit(cache=True, inline="always")
def drive_acceleration(motor: float, t_string: float, inertia: float) -> float:
    """j domega_s/dtau = m - (PHI_S - PHI): the drive's angular acceleration."""
    return (motor - t_string) / inertia


@njit(cache=True, inline="always")
def motor_response(previous: float, command: float, alpha: float, max_rate: float,
                   max_torque: float, dt: float) -> float:
    """The motor torque after one step: the first-order lag toward ``command`` (within the
    limit already, :func:`lag.lag_step`), then at most ``max_rate * dt`` away from ``previous``
    (the drive's torque rate limit, :func:`ramp`; inf: none, the lagged torque exactly),
    within the limit: a torque that starts beyond it (at t = 0, or the limit lowered at run
    time) is held to it at once, as a drive's current loop holds its torque limit; from
    within the limit the lag and the ramp never leave it."""
    return within_limit(ramp(previous, lag_step(previous, command, alpha), max_rate, dt),
                        max_torque)


@njit(cache=True, inline="always")
def drive_step(mode: int, omega_s: float, omega_ref: float, integral: float, motor: float,
               t_string: float, tgt_omega: float, tgt_torque: float, omega_rate: float,
               inertia: float, kp: float, ki: float, max_torque: float, lag_alpha: float,
               max_torque_rate: float, dt: float) -> tuple[float, float, float, float]:
    """One step of the drive in its mode, against the string torque ``t_string`` at the
    quill: ``(omega_s at the end of the step, omega_ref, integral, motor torque)``. In the
    speed and torque modes the motor torque follows its command through the lag and the
    rate limit (:func:`motor_response`); the kinematic mode's torque is what the imposed
    speed takes."""
    if mode == TD_KINEMATIC:                  # the paper's imposed speed
        omega_next = ramp(omega_s, tgt_omega, omega_rate, dt)
        return omega_next, omega_next, integral, kinematic_torque(omega_s, omega_next,
                                                                  t_string, inertia, dt)
    omega_ref = ramp(omega_ref, tgt_omega, omega_rate, dt)   # an inertia turned by a motor
    if mode == TD_SPEED:
        command, integral = speed_loop(omega_ref, omega_s, integral, kp, ki, max_torque, dt)
    else:
        command = within_limit(tgt_torque, max_torque)
    motor = motor_response(motor, command, lag_alpha, max_torque_rate, max_torque, dt)
    return (omega_s + drive_acceleration(motor, t_string, inertia) * dt, omega_ref, integral,
            motor)


# ---- parameters -------------------------------------------------------------------------
def _check_fields(drive: Any, inertia: str, gains: tuple[str, str], limits: tuple[str, str],
                  lag: str) -> None:
    """ParameterError naming ``top_drive.<field>`` of ``drive`` unless its mode is known, its
    ``inertia`` finite and > 0, its ``gains`` finite and >= 0, its ``limits`` (the torque and
    its rate) > 0 (inf: no limit) and its ``lag`` finite and >= 0: the one check of a drive,
    in either units."""
    mode_index(drive.mode)
    value = getattr(drive, lag)
    if not (math.isfinite(value) and value >= 0.0):
        raise ParameterError(f"parameter 'top_drive.{lag}' = {value!r} must be finite and "
                             ">= 0")
    for name in (inertia, *limits):
        value = getattr(drive, name)
        if math.isnan(value) or value <= 0.0:
            raise ParameterError(f"parameter 'top_drive.{name}' = {value!r} must be > 0")
    for name in gains:
        value = getattr(drive, name)
        if not (math.isfinite(value) and value >= 0.0):
            raise ParameterError(f"parameter 'top_drive.{name}' = {value!r} must be "
                                 "finite and >= 0")
    if not math.isfinite(getattr(drive, inertia)):
        raise ParameterError(f"parameter 'top_drive.{inertia}' must be finite")


@dataclass(frozen=True)
class TopDrive:
    """The drive in kernel units, the paper's scaling (see the module docstring): what the
    :class:`~drill_sim_ros.model.simulator.Simulator` takes.

    mode: 'kinematic' | 'speed' | 'torque'; inertia_ratio: J / I; kp: kp_SI / (C t*);
    ki: ki_SI / C; max_torque: max_SI / C (inf: no limit); motor_lag: time constant of the
    first-order motor torque lag (the drive's torque bandwidth), in t* (0: none);
    max_torque_rate: the largest rate of the motor torque, rate_SI t* / C (inf: no limit).
    The defaults are the field preset's drive (J = 2900 kg m^2 on I = 207 kg m^2).
    """

    mode: str = "kinematic"
    inertia_ratio: float = 14.0
    kp: float = 83.0
    ki: float = 123.0
    max_torque: float = math.inf
    motor_lag: float = 0.0
    max_torque_rate: float = math.inf

    def __post_init__(self) -> None:
        _check_fields(self, "inertia_ratio", ("kp", "ki"), ("max_torque", "max_torque_rate"),
                      "motor_lag")

    def with_(self, **changes: Any) -> TopDrive:
        """A copy with ``changes`` applied (validated)."""
        return replace(self, **changes)

    def physical(self, scales: Scales) -> TopDrivePhysical:
        """The same drive in SI (inverse of :meth:`TopDrivePhysical.scaled`): how a
        dimensionless preset's drive, given in these units, becomes SI once."""
        c, t_star = scales.torque_nm, scales.time_s
        return TopDrivePhysical(mode=self.mode, inertia_kg_m2=self.inertia_ratio * c * t_star**2,
                                kp_nm_s=self.kp * c * t_star, ki_nm=self.ki * c,
                                max_torque_nm=self.max_torque * c,
                                motor_lag_s=self.motor_lag * t_star,
                                max_torque_rate_nm_s=self.max_torque_rate * c / t_star)

    def lag_alpha(self, dtau: float) -> float:
        """The lag's share per step, 1 - exp(-dtau / lag) (1: no lag)."""
        return lag_share(self.motor_lag, dtau)


@dataclass(frozen=True)
class TopDrivePhysical:
    """The drive in SI, referred to the quill: the one description of a drive. It is built
    once, from a preset (``presets.preset_from_dict``, :attr:`Preset.drive`) or from
    sim_node's ``top_drive.*`` parameters (``ros.parameters.top_drive_of``), handed down as
    it is (a change of mode or lag: ``dataclasses.replace``) and converted to kernel units
    once, by :meth:`scaled`, where the session builds or updates its simulator.

    mode; inertia_kg_m2: J; kp_nm_s: proportional gain, N m per rad/s; ki_nm: integral gain,
    N m per rad; max_torque_nm: motor torque limit, N m (inf: no limit); motor_lag_s: time
    constant of the first-order lag of the motor torque behind its command (VFD torque
    bandwidth), s; max_torque_rate_nm_s: the largest rate of change of the motor torque
    after the lag, N m/s (inf: no limit).
    """

    mode: str = "speed"
    inertia_kg_m2: float = 2900.0
    kp_nm_s: float = 23_200.0
    ki_nm: float = 46_400.0
    max_torque_nm: float = 50_000.0
    motor_lag_s: float = 0.0
    max_torque_rate_nm_s: float = math.inf

    def __post_init__(self) -> None:
        _check_fields(self, "inertia_kg_m2", ("kp_nm_s", "ki_nm"),
                      ("max_torque_nm", "max_torque_rate_nm_s"), "motor_lag_s")

    def scaled(self, scales: Scales) -> TopDrive:
        """The paper's scaling: I = C t*^2, so j = J / (C t*^2) (eqs. 19-20)."""
        c, t_star = scales.torque_nm, scales.time_s
        return TopDrive(mode=self.mode, inertia_ratio=self.inertia_kg_m2 / (c * t_star**2),
                        kp=self.kp_nm_s / (c * t_star), ki=self.ki_nm / c,
                        max_torque=self.max_torque_nm / c,
                        motor_lag=self.motor_lag_s / t_star,
                        max_torque_rate=self.max_torque_rate_nm_s * t_star / c)


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
    return cls(**{key: (str(v) if key == "mode" else _float(v)) for key, v in values.items()})


def _float(value: Any) -> float:
    """A checked number (checks.as_number: an integer beyond a double is inf, no limit)."""
    number = as_number(value)
    return float(value) if number is None else number


def paper_drive(scales: Scales) -> TopDrivePhysical:
    """The paper's kinematic drive (the :class:`TopDrive` defaults) in the SI of ``scales``:
    a preset's drive when it gives none."""
    return TopDrive().physical(scales)


def top_drive_from_dict(values: dict[str, Any] | None, scales: Scales,
                        physical: bool) -> TopDrivePhysical:
    """A preset's ``top_drive`` mapping in SI: SI keys (:class:`TopDrivePhysical`) in a
    physical preset; scaled keys (:class:`TopDrive`) in a dimensionless one, turned into SI
    once with its ``scales``; None (no ``top_drive``): the paper's kinematic drive."""
    if values is None:
        return paper_drive(scales)
    if physical:
        return _from_dict(TopDrivePhysical, values)
    return _from_dict(TopDrive, values).physical(scales)
