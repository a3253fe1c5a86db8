"""The OPC UA address space of a rig object (issue 33): its variables, units and sources.

ROS-free and asyncua-free: one table, :data:`VARIABLES`, that the gateway builds its nodes
from (:mod:`drill_sim_ros.hil.rig_server`), that maps a ``drill/surface/measured`` sample onto
the read-only values, and that ``docs/hil.md`` shows (:func:`markdown_table`). PLC programs
bind to these BrowseNames: keep them.

Units are the UNECE Recommendation 20 common codes that OPC UA's EUInformation carries
(namespace :data:`UNECE_URI`, UnitId from the code by :func:`unece_unit_id`, OPC UA Part 8
5.6.3).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from enum import IntEnum

NAMESPACE_URI = "urn:drill_sim_ros"
DEFAULT_ENDPOINT = "opc.tcp://127.0.0.1:4840/drill_sim/"
DEFAULT_RIG = "Rig"
UNECE_URI = "http://www.opcfoundation.org/UA/units/un/cefact"
# The source timestamp of a value is its simulated time, counted from this instant (UTC).
SIM_EPOCH_TEXT = "1970-01-01T00:00:00Z"


class RigStatus(IntEnum):
    """The rig object's ``Status`` (an enumeration, its text in ``StatusText``)."""

    WaitingForSim = 0       # no sample yet: at start, or sim_node started again
    Running = 1             # samples come, a session owns the setpoints
    WaitingForClient = 2    # samples come, no session owns the setpoints
    HeartbeatLost = 3       # the owner went silent in free run: safe stop; Reset to go on
    SimLost = 4             # sim_node does not answer a command, or sends no samples
    Faulted = 5             # the safe stop could not be made; Reset to go on


class DriveModeEnum(IntEnum):
    """The rig object's ``DriveMode`` (an enumeration): what a command carries. The names are
    sim_node's ``top_drive.mode`` values (its kinematic mode shows as speed)."""

    speed = 0               # SpeedSetpoint
    torque = 1              # TorqueCommand


DRIVE_MODE_MEANINGS = {
    DriveModeEnum.speed: "a command carries SpeedSetpoint (the drive's speed loop)",
    DriveModeEnum.torque: "a command carries TorqueCommand (the motor torque, no speed loop)",
}
STATUS_MEANINGS = {
    RigStatus.WaitingForSim: "no sample from sim_node yet (at start, or after it started "
    "again)",
    RigStatus.Running: "samples come and a session owns the setpoints",
    RigStatus.WaitingForClient: "samples come; no session owns the setpoints (none wrote yet, "
    "or the owner closed or went silent in lockstep)",
    RigStatus.HeartbeatLost: "in free run, the owner closed or wrote nothing for "
    "heartbeat_timeout_s: the speed setpoint ramps to 0; writes are refused until Reset",
    RigStatus.SimLost: "a command unanswered, or no sample in free run, for sim_timeout_s",
    RigStatus.Faulted: "the safe stop could not be made (sim_node refused or did not answer "
    "the switch to speed mode); writes are refused until Reset",
}

# The enumeration DataTypes of the address space: each one's Description and its values'.
ENUMERATIONS: dict[type[IntEnum], tuple[str, dict[IntEnum, str]]] = {
    RigStatus: ("what the rig does or waits for (the variable Status)", STATUS_MEANINGS),
    DriveModeEnum: ("what a command carries, and sim_node's top_drive.mode (the variable "
                    "DriveMode)", DRIVE_MODE_MEANINGS),
}


@dataclass(frozen=True)
class Unit:
    """An engineering unit: its symbol, UNECE common code and description."""

    symbol: str
    code: str
    description: str


RAD_S = Unit("rad/s", "2A", "radian per second")
NEWTON_METRE = Unit("N·m", "NU", "newton metre")
NEWTON = Unit("N", "NEW", "newton")
METRE = Unit("m", "MTR", "metre")
METRE_S = Unit("m/s", "MTS", "metre per second")
SECOND = Unit("s", "SEC", "second")


