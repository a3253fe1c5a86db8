"""What a top-drive controller reads and what it commands (SI, ROS-free).

A controller sees only what a rig measures at the surface (:class:`SurfaceMeasurement`: the
drive's encoder, its motor torque, the torque sub at the quill and the hook load with the
applied-WOB estimate from it, ``model.measurement``) and
answers with a :class:`Command`, the content of one ``drill/cmd/top_drive`` message.
"""

from __future__ import annotations

import math
import sys
from dataclasses import MISSING, dataclass, field
from typing import Any

import numpy as np

from drill_sim_ros.model.params import RPM_PER_RAD_S
from drill_sim_ros.model.session import SimSession
from drill_sim_ros.model.telemetry import TELEMETRY_INDEX

F = TELEMETRY_INDEX


def quantity(unit: str, meaning: str, default: Any = MISSING) -> Any:
    """A dataclass field that says its unit and meaning (``field.metadata["unit"]`` and
    ``["meaning"]``): the source of the controller API's reference in docs/closed-loop.md
    (docs/generate.py)."""
    return field(default=default, metadata={"unit": unit, "meaning": meaning})


@dataclass(frozen=True)
class Command:
    """What one drill/cmd/top_drive message commands; None commands nothing (the drive
    keeps the last value it was given)."""

    speed_rad_s: float | None = quantity(
        "rad/s", "speed setpoint of the drive's own PI speed loop (speed mode); clamped to "
        "[0, the rpm limit]", None)
    motor_torque_nm: float | None = quantity(
        "N m", "motor torque (torque mode); the drive applies it within +- its "
        "max_torque_nm", None)
    wob_n: float | None = quantity(
        "N", "applied weight on bit setpoint; clamped to [0, limits.max_wob_n]", None)


@dataclass(frozen=True)
class SurfaceMeasurement:
    """One sample of the rig's surface sensors, stamped with its simulated time (with the
    scenario's noise, quantisation and delay, ``model.measurement``)."""

    time_s: float = quantity("s", "simulated time of the sample (its stamp)")
    drive_speed_rad_s: float = quantity("rad/s", "the drive's speed, from its encoder")
    motor_torque_nm: float = quantity("N m", "the drive's own estimate of its motor torque")
    string_torque_nm: float = quantity("N m", "the string's torque at the quill, from the "
                                              "torque sub")
    hook_load_n: float = quantity("N", "hook load, from the deadline load cell "
                                       "(NaN when a caller gives none)", math.nan)
    applied_wob_estimate_n: float = quantity(
        "N", "applied WOB estimated from it: submerged string weight - hook load "
        "(NaN when a caller gives none)", math.nan)


# the telemetry fields of a SurfaceMeasurement's values, in its order after time_s
SURFACE_FIELDS = np.array([F["drive_speed_measured_rad_s"], F["motor_torque_measured_nm"],
                           F["string_torque_measured_nm"], F["hook_load_measured_n"],
                           F["applied_wob_estimate_n"]])


def measurement_of_row(row: np.ndarray, time_ns: int) -> SurfaceMeasurement:
    """The surface measurement in a telemetry row (``TELEMETRY_FIELDS`` order) stamped
    ``time_ns``; the time is ``time_ns / 1e9`` as a subscriber computes it from the stamp."""
    return SurfaceMeasurement(time_ns / 1e9, *row[SURFACE_FIELDS].tolist())


@dataclass(frozen=True)
class CommandLimits:
    """The bounds a setpoint command is clamped to (sim_node's ``limits.*``). A motor
    torque has the drive's own limit, applied by the drive (``top_drive.within_limit``)."""

    max_surface_rpm: float
    max_wob_n: float


def clamp_command(value: float, limit: float, unit: str, low: float = 0.0
                  ) -> tuple[float | None, str | None]:
    """A setpoint command within [``low``, ``limit``]: (the value to apply, None) when it is
    inside, (the bound it saturates at, why) when it is finite and beyond, (None, why) when
    it is not finite (rejected)."""
    if not math.isfinite(value):
        return None, f"{value!r} is not finite"
    if value < low:
        return low, f"{value!r} {unit} is below {low!r} {unit}"
    if value > limit:
        return limit, f"{value!r} {unit} exceeds the limit {limit!r} {unit}"
    return value, None


def rpm_of_rad_s(speed_rad_s: float) -> float:
    """rev/min of a speed; a finite speed stays finite (1e308 rad/s saturates at the largest
    float instead of overflowing to inf, so it is clamped, not rejected)."""
    if not math.isfinite(speed_rad_s):
        return speed_rad_s
    return max(-sys.float_info.max, min(sys.float_info.max, speed_rad_s * RPM_PER_RAD_S))


def apply_command(session: SimSession, command: Command, limits: CommandLimits
                  ) -> list[tuple[bool, str]]:
    """Set what ``command`` commands on ``session`` (from its next period): the speed and
    WOB setpoints clamped to ``limits``, the motor torque as it is (the drive applies it
    within its limit, ``session.drive.max_torque_nm``); a non-finite value is not applied
    (the last setpoint stays). Returns ``(applied, why)`` for each value that was clamped or
    lies beyond the drive's limit (applied) or was rejected. The one implementation behind
    sim_node's commands and the in-process bench."""
    problems: list[tuple[bool, str]] = []

    def bounded(value: float, high: float, unit: str, low: float = 0.0) -> float | None:
        applied, why = clamp_command(value, high, unit, low)
        if why is not None:
            problems.append((applied is not None, why))
        return applied

    if command.speed_rad_s is not None:
        rpm = bounded(rpm_of_rad_s(command.speed_rad_s), limits.max_surface_rpm, "rev/min")
        if rpm is not None:
            session.set_surface_rpm(rpm)
    if command.motor_torque_nm is not None:
        limit_nm = session.drive.max_torque_nm
        if bounded(command.motor_torque_nm, limit_nm, "N m", -limit_nm) is not None:
            session.set_motor_torque_nm(command.motor_torque_nm)
    if command.wob_n is not None:
        wob = bounded(command.wob_n, limits.max_wob_n, "N")
        if wob is not None:
            session.set_wob_n(wob)
    return problems
