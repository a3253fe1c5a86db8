"""Reference top-drive controllers: stiff, soft_torque, z_torque (SI, ROS-free).

Each controller runs at the control period (one publish period of the sim) on the rig's
SURFACE measurements only (:class:`~drill_sim_ros.control.command.SurfaceMeasurement`) and
answers with a :class:`~drill_sim_ros.control.command.Command`. Its core is a speed
reference omega_ref(t) built from the operator's setpoint omega_0(t) (the
:class:`~drill_sim_ros.control.schedule.Schedule`); the mode decides what is sent:

* ``speed``: omega_ref is the setpoint of the drive's own PI speed loop;
* ``torque``: the controller closes its own PI speed loop on omega_ref and sends the motor
  torque (``model.top_drive.speed_loop``, the same loop as the drive's, with anti-windup),
  gains :meth:`TopDriveController.loop_gains`: by default kp = 2 J w_c, ki = J w_c^2
  (critically damped on the drive's inertia J) for a bandwidth w_c =
  ``loop_bandwidth_rad_s`` (default 3 omega_1, as the field drive's); a subclass sets kp
  and ki independently by overriding it.

Before ``enable_at_s`` every controller sends omega_ref = omega_0 (the drive as delivered);
its filters run from the first sample, so it switches on without a start-up transient.

The references (Z, C, I, J, omega_1 from :mod:`drill_sim_ros.control.rig`):

* ``stiff``: omega_ref = omega_0. With a stiff loop the top of the string is nearly a fixed
  speed end, which reflects torsional waves and lets stick-slip through (the baseline).
* ``soft_torque`` and ``z_torque`` (:class:`SoftDrive`) emulate a softer drive through the
  setpoint: the torque sub's string torque T drives a virtual rotor J_v under a virtual PI
  loop (kp_d, ki_d), and the setpoint makes the real drive move as that rotor, so the top
  meets the string with the impedance J_v s + kp_d + ki_d / s. ki_d = J_v omega_1^2 cancels
  the reactance at the first mode, where the top is then the damper kp_d, and
  |r| = |Z - kp_d| / (Z + kp_d).
  ``soft_torque`` (the SoftSpeed family: Kyllingstad & Nessjoen 2009, SPE/IADC 119660):
  kp_d = 2 Z (``impedance_factor``), J_v = J / 5; ``z_torque`` (impedance matching, the
  ZTorque family: Dwars 2015, SPE/IADC-173037-MS): kp_d = Z (``impedance_nm_s``),
  J_v = 0.15 J (``inertia_fraction``).
  Why this form (docs/closed-loop.md): a high-pass of T fed to the setpoint (the previous
  designs) made the drive return up to 1.07 of every wave above 5 Hz (the zero-order hold
  and the stiff loop's lag turn its phase), pumping the collars' ring until the motor hit
  its limit; a low-pass made it worse. Emulating an impedance stays within 0.6 % of
  passive there, and a damper in series with it (``hold_margin``,
  :meth:`SoftDrive.droop_per_nm_s`) makes it passive up to a sixth of the control rate.
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
HOLD_PHASE_RAD = math.pi / 3    # the series damper's phase at a sixth of the control rate
MAX_HOLD_PHASE_RAD = 1.2        # ... beyond which a motor's lag leaves no band to keep


class LowPass:
    """First-order low-pass 1 / (1 + s / w_c), exact for a signal held over each period P:
    y += a (x - y), a = 1 - exp(-w_c P). Its corner w_c is in rad/s (a corner of f Hz is
    ``LowPass(2 * math.pi * f, period_s)``). Starts at its first input; :meth:`update`
    returns the filtered value, ``value`` holds it (None before the first input)."""

    def __init__(self, corner_rad_s: float, period_s: float) -> None:
        self.alpha = 1.0 - math.exp(-corner_rad_s * period_s)
        self.value: float | None = None

    def update(self, x: float) -> float:
        self.value = x if self.value is None else self.value + self.alpha * (x - self.value)
        return self.value


class TopDriveController:
    """The shared frame: schedule, switch-on, speed or torque output, limits.

    Built as ``Class(rig, schedule, mode, period_s, enable_at_s, **params)`` (the bench and
    the controller node do it), it keeps them as ``self.rig`` (a
    :class:`~drill_sim_ros.control.rig.RigPhysics`), ``self.schedule`` (the operator's
    setpoints: ``rpm_at(t_s)``, ``wob_at(t_s)``), ``self.mode`` ("speed" or "torque"),
    ``self.period_s`` (the control period, s), ``self.enable_at_s`` (the switch-on, s) and
    ``self.params`` (:meth:`defaults` updated with the given parameters, each checked to be
    a known name and a number in (0, 1e9]).

    Subclasses set ``name`` and ``PARAMS`` ({name: description with unit}) and override the
    hooks of ``HOOKS``. Every control period the caller calls :meth:`update` with the newest
    measurement (None before the first one); it calls :meth:`reference_rad_s` and, in
    torque mode, closes a PI speed loop with :meth:`loop_gains` on the reference.
    """

    name = "base"
    PARAMS: ClassVar[dict[str, str]] = {
        "loop_bandwidth_rad_s": "bandwidth of the controller's own PI speed loop in torque "
                                "mode, rad/s (default 3 omega_1)",
    }
    # what a subclass overrides or calls, in the order docs/closed-loop.md's reference has them
    HOOKS: ClassVar[tuple[str, ...]] = ("defaults", "reset", "reference_rad_s", "loop_gains",
                                        "delivered_loop_gains", "active", "update")

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
        """The parameters' defaults, derived from ``self.rig`` (called once, in the
        constructor, before ``self.params`` exists); extend ``super().defaults()`` to keep
        the base class's, or return only your own."""
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
        """Forget all state (filters, loop integral, counters); called by the constructor
        (and by whoever restarts the controller). Build your filters here and call
        ``super().reset()``. In torque
        mode it loads the compiled loop now, so that the first control period is not
        charged with it."""
        self._integral_nm: float | None = None
        self.clamped_commands = 0
        if self.mode == "torque":
            speed_loop(0.0, 0.0, 0.0, 1.0, 1.0, 1.0, self.period_s)

    def reference_rad_s(self, m: SurfaceMeasurement, nominal_rad_s: float) -> float:
        """The speed reference omega_ref (rad/s) from the measurement ``m`` and the
        operator's setpoint ``nominal_rad_s`` at its time; called every period from the
        first measurement on, also before the switch-on (where it is not used), so filters
        stay warm. Default: the setpoint."""
        return nominal_rad_s

    def loop_gains(self) -> tuple[float, float]:
        """(kp N m s/rad, ki N m/rad) of the controller's own PI speed loop in torque mode
        once switched on: motor torque = kp e + ki int e dt, e = omega_ref - the measured
        drive speed (the integral held while the torque is at the drive's limit). Called
        every period from the switch-on; before it the loop runs with
        :meth:`delivered_loop_gains` (the drive as delivered), and its integral carries
        over. Default: those same gains; override it to set kp and ki independently."""
        return self.delivered_loop_gains()

    def delivered_loop_gains(self) -> tuple[float, float]:
        """(kp N m s/rad, ki N m/rad) critically damped on J: kp = 2 J w_c, ki = J w_c^2
        with w_c = ``params["loop_bandwidth_rad_s"]``."""
        w_c, j = self.params["loop_bandwidth_rad_s"], self.rig.drive_inertia_kg_m2
        return 2.0 * j * w_c, j * w_c**2

    def active(self, time_s: float) -> bool:
        """Whether the controller is switched on at ``time_s`` (s): from ``enable_at_s``."""
        return time_s >= self.enable_at_s

    def update(self, m: SurfaceMeasurement | None) -> Command:
        """The command of this control period, for the newest measurement ``m`` (None
        before the first): before the switch-on the operator's setpoint, then
        :meth:`reference_rad_s` within [0, the rpm limit], sent as the speed setpoint
        (speed mode) or through the PI loop of :meth:`loop_gains` as the motor torque
        (torque mode); the WOB setpoint from the schedule. Override only to replace the
        whole frame."""
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
        kp, ki = self.loop_gains() if self.active(m.time_s) else self.delivered_loop_gains()
        if self._integral_nm is None:
            self._integral_nm = m.motor_torque_nm
        limit = self.rig.max_torque_nm
        torque, self._integral_nm = speed_loop(reference_rad_s, m.drive_speed_rad_s,
                                               self._integral_nm, kp, ki, limit, self.period_s)
        if abs(torque) >= limit:
            self.clamped_commands += 1
        return float(torque)


