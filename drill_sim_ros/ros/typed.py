"""The typed topics of the ``drill_sim_msgs`` interface package, beside the standard ones.

``drill/typed/telemetry`` (drill_sim_msgs/Telemetry: a header stamped with the sample's sim
time, framed by the rig, and one named field per telemetry value), ``drill/typed/run_info``
(RunInfo, latched) and ``drill/typed/cmd/top_drive`` (TopDriveCommand, what
``drill/cmd/top_drive`` carries as a JointState) and, with ``string.message`` typed,
``drill/typed/string/torsion`` (StringProfile, packed by
:mod:`drill_sim_ros.ros.string_sink`). The standard-message topics stay: plotting
tools read them without the package. Without ``drill_sim_msgs`` installed (a ROS install
that has not built msgs/ yet) :data:`AVAILABLE` is False and sim_node publishes only those.

Samples are packed into Telemetry CDR by one ``struct`` format laid out like the message
(:mod:`drill_sim_ros.ros.cdr`), so the typed topic costs a pack per sample, not a message
object and its serialization.
"""

from __future__ import annotations

import json
import math
import struct
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

try:
    from drill_sim_msgs.msg import StringProfile
except ImportError:       # not built, or built before StringProfile: profiles as JointState
    StringProfile = None

AVAILABLE = Telemetry is not None
PROFILE_AVAILABLE = StringProfile is not None
__all__ = ["AVAILABLE", "PROFILE_AVAILABLE", "BitMode", "RunInfo", "StringProfile",
           "Telemetry", "TelemetryPacker", "TopDriveCommand", "command_of",
           "run_info_message"]


def telemetry_fields() -> list[str]:
    """The value fields of drill_sim_msgs/Telemetry, in message order (without the header)."""
    return [name for name in Telemetry.get_fields_and_field_types() if name != "header"]


class TelemetryPacker:
    """Packs SI telemetry rows (``TELEMETRY_FIELDS`` order) into Telemetry payloads.

    One ``struct`` format covers the whole message: the fixed bytes before and after the
    stamp (encapsulation, frame_id), then each value at its CDR offset, padding zeroed.
    """

    def __init__(self, frame_id: str) -> None:
        cdr = CdrBuffer()
        stamp_at = cdr.stamp()
        cdr.string(frame_id)
        kinds = Telemetry.get_fields_and_field_types()
        fields = telemetry_fields()
        places = [(cdr.uint8(), "B") if kinds[name] == "uint8" else
                  (cdr.doubles(1, sequence=False)[0], "d") for name in fields]
        template = cdr.layout().template
        self.size = len(template)
        first = places[0][0]
        fmt = f"<{stamp_at}siI{first - stamp_at - 8}s"
        position = first
        for at, code in places:
            fmt += f"{at - position}x{code}" if at > position else code
            position = at + struct.calcsize(code)
        fmt += f"{self.size - position}x"
        self._struct = struct.Struct(fmt)
        self._fixed = (template[:stamp_at], template[stamp_at + 8:first])
        self._columns = [TELEMETRY_INDEX[name] for name in fields]
        self._byte_slots = [i for i, name in enumerate(fields) if kinds[name] == "uint8"]

    def pack(self, rows: np.ndarray, stamps_ns: np.ndarray) -> list[bytes]:
        """One payload per row (shape (N, F)), stamped ``stamps_ns`` (shape (N,))."""
        head, middle = self._fixed
        out = []
        for row, time_ns in zip(rows.tolist(), stamps_ns.tolist(), strict=True):
            values = [row[c] for c in self._columns]
            for slot in self._byte_slots:
                values[slot] = int(values[slot])
            sec, nanosec = divmod(time_ns, NS_PER_S)
            out.append(self._struct.pack(head, sec, nanosec, middle, *values))
        return out


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