@dataclass(frozen=True)
class Variable:
    """One variable of a rig object. ``source``: for a sample value, the JointState array
    (position, velocity, effort) and joint index of ``drill/surface/measured``
    (``topics.MEASURED_JOINTS``: top_drive, quill, hook_load, wob_estimate), or ``stamp``;
    ``limit``: for a setpoint, the sim_node parameter its EURange comes from (and follows)."""

    name: str
    type_name: str                  # OPC UA built-in type: Double, UInt32, Boolean, String
    writable: bool
    meaning: str
    unit: Unit | None = None
    source: tuple[str, int] | None = None
    limit: str = ""
    enumeration: type[IntEnum] | None = None     # its DataType (Int32 values, EnumStrings)


VARIABLES = (
    Variable("DriveSpeed", "Double", False, "drive speed, encoder", RAD_S, ("velocity", 0)),
    Variable("MotorTorque", "Double", False, "motor torque, the drive's estimate",
             NEWTON_METRE, ("effort", 0)),
    Variable("QuillTorque", "Double", False, "string torque at the quill (torque sub)",
             NEWTON_METRE, ("effort", 1)),
    Variable("HookLoad", "Double", False, "hook load (load cell)", NEWTON, ("effort", 2)),
    Variable("WobEstimate", "Double", False, "applied WOB estimate (string weight - hook "
             "load)", NEWTON, ("effort", 3)),
    Variable("BitDepth", "Double", False, "bit depth below the start", METRE,
             ("position", 2)),
    Variable("Rop", "Double", False, "rate of penetration", METRE_S, ("velocity", 2)),
    Variable("SimTime", "Double", False, "simulated time of the sample", SECOND, ("stamp", 0)),
    Variable("SpeedSetpoint", "Double", True, "drive speed setpoint (DriveMode speed)", RAD_S,
             limit="limits.max_surface_rpm"),
    Variable("TorqueCommand", "Double", True, "motor torque command (DriveMode torque)",
             NEWTON_METRE, limit="top_drive.max_torque_nm"),
    Variable("WobSetpoint", "Double", True, "applied WOB setpoint", NEWTON,
             limit="limits.max_wob_n"),
    Variable("DriveMode", "Int32", True, "DriveModeEnum: what a command carries, speed (0, "
             "SpeedSetpoint) or torque (1, TorqueCommand); a new value switches sim_node's "
             "top_drive.mode first, and shows sim_node's own switches (its kinematic mode "
             "shows as speed)", enumeration=DriveModeEnum),
    Variable("CommandCounter", "UInt32", True, "the client's handshake: SampleCounter + 1 "
             "sends the setpoints as the next period's command"),
    Variable("SampleCounter", "UInt32", False, "the gateway's handshake: set to "
             "CommandCounter once that command's sample is in the values"),
    Variable("Lockstep", "Boolean", False, "sim_node runs in command-triggered lockstep "
             "(lockstep and lockstep_trigger, followed at runtime)"),
    Variable("Heartbeat", "UInt32", True, "the owner's heartbeat: any write of the owner "
             "(this counter, a setpoint, CommandCounter) or Step within heartbeat_timeout_s "
             "keeps its ownership (and, in free run, the drive) alive"),
    Variable("Status", "Int32", False, "RigStatus: WaitingForSim, Running, WaitingForClient, "
             "HeartbeatLost, SimLost, Faulted (EnumStrings)", enumeration=RigStatus),
    Variable("StatusText", "String", False, "what the gateway does or waits for, and why, one "
             "line"),
    Variable("ControlPeriod", "Double", False, "sim_node's sample period (1/publish_rate_hz): "
             "the period a control law must use, whatever the PLC task's cycle", SECOND),
    Variable("RejectedWrites", "UInt32", False, "writes and calls refused with a Bad status "
             "code"),
)
VARIABLE_BY_NAME = {v.name: v for v in VARIABLES}
SAMPLE_VARIABLES = tuple(v for v in VARIABLES if v.source is not None)
STEP_METHOD = "Step"
RESET_METHOD = "Reset"
METHOD_MEANINGS = {
    STEP_METHOD: "sends the setpoints as the next period's command (as CommandCounter + 1 "
    "does) and returns the new SampleCounter (UInt32) once that sample is in the values, or "
    "BadTimeout after step_timeout_s",
    RESET_METHOD: "after HeartbeatLost (the drive at rest) or Faulted: the rig takes writes "
    "again, and the first session that writes owns the setpoints",
}


