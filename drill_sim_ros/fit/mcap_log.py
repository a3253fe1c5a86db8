"""The surface log of a sim_node recording: ``drill/surface/measured`` (sensor_msgs/JointState,
``topics.MEASURED_JOINTS``) as named columns (fit.log's names): the top drive's measured
speed and motor torque, the quill's string torque (the torque sub) and the hook load, at the
messages' header stamps (simulated time)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from drill_sim_ros import topics
from drill_sim_ros.archive.reader import ArchiveReader
from drill_sim_ros.fit.errors import LogError
from drill_sim_ros.viz.mcap_telemetry import channel_decoder


def read_mcap_columns(path: Path) -> dict[str, np.ndarray]:
    """time_s, drive_speed_rad_s, motor_torque_nm, string_torque_nm and hook_load_n of the
    recording's measured surface signals; LogError when it has none."""
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
    return {name: table[:, i] for i, name in enumerate(names)}
