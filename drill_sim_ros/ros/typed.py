"""The typed topics of the ``drill_sim_msgs`` interface package, beside the standard ones.

``drill/typed/telemetry`` (drill_sim_msgs/Telemetry: a header stamped with the sample's sim
time, framed by the rig, and one named field per telemetry value), ``drill/typed/run_info``
(RunInfo, latched) and ``drill/typed/cmd/top_drive`` (TopDriveCommand, what
``drill/cmd/top_drive`` carries as a JointState). The standard-message topics stay: plotting
tools read them without the package. Without ``drill_sim_msgs`` installed (a ROS install
that has not built msgs/ yet) :data:`AVAILABLE` is False and sim_node publishes only those.

A block of samples is packed into Telemetry CDR in one vectorised numpy pass over a record
type whose offsets are those of the message's CDR layout (:mod:`drill_sim_ros.ros.cdr`), so
the typed topic costs a copy per sample, not a message object.
"""

from __future__ import annotations

import json
import math
from typing import Any

import numpy as np

from drill_sim_ros import topics
from drill_sim_ros.control.command import Command
from drill_sim_ros.model.telemetry import NS_PER_S, TELEMETRY_INDEX
from drill_sim_ros.ros.cdr import CdrBuffer

try:
    from drill_sim_msgs.msg import BitMode, RunInfo, Telemetry, TopDriveCommand
except ImportError:       # msgs/ not built here: the standard topics only
    BitMode = RunInfo = Telemetry = TopDriveCommand = None

AVAILABLE = Telemetry is not None
__all__ = ["AVAILABLE", "BitMode", "RunInfo", "Telemetry", "TelemetryPacker",
           "TopDriveCommand", "command_of", "run_info_message"]


def telemetry_fields() -> list[str]:
    """The value fields of drill_sim_msgs/Telemetry, in message order (without the header)."""
    return [name for name in Telemetry.get_fields_and_field_types() if name != "header"]


class TelemetryPacker:
    """Packs SI telemetry rows (``TELEMETRY_FIELDS`` order) into Telemetry payloads."""

    def __init__(self, frame_id: str) -> None:
        cdr = CdrBuffer()
        names, formats, offsets = ["sec", "nanosec"], ["<i4", "<u4"], [cdr.stamp()]
        offsets.append(offsets[0] + 4)
        cdr.string(frame_id)
        self._fields = telemetry_fields()
        for name in self._fields:
            kind = Telemetry.get_fields_and_field_types()[name]
            at = cdr.uint8() if kind == "uint8" else cdr.doubles(1, sequence=False)[0]
            names.append(name)
            formats.append("u1" if kind == "uint8" else "<f8")
            offsets.append(at)
        template = cdr.layout().template
        self.size = len(template)
        self._dtype = np.dtype({"names": names, "formats": formats, "offsets": offsets,
                                "itemsize": self.size})
        self._template = np.frombuffer(template, dtype=np.uint8)  # with the frame_id bytes
        self._columns = [TELEMETRY_INDEX[name] for name in self._fields]

    def pack(self, rows: np.ndarray, stamps_ns: np.ndarray) -> list[bytes]:
        """One payload per row (shape (N, F)), stamped ``stamps_ns`` (shape (N,))."""
        raw = np.tile(self._template, rows.shape[0])     # a record copy would drop the gaps
        records = raw.view(self._dtype)
        records["sec"] = stamps_ns // NS_PER_S
        records["nanosec"] = stamps_ns % NS_PER_S
        for name, column in zip(self._fields, self._columns, strict=True):
            records[name] = rows[:, column]
        data = raw.tobytes()
        return [data[i:i + self.size] for i in range(0, len(data), self.size)]


def run_info_message(info: dict[str, Any], values: dict[str, Any], time_ns: int,
                     frame_id: str) -> Any:
    """drill_sim_msgs/RunInfo of the session's run info and the node's parameter values."""
    msg = RunInfo(preset=str(info["preset"]), publish_rate_hz=float(values["publish_rate_hz"]),
                  clock_rate_hz=float(values["clock_rate_hz"]),
                  real_time_factor=float(values["real_time_factor"]),
                  lockstep=bool(values["lockstep"]), json=json.dumps(info))
    msg.header.stamp.sec, msg.header.stamp.nanosec = divmod(int(time_ns), NS_PER_S)
    msg.header.frame_id = frame_id
    return msg


def command_of(msg: Any) -> Command:
    """The :class:`Command` of a TopDriveCommand (NaN: no command for that field)."""
    def value(x: float) -> float | None:
        return None if math.isnan(x) else float(x)
    return Command(speed_rad_s=value(msg.speed_rad_s),
                   motor_torque_nm=value(msg.motor_torque_nm), wob_n=value(msg.wob_n))


TYPED_TOPICS = (topics.TYPED_TELEMETRY, topics.TYPED_RUN_INFO, topics.TYPED_CMD_TOP_DRIVE)
