"""Reference top-drive controllers: stiff, soft_torque, z_torque (SI, ROS-free).

Each controller runs at the control period (one publish period of the sim) on the rig's
SURFACE measurements only (:class:`~drill_sim_ros.control.command.SurfaceMeasurement`) and
answers with a :class:`~drill_sim_ros.control.command.Command`. Its core is a speed
reference omega_ref(t) built from the operator's setpoint omega_0(t) (the
:class:`~drill_sim_ros.control.schedule.Schedule`); the mode decides what is sent:

* ``speed``: omega_ref is the setpoint of the drive's own PI speed loop;
* ``torque``: the controller closes its own PI speed loop on omega_ref and sends the motor
  torque (``model.top_drive.speed_loop``, the same loop as the drive's, with anti-windup),
  gains kp = 2 J w_c, ki = J w_c^2 (critically damped on the drive's inertia J) for a
  bandwidth w_c = ``loop_bandwidth_rad_s`` (default 3 omega_1, as the field drive's).

Before ``enable_at_s`` every controller sends omega_ref = omega_0 (the drive as delivered);
its filters run from the first sample, so it switches on without a start-up transient.

The references (Z, C, I, J, omega_1 from :mod:`drill_sim_ros.control.rig`):

* ``stiff``: omega_ref = omega_0. With a stiff loop the top of the string is nearly a fixed
  speed end, which reflects torsional waves and lets stick-slip through (the baseline).
* ``soft_torque`` (torque feedback, the SoftTorque/SoftSpeed family: Halsey, Kyllingstad &
  Kylling 1988, SPE 18049; Kyllingstad & Nessjoen 2009, SPE/IADC 119660):
  omega_ref = omega_0 - HP(T_sub) / c, the string torque of the torque sub high-pass
  filtered (first order, corner ``highpass_rad_s``, default omega_1 / 5, so the mean torque
  does not lower the mean speed and the phase at omega_1 is within 12 degrees). The top then
  acts, near omega_1, as a damper c in series with the pipe; for the lumped mode (bit inertia
  I on the spring C, RGD07 eq. 1) s^2 + (C/c) s + C/I = 0, so the damping ratio is
  zeta = sqrt(C I) / (2 c) and c = sqrt(C I) / (2 zeta) (``damping_ratio``, default 0.5).
* ``z_torque`` (impedance matching, the Z-Torque family: Dwars 2015, SPE/IADC-173037-MS):
  the string torque is estimated from the drive alone, T_est = tau_motor - J d omega_s/dt
  (backward difference of the encoder over one period), low-passed at ``estimate_rad_s``
  (default 2 omega_1: in speed mode the motor torque is sampled at the end of a period while
  the speed difference measures its mean over the period; the drive's loop makes the two
  differ by about kp dw / 2, which feeds back through 1/Z with a gain of kp P / (2 Z) ~ 40
  per period on the field drive and, filtered less, sets the drive oscillating against its
  torque limit), and the speed reference follows it
  through the pipe's characteristic impedance: omega_ref = omega_0 - (T_est - <T_est>) / Z,
  Z = J_p sqrt(G rho) (``impedance_nm_s``), the mean <T_est> tracked by a first-order
  low-pass at ``mean_rad_s`` (default omega_1 / 5). A top end moving at -T/Z absorbs an
  arriving torsional wave without reflection.
"""

from __future__ import annotations

import math
from typing import Any, ClassVar

from drill_sim_ros.control.command import Command, SurfaceMeasurement
from drill_sim_ros.control.rig import RigPhysics
from drill_sim_ros.control.schedule import Schedule
from drill_sim_ros.model.errors import ParameterError
from drill_sim_ros.model.params import RPM_PER_RAD_S
from drill_sim_ros.model.top_drive import speed_loop

CONTROL_MODES = ("speed", "torque")
MAX_PARAMETER = 1e9     # every parameter is a positive number at most this (SI)