# A setting read from sim_node is given in decimal (a YAML or command-line value), so 15
# significant digits hold it whole; a scaled preset's SI round trip (x / c * c) can add an ulp
# (50000.00000000001), which :func:`exact_setting` takes off.
SETTING_DIGITS = 15
# A write within this many ulps of an EURange bound is in range (and clamped to the bound):
# 300 rev/min is 300*pi/30 = 31.41592653589793 or 300/(30/pi) = 31.415926535897928 rad/s,
# depending on how a PLC writes the conversion.
RANGE_TOLERANCE_ULPS = 4


def exact_setting(value: float) -> float:
    """A decimal setting without the last-digit drift of a unit round trip."""
    return float(f"{value:.{SETTING_DIGITS}g}") if math.isfinite(value) else value


def rad_s_of_rpm(rpm: float) -> float:
    """rev/min -> rad/s as rpm*pi/30, so 300 rev/min gives the double nearest 10*pi."""
    return exact_setting(rpm) * math.pi / 30.0


def within(value: float, low: float, high: float) -> float | None:
    """``value`` in [``low``, ``high``] (one within RANGE_TOLERANCE_ULPS of a bound: that
    bound), or None if it is not finite or outside."""
    if not math.isfinite(value):
        return None
    if low <= value <= high:
        return value
    for bound in (low, high):
        if abs(value - bound) <= RANGE_TOLERANCE_ULPS * math.ulp(bound):
            return bound
    return None


def unece_unit_id(code: str) -> int:
    """The EUInformation UnitId of a UNECE common code (its ASCII bytes, big-endian)."""
    unit_id = 0
    for char in code:
        unit_id = (unit_id << 8) | ord(char)
    return unit_id


def node_id(rig: str, name: str) -> str:
    """The string NodeId of a rig's variable or method in :data:`NAMESPACE_URI`
    (``Rig.DriveSpeed``): stable across restarts, so a PLC may bind to it."""
    return f"{rig}.{name}"


def rig_name(namespace: str) -> str:
    """The rig object's BrowseName: the ROS namespace's last part, ``Rig`` in the root."""
    return namespace.rstrip("/").rpartition("/")[2] or DEFAULT_RIG


def _range_text(variable: Variable) -> str:
    if variable.name == "TorqueCommand":
        return f"±`{variable.limit}`"
    if variable.limit:
        return f"0 … `{variable.limit}`" + (" (in rad/s)" if variable.unit is RAD_S else "")
    if variable.enumeration is not None:
        return ", ".join(f"{member.value} {member.name}" for member in variable.enumeration)
    return ""


def markdown_table() -> str:
    """The address space as the Markdown table of docs/hil.md."""
    lines = ["| BrowseName | type | access | unit (UNECE) | EURange or values | meaning |",
             "| --- | --- | --- | --- | --- | --- |"]
    for v in VARIABLES:
        unit = f"{v.unit.symbol} (`{v.unit.code}`)" if v.unit else "–"
        access = "read/write" if v.writable else "read"
        kind = f"{v.enumeration.__name__} (Int32)" if v.enumeration else v.type_name
        lines.append(f"| `{v.name}` | {kind} | {access} | {unit} | "
                     f"{_range_text(v) or '–'} | {v.meaning} |")
    for name, meaning in METHOD_MEANINGS.items():
        lines.append(f"| `{name}()` | method | call | – | – | {meaning} |")
    return "\n".join(lines)
