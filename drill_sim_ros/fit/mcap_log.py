"""The surface log of a sim_node recording: ``drill/surface/measured`` (sensor_msgs/JointState,
``topics.MEASURED_JOINTS``) as named columns (fit.log's names): the top drive's measured
speed and motor torque, the quill's string torque (the torque sub) and the hook load, at the
messages' header stamps (simulated time); and the drive's speed setpoint in force (a command,
read from the telemetry recorded beside, ``speed_setpoint_rpm``) where the recording has it
at those stamps (``drill_sim fit --follow setpoint``)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from drill_sim_ros import topics
from drill_sim_ros.archive.reader import ArchiveReader
from drill_sim_ros.fit.errors import LogError
from drill_sim_ros.model.telemetry import TELEMETRY_INDEX
from drill_sim_ros.viz.mcap_telemetry import NoTelemetryError, channel_decoder, read_telemetry

STAMP_TOLERANCE_S = 1e-6     # a telemetry sample and a measured one at the same instant


def read_mcap_columns(path: Path) -> dict[str, np.ndarray]:
    """time_s, drive_speed_rad_s, motor_torque_nm, string_torque_nm and hook_load_n of the
    recording's measured surface signals, and setpoint_rpm where :func:`read_setpoint_rpm`
    finds it (fit.log converts it, as a CSV's); LogError when it has none."""
    rows: list[tuple[float, ...]] = []
    decode = None
    try:
        for message in ArchiveReader(path).messages(
                lambda topic: topic == topics.SURFACE_MEASURED):
            decode = decode or channel_decoder(message.channel)
            msg = decode(message.data)
            joint = {name: i for i, name in enumerate(msg.name)}
            if not {"top_drive", "quill", "hook_load"} <= set(joint):
                continue
            top, quill, hook = joint["top_drive"], joint["quill"], joint["hook_load"]
            rows.append((msg.header.stamp.sec + 1e-9 * msg.header.stamp.nanosec,
                         msg.velocity[top], msg.effort[top], msg.effort[quill],
                         msg.effort[hook]))
    except (OSError, ValueError) as exc:
        raise LogError(f"--log {path}: not a readable recording ({exc})") from None
    if not rows:
        raise LogError(f"--log {path}: no {topics.SURFACE_MEASURED} messages with the joints "
                       "top_drive, quill and hook_load")
    table = np.asarray(rows, dtype=float)
    names = ("time_s", "drive_speed_rad_s", "motor_torque_nm", "string_torque_nm",
             "hook_load_n")
    columns = {name: table[:, i] for i, name in enumerate(names)}
    setpoint = read_setpoint_rpm(path, columns["time_s"])
    if setpoint is not None:
        columns["setpoint_rpm"] = setpoint
    return columns


def read_setpoint_rpm(path: Path, t_s: np.ndarray) -> np.ndarray | None:
    """The telemetry's speed setpoint (rpm) at the times ``t_s``; None when the recording
    has no telemetry or no telemetry sample at one of those times."""
    try:
        rows = np.concatenate([batch.rows for batch in read_telemetry(path)])
    except NoTelemetryError:
        return None
    stamps = rows[:, TELEMETRY_INDEX["sim_time_s"]]
    at = np.clip(np.searchsorted(stamps, t_s - STAMP_TOLERANCE_S), 0, stamps.size - 1)
    if np.any(np.abs(stamps[at] - t_s) > STAMP_TOLERANCE_S):
        return None
    return rows[at, TELEMETRY_INDEX["speed_setpoint_rpm"]]