class LowPass:
    """First-order low-pass, exact for a signal held over each period: y += a (x - y),
    a = 1 - exp(-w_c P). Starts at its first input."""

    def __init__(self, corner_rad_s: float, period_s: float) -> None:
        self.alpha = 1.0 - math.exp(-corner_rad_s * period_s)
        self.value: float | None = None

    def update(self, x: float) -> float:
        self.value = x if self.value is None else self.value + self.alpha * (x - self.value)
        return self.value


class TopDriveController:
    """The shared frame: schedule, switch-on, speed or torque output, limits.

    Subclasses set ``name`` and ``PARAMS`` ({name: description with unit}), derive their
    defaults in :meth:`defaults` and compute :meth:`reference_rad_s`. Call :meth:`update`
    once per control period with the newest measurement (None before the first one).
    """

    name = "base"
    PARAMS: ClassVar[dict[str, str]] = {
        "loop_bandwidth_rad_s": "bandwidth of the controller's own PI speed loop in torque "
                                "mode, rad/s (default 3 omega_1)",
    }

    def __init__(self, rig: RigPhysics, schedule: Schedule, mode: str = "speed",
                 period_s: float = 0.01, enable_at_s: float = 0.0, **params: float) -> None:
        if mode not in CONTROL_MODES:
            raise ParameterError(f"controller mode {mode!r} must be one of {CONTROL_MODES}")
        if not (math.isfinite(period_s) and period_s > 0):
            raise ParameterError(f"control period {period_s!r} s must be > 0")
        self.rig, self.schedule, self.mode = rig, schedule, mode
        self.period_s, self.enable_at_s = float(period_s), float(enable_at_s)
        self.params = {**self.defaults(), **self._checked(params)}
        self.reset()

    def defaults(self) -> dict[str, float]:
        return {"loop_bandwidth_rad_s": 3.0 * self.rig.first_mode_rad_s}

    def _checked(self, params: dict[str, Any]) -> dict[str, float]:
        known = set(self.defaults())
        for key, value in params.items():
            if key not in known:
                raise ParameterError(f"controller {self.name!r} has no parameter {key!r}; "
                                     f"known: {sorted(known)}")
            if isinstance(value, bool) or not isinstance(value, (int, float)) or \
                    not (math.isfinite(value) and 0 < value <= MAX_PARAMETER):
                raise ParameterError(f"controller parameter {key!r} = {value!r} is outside "
                                     f"(0, {MAX_PARAMETER:g}]")
        return {key: float(value) for key, value in params.items()}

    def reset(self) -> None:
        """Forget all state (filters, loop integral, counters)."""
        self._integral_nm: float | None = None
        self.clamped_commands = 0

    def reference_rad_s(self, m: SurfaceMeasurement, nominal_rad_s: float) -> float:
        """The speed reference from the measurement (called every period, also before the
        switch-on, so filters stay warm)."""
        return nominal_rad_s

    def active(self, time_s: float) -> bool:
        return time_s >= self.enable_at_s

    def update(self, m: SurfaceMeasurement | None) -> Command:
        """The command of this control period."""
        time_s = 0.0 if m is None else m.time_s
        nominal = self.schedule.rpm_at(time_s) / RPM_PER_RAD_S
        wob_n = self.schedule.wob_at(time_s)
        if m is None:                              # no measurement yet: the setpoints
            return Command(speed_rad_s=nominal if self.mode == "speed" else None, wob_n=wob_n)
        reference = self.reference_rad_s(m, nominal)
        speed = self._within_speed_limits(reference if self.active(time_s) else nominal)
        if self.mode == "speed":
            return Command(speed_rad_s=speed, wob_n=wob_n)
        return Command(motor_torque_nm=self._torque_loop(speed, m), wob_n=wob_n)

    def _within_speed_limits(self, speed_rad_s: float) -> float:
        top = self.rig.max_surface_rpm / RPM_PER_RAD_S
        if 0.0 <= speed_rad_s <= top:
            return speed_rad_s
        self.clamped_commands += 1
        return min(max(speed_rad_s, 0.0), top)

    def _torque_loop(self, reference_rad_s: float, m: SurfaceMeasurement) -> float:
        """PI speed loop on the drive's inertia (model.top_drive.speed_loop), starting from
        the measured motor torque (no bump)."""
        w_c, j = self.params["loop_bandwidth_rad_s"], self.rig.drive_inertia_kg_m2
        if self._integral_nm is None:
            self._integral_nm = m.motor_torque_nm
        limit = self.rig.max_torque_nm
        torque, self._integral_nm = speed_loop(reference_rad_s, m.drive_speed_rad_s,
                                               self._integral_nm, 2.0 * j * w_c, j * w_c**2,
                                               limit, self.period_s)
        if abs(torque) >= limit:
            self.clamped_commands += 1
        return float(torque)