class Stiff(TopDriveController):
    """A stiff PI speed loop on the operator's setpoint (the baseline)."""

    name = "stiff"


class SoftDrive(TopDriveController):
    """A softer drive emulated through the setpoint (the shared law of ``soft_torque`` and
    ``z_torque``; module doc). The string torque of the torque sub drives a virtual rotor of
    inertia J_v under a virtual PI loop (kp_d, ki_d) on the operator's setpoint:
    J_v dw_v/dt = kp_d (w_0 - w_v) + I_d - T, dI_d/dt = ki_d (w_0 - w_v), the loop's torque
    within the drive's limit and I_d held while the limit holds it (the drive's own
    ``speed_loop``: a bit held at the limit does not wind it up). The setpoint sent
    is w_v plus the torque the real drive needs to move so, u = T + J dw_v/dt, through the
    inverse of the drive's own PI loop K (kp e + ki int e = u, a first-order filter whose
    steady state is 0), so the real drive under K moves as the virtual one: its admittance
    to the string torque is 1 / (J_v s + kp_d + ki_d / s). With J_v = J the emulated drive
    keeps the real inertia at high frequency and is passive at every frequency; a lighter
    J_v widens the band it absorbs, and the loop's zero-order hold (half a control period)
    then makes it return slightly more than it receives above a few Hz, which a damper in
    series with the emulated impedance takes back (:meth:`droop_per_nm_s`); the motor
    must also supply (J / J_v - 1) times the virtual rotor's net torque, so a light J_v
    drives the motor to its limit on the collars' ring that reaches the top. The virtual
    state starts at the switch-on from the measured drive speed and torque (no bump)."""

    PARAMS: ClassVar[dict[str, str]] = {**TopDriveController.PARAMS,
              "inertia_fraction": "J_v / J, the emulated drive's inertia over the real one's",
              "tuned_rad_s": "where the emulated drive's reactance vanishes, rad/s (default "
                             "omega_1)",
              "hold_margin": "the series damper's admittance over the hold's deficit "
                             "(P / 2 + motor lag)(1 / J_v - 1 / J) (default "
                             "1 / cos(pi / 3 (1 + lag / P)), 2 without a motor lag: passive "
                             "up to a sixth of the control rate, past the collars' ring)"}

    def defaults(self) -> dict[str, float]:
        return {**super().defaults(), "inertia_fraction": 1.0,
                "tuned_rad_s": self.rig.first_mode_rad_s,
                "hold_margin": 1.0 / math.cos(min(HOLD_PHASE_RAD * (
                    1.0 + self.rig.motor_lag_s / self.period_s), MAX_HOLD_PHASE_RAD))}

    def reset(self) -> None:
        super().reset()
        self._virtual: list[float] | None = None    # w_v, I_d, e, u, droop, last T
        self._droop = self.droop_per_nm_s()         # fixed by the parameters

    def droop_per_nm_s(self) -> tuple[float, float]:
        """(admittance 1/b rad/(N m s), high-pass factor) of the series damper that keeps
        the emulated drive passive under the zero-order hold.

        The torque sub is sampled at the start of each period and held over it (a delay of
        P / 2), while the real drive meets the string's torque at once. Compensating its
        inertia J down to J_v with that late torque adds the admittance
        -(sin wP/2 / w)(1 / J_v - 1 / J) to the drive's, negative real, so above a few Hz,
        where the virtual inertia hides the damper kp_d, the drive returns
        1 + 2 Z (P / 2)(1 / J_v - 1 / J) of a wave (1.0041 for soft_torque and 1.0058 for
        z_torque on the field drive: what was measured). A damper b in series with the
        emulated impedance adds the real admittance 1 / b, but it acts through the same
        hold and the period's speed ramp, a delay P: cos(wP) / b. With 1 / b = m times that
        deficit (m = hold_margin) the drive is passive while m cos(wP) > 1, up to
        arccos(1 / m) / (2 pi P): 16.7 Hz for m = 2 at 100 Hz, past the collars' ring
        (c / L = 15.9 Hz on the field string). A motor that follows its command with a lag
        tau adds tau to both delays: the deficit grows to (P / 2 + tau)(...) and the
        damper acts as cos(w (P + tau)), so the default margin
        1 / cos(pi / 3 (1 + tau / P)) keeps the band to a sixth of the control rate (2.35
        for the field drive's 0.8 ms at 100 Hz; the phase is capped at 1.2 rad, where a
        lag near half a period leaves no band to keep). Above that no sampled correction helps:
        anything computed from the samples lags by more than 90 degrees near the Nyquist
        rate, and the drive's own instant damper kp adds only kp / (w J)^2 there
        (docs/closed-loop.md). It is high-passed well below the first mode (corner
        omega_1 / 10), so it yields to a torque change but not to the mean torque: no
        steady speed droop."""
        j_v, _, _ = self.virtual_gains()
        deficit = (0.5 * self.period_s + self.rig.motor_lag_s) \
            * max(1.0 / j_v - 1.0 / self.rig.drive_inertia_kg_m2, 0.0)
        corner = 0.1 * self.params["tuned_rad_s"]
        return self.params["hold_margin"] * deficit, 1.0 / (1.0 + corner * self.period_s)

    def virtual_gains(self) -> tuple[float, float, float]:
        """(J_v kg m^2, kp_d N m s, ki_d N m) of the emulated drive."""
        raise NotImplementedError

    def inner_gains(self) -> tuple[float, float]:
        """(kp, ki) of the loop that follows the setpoint: the drive's own in speed mode,
        the controller's own in torque mode."""
        if self.mode == "speed":
            return self.rig.drive_kp_nm_s, self.rig.drive_ki_nm
        return self.loop_gains()

    def reference_rad_s(self, m: SurfaceMeasurement, nominal_rad_s: float) -> float:
        if not self.active(m.time_s):
            return nominal_rad_s
        j_v, kp_d, ki_d = self.virtual_gains()
        kp, ki = self.inner_gains()
        p, t_nm = self.period_s, m.string_torque_nm
        if self._virtual is None:                  # start where the drive is, at rest
            w0 = m.drive_speed_rad_s
            self._virtual = [w0, t_nm - kp_d * (nominal_rad_s - w0), 0.0, t_nm, 0.0, t_nm]
        w_v, i_d, e, u_old, droop_old, t_old = self._virtual
        # the virtual PI loop within the drive's torque limit, its integral held while the
        # limit holds it (the drive's own loop, model.top_drive.speed_loop)
        tau_v, i_d = speed_loop(nominal_rad_s, w_v, i_d, kp_d, ki_d, self.rig.max_torque_nm, p)
        accel = (tau_v - t_nm) / j_v
        w_v += accel * p
        admittance, keep = self._droop
        droop = keep * (droop_old + admittance * (t_nm - t_old))  # high-passed T / b
        # what the real drive must apply to move as w_v - droop
        u = t_nm + self.rig.drive_inertia_kg_m2 * (accel - (droop - droop_old) / p)
        e = (e + (u - u_old) / kp) / (1.0 + ki * p / kp)  # through the inverse of its loop
        self._virtual = [w_v, i_d, e, u, droop, t_nm]
        return w_v - droop + e


