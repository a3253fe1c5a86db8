"""What a top-drive controller reads and what it commands (SI, ROS-free).

A controller sees only what a rig measures at the surface (:class:`SurfaceMeasurement`: the
drive's encoder, its motor torque and the torque sub at the quill, ``model.measurement``) and
answers with a :class:`Command`, the content of one ``drill/cmd/top_drive`` message.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from drill_sim_ros.model.telemetry import TELEMETRY_INDEX

F = TELEMETRY_INDEX


@dataclass(frozen=True)
class Command:
    """What one drill/cmd/top_drive message commands; None commands nothing."""

    speed_rad_s: float | None = None       # speed setpoint (kinematic and speed modes)
    motor_torque_nm: float | None = None   # motor torque (torque mode)
    wob_n: float | None = None             # applied WOB


@dataclass(frozen=True)
class SurfaceMeasurement:
    """One sample of the rig's surface sensors, stamped with its simulated time."""

    time_s: float
    drive_speed_rad_s: float     # encoder
    motor_torque_nm: float       # the drive's own torque estimate
    string_torque_nm: float      # torque sub at the quill


def measurement_of_row(row: np.ndarray, time_ns: int) -> SurfaceMeasurement:
    """The surface measurement in a telemetry row (``TELEMETRY_FIELDS`` order) stamped
    ``time_ns``; the time is ``time_ns / 1e9`` as a subscriber computes it from the stamp."""
    return SurfaceMeasurement(time_s=time_ns / 1e9,
                              drive_speed_rad_s=float(row[F["drive_speed_measured_rad_s"]]),
                              motor_torque_nm=float(row[F["motor_torque_measured_nm"]]),
                              string_torque_nm=float(row[F["string_torque_measured_nm"]]))