class Stiff(TopDriveController):
    """A stiff PI speed loop on the operator's setpoint (the baseline)."""

    name = "stiff"


class SoftTorque(TopDriveController):
    """Torque feedback through a high-pass filter, tuned to the lumped first mode."""

    name = "soft_torque"
    PARAMS: ClassVar[dict[str, str]] = {**TopDriveController.PARAMS,
              "damping_ratio": "damping ratio of the lumped mode with an ideal speed loop; "
                               "c = sqrt(C I) / (2 zeta) (default 0.5)",
              "highpass_rad_s": "corner of the torque high-pass, rad/s (default omega_1 / 5)"}

    def defaults(self) -> dict[str, float]:
        return {**super().defaults(), "damping_ratio": 0.5,
                "highpass_rad_s": self.rig.first_mode_rad_s / 5.0}

    def reset(self) -> None:
        super().reset()
        self._mean = LowPass(self.params["highpass_rad_s"], self.period_s)

    @property
    def damping_nm_s(self) -> float:
        """c = sqrt(C I) / (2 zeta), N m s/rad."""
        return self.rig.lumped_impedance_nm_s / (2.0 * self.params["damping_ratio"])

    def reference_rad_s(self, m: SurfaceMeasurement, nominal_rad_s: float) -> float:
        high_nm = m.string_torque_nm - self._mean.update(m.string_torque_nm)
        return nominal_rad_s - high_nm / self.damping_nm_s


class ZTorque(TopDriveController):
    """Impedance matching on the string torque estimated from the drive."""

    name = "z_torque"
    PARAMS: ClassVar[dict[str, str]] = {**TopDriveController.PARAMS,
              "impedance_nm_s": "Z, N m s/rad (default J_p sqrt(G rho) of the drill pipe)",
              "mean_rad_s": "corner of the mean-torque tracker, rad/s (default omega_1 / 5)",
              "estimate_rad_s": "corner of the low-pass on the torque estimate, rad/s "
                                "(default 2 omega_1)"}

    def defaults(self) -> dict[str, float]:
        w1 = self.rig.first_mode_rad_s
        return {**super().defaults(), "impedance_nm_s": self.rig.impedance_nm_s,
                "mean_rad_s": w1 / 5.0, "estimate_rad_s": 2.0 * w1}

    def reset(self) -> None:
        super().reset()
        self._mean = LowPass(self.params["mean_rad_s"], self.period_s)
        self._estimate = LowPass(self.params["estimate_rad_s"], self.period_s)
        self._last_speed: float | None = None

    def string_torque_estimate_nm(self, m: SurfaceMeasurement) -> float:
        """T_est = tau_motor - J (omega_k - omega_k-1) / P (J omega_dot = tau_m - T)."""
        last = m.drive_speed_rad_s if self._last_speed is None else self._last_speed
        self._last_speed = m.drive_speed_rad_s
        accel = (m.drive_speed_rad_s - last) / self.period_s
        return m.motor_torque_nm - self.rig.drive_inertia_kg_m2 * accel

    def reference_rad_s(self, m: SurfaceMeasurement, nominal_rad_s: float) -> float:
        torque_nm = self._estimate.update(self.string_torque_estimate_nm(m))
        high_nm = torque_nm - self._mean.update(torque_nm)
        return nominal_rad_s - high_nm / self.params["impedance_nm_s"]