class SoftTorque(SoftDrive):
    """SoftSpeed-class: the emulated drive is a damper of ``impedance_factor`` x Z at the
    first mode, where its integral gain cancels the reactance of its inertia
    (ki_d = J_v omega_1^2; Kyllingstad & Nessjoen 2009, SPE/IADC 119660), with a fifth of the
    drive's inertia."""

    name = "soft_torque"
    PARAMS: ClassVar[dict[str, str]] = {**SoftDrive.PARAMS,
              "impedance_factor": "the emulated drive's damping kp_d / Z (default 2: "
                                  "|r| = 1/3 at the first mode)"}

    def defaults(self) -> dict[str, float]:
        return {**super().defaults(), "impedance_factor": 2.0, "inertia_fraction": 0.2}

    def virtual_gains(self) -> tuple[float, float, float]:
        j_v = self.params["inertia_fraction"] * self.rig.drive_inertia_kg_m2
        return (j_v, self.params["impedance_factor"] * self.rig.impedance_nm_s,
                j_v * self.params["tuned_rad_s"] ** 2)


class ZTorque(SoftDrive):
    """ZTorque-class impedance matching (Dwars 2015, SPE/IADC-173037-MS): the emulated drive
    is the pipe's characteristic impedance Z at the first mode (an arriving wave is absorbed,
    nothing comes back), with 0.15 of the drive's inertia."""

    name = "z_torque"
    PARAMS: ClassVar[dict[str, str]] = {**SoftDrive.PARAMS,
              "impedance_nm_s": "Z, N m s/rad (default J_p sqrt(G rho) of the drill pipe)"}

    def defaults(self) -> dict[str, float]:
        return {**super().defaults(), "impedance_nm_s": self.rig.impedance_nm_s,
                "inertia_fraction": 0.15}

    def virtual_gains(self) -> tuple[float, float, float]:
        j_v = self.params["inertia_fraction"] * self.rig.drive_inertia_kg_m2
        return j_v, self.params["impedance_nm_s"], j_v * self.params["tuned_rad_s"] ** 2
