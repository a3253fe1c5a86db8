"""The ROS interface of drill_sim_ros: topic names, message types and telemetry fields.

Pure data (no rclpy import), shared by the sim node, the MCAP archive and the rerun bridge.
Units are SI unless the name says otherwise (rpm = rev/min).
"""

from __future__ import annotations

from drill_sim_ros.model.telemetry import MODE_NAMES, TELEMETRY_FIELDS, TELEMETRY_INDEX

__all__ = ["MODE_NAMES", "TELEMETRY_FIELDS", "TELEMETRY_INDEX"]   # with the names below

NODE_NAME = "drill_sim"

# ---- published by sim_node -------------------------------------------------------------
BIT_WOB = "/drill/bit/wob"                    # std_msgs/Float64, N
BIT_TOB = "/drill/bit/tob"                    # std_msgs/Float64, N m
BIT_ROP = "/drill/bit/rop"                    # std_msgs/Float64, m/s
BIT_RPM = "/drill/bit/rpm"                    # std_msgs/Float64, rev/min
BIT_DEPTH_OF_CUT = "/drill/bit/depth_of_cut"  # std_msgs/Float64, m per revolution
BIT_MODE = "/drill/bit/mode"                  # std_msgs/UInt8, see MODE_NAMES
BIT_JOINT_STATES = "/drill/bit/joint_states"  # sensor_msgs/JointState (BIT_JOINTS)
SURFACE_JOINT_STATES = "/drill/surface/joint_states"  # sensor_msgs/JointState (SURFACE_JOINTS)
SURFACE_MEASURED = "/drill/surface/measured"  # sensor_msgs/JointState (MEASURED_JOINTS)
TELEMETRY = "/drill/telemetry"                # std_msgs/Float64MultiArray (TELEMETRY_FIELDS)
DIAGNOSTICS = "/diagnostics"                  # diagnostic_msgs/DiagnosticArray, 1 Hz
CLOCK = "/clock"                              # rosgraph_msgs/Clock (publish_clock)
RUN_INFO = "/drill/run_info"                  # std_msgs/String, JSON; latched (transient local)
# distributed string only, at string.rate_hz (10 Hz) of sim time: one joint per depth
STRING_TORSION = "/drill/string/torsion"      # sensor_msgs/JointState (STRING_JOINT_PATTERN)

# ---- subscribed by sim_node ------------------------------------------------------------
CMD_SURFACE_RPM = "/drill/cmd/surface_rpm"    # std_msgs/Float64, rev/min
CMD_WOB = "/drill/cmd/wob"                    # std_msgs/Float64, N
CMD_TOP_DRIVE = "/drill/cmd/top_drive"        # sensor_msgs/JointState (COMMAND_JOINTS)
# top_drive: velocity = speed setpoint rad/s, effort = motor torque N m (torque mode);
# hook: effort = applied WOB N, as in the state. header.stamp: the stamp of the sample the
# command reacts to. Each array is empty or as long as name; other messages are rejected.
COMMAND_JOINTS = ("top_drive", "hook")
COMMANDS = (CMD_SURFACE_RPM, CMD_WOB, CMD_TOP_DRIVE)

# ---- typed twins (drill_sim_msgs, when installed; drill_sim_ros.ros.typed) --------------
TYPED_TELEMETRY = "/drill/typed/telemetry"    # drill_sim_msgs/Telemetry, one per sample
TYPED_RUN_INFO = "/drill/typed/run_info"      # drill_sim_msgs/RunInfo; latched
TYPED_CMD_TOP_DRIVE = "/drill/typed/cmd/top_drive"  # drill_sim_msgs/TopDriveCommand (subscribed)
# string.message typed (the default): the string profiles as drill_sim_msgs/StringProfile
# here instead of drill/string/torsion's JointState
TYPED_STRING_TORSION = "/drill/typed/string/torsion"
TYPED_MSG_TYPES: dict[str, str] = {
    TYPED_TELEMETRY: "drill_sim_msgs/msg/Telemetry",
    TYPED_RUN_INFO: "drill_sim_msgs/msg/RunInfo",
    TYPED_CMD_TOP_DRIVE: "drill_sim_msgs/msg/TopDriveCommand",
    TYPED_STRING_TORSION: "drill_sim_msgs/msg/StringProfile",
}
# published at a lower rate than the samples (not one message per sample): the string
# profiles, on one of the two topics (string.message)
PROFILE_TOPICS = (STRING_TORSION, TYPED_STRING_TORSION)

# sim_node names its topics relative to its namespace (`-r __ns:=/rig1` moves them all),
# except these two, which ROS conventions keep absolute. The names above are those of the
# root namespace, as a recording of a sim without a namespace holds them.
ABSOLUTE = (CLOCK, DIAGNOSTICS)


def node_relative(topic: str) -> str:
    """The name sim_node gives ``topic``: relative to its namespace, or absolute."""
    return topic if topic in ABSOLUTE else topic.lstrip("/")

MSG_TYPES: dict[str, str] = {
    BIT_WOB: "std_msgs/msg/Float64",
    BIT_TOB: "std_msgs/msg/Float64",
    BIT_ROP: "std_msgs/msg/Float64",
    BIT_RPM: "std_msgs/msg/Float64",
    BIT_DEPTH_OF_CUT: "std_msgs/msg/Float64",
    BIT_MODE: "std_msgs/msg/UInt8",
    BIT_JOINT_STATES: "sensor_msgs/msg/JointState",
    SURFACE_JOINT_STATES: "sensor_msgs/msg/JointState",
    SURFACE_MEASURED: "sensor_msgs/msg/JointState",
    TELEMETRY: "std_msgs/msg/Float64MultiArray",
    DIAGNOSTICS: "diagnostic_msgs/msg/DiagnosticArray",
    CLOCK: "rosgraph_msgs/msg/Clock",
    RUN_INFO: "std_msgs/msg/String",
    STRING_TORSION: "sensor_msgs/msg/JointState",
    CMD_SURFACE_RPM: "std_msgs/msg/Float64",
    CMD_WOB: "std_msgs/msg/Float64",
    CMD_TOP_DRIVE: "sensor_msgs/msg/JointState",
}

# JointState joints: position / velocity / effort
BIT_JOINTS = ("bit_rotation", "bit_axial")
# bit_rotation: angle rad, angular speed rad/s, torque on bit N m
# bit_axial:    depth m (down positive), rate of penetration m/s, weight on bit N
SURFACE_JOINTS = ("top_drive", "hook")
# top_drive: angle rad, speed rad/s, surface (pipe) torque N m
# hook:      bit depth m, rate of penetration m/s, applied WOB N (the weight the hook sets
#            down: submerged string weight - hook load; the hook load is in the telemetry)
# drill/string/torsion: string_<depth below the top, m, as 0000.0>m, top to bottom
STRING_JOINT_PATTERN = "string_DDDD.Dm"
# What the rig's surface sensors give (the only signals a controller should read):
# (no joint "hook" here: "hook" means the applied WOB, in the state and in the command)
MEASURED_JOINTS = ("top_drive", "quill", "hook_load", "wob_estimate")
# top_drive:    angle rad, measured speed rad/s (encoder), measured motor torque N m
# quill:        angle rad, measured speed rad/s, measured string torque N m (torque sub)
# hook_load:    bit depth m, rate of penetration m/s, measured hook load N (load cell)
# wob_estimate: bit depth m, rate of penetration m/s, applied WOB estimate N
#               (submerged string weight - measured hook load)

# /drill/telemetry carries one row of the model's telemetry record per sample, and its
# layout.dim[0].label lists TELEMETRY_FIELDS (drill_sim_ros.model.telemetry).

# What each topic carries, with its unit: the topic table of docs/sim_node.md is generated
# from MSG_TYPES, this, JOINTS and JOINT_FIELDS (`make docs`); a topic or joint without a
# description fails that test.
DESCRIPTIONS: dict[str, str] = {
    BIT_WOB: "weight on bit, N",
    BIT_TOB: "torque on bit, N m",
    BIT_ROP: "rate of penetration, m/s",
    BIT_RPM: "bit speed, rev/min",
    BIT_DEPTH_OF_CUT: "depth of cut per revolution, m (negative: bit above the rock)",
    BIT_MODE: "0 cutting, 1 lost_contact, 2 stuck, 3 off_bottom",
    BIT_JOINT_STATES: "the bit, true values",
    SURFACE_JOINT_STATES: "the surface, true values",
    SURFACE_MEASURED: "what the rig's sensors give (`sensors.*`); the only topic a "
                      "controller should read",
    TELEMETRY: "one record per sample, fields `TELEMETRY_FIELDS` (SI)",
    DIAGNOSTICS: "two statuses, 1 Hz of wall time",
    CLOCK: "simulated time (when `publish_clock`)",
    RUN_INFO: "JSON of what runs (preset, groups, scales, sampling, string), once",
    STRING_TORSION: "with `string.message` joint_state (the default, typed, sends "
                    "drill_sim_msgs/StringProfile on `/drill/typed/string/torsion`): the "
                    "distributed string along depth at `string.rate_hz` (default 10 Hz) "
                    "of sim time, `string.depths` (<= 64) joints top to bottom, joint "
                    "`string_DDDD.Dm` at DDDD.D m below the top (e.g. `string_0021.1m`); "
                    "not for a lumped string",
    CMD_SURFACE_RPM: "top-drive speed setpoint, rev/min",
    CMD_WOB: "applied WOB setpoint, N",
    CMD_TOP_DRIVE: "the controller's command; `header.stamp` = the stamp of the sample it "
                   "answers; NaN or a missing entry commands nothing",
}

# The joints of each JointState topic, in order.
JOINTS: dict[str, tuple[str, ...]] = {
    BIT_JOINT_STATES: BIT_JOINTS,
    SURFACE_JOINT_STATES: SURFACE_JOINTS,
    SURFACE_MEASURED: MEASURED_JOINTS,
    CMD_TOP_DRIVE: COMMAND_JOINTS,
    STRING_TORSION: (STRING_JOINT_PATTERN,),
}

# What position, velocity and effort of each joint mean, per topic ("-": unused).
JOINT_FIELDS: dict[str, dict[str, tuple[str, str, str]]] = {
    BIT_JOINT_STATES: {
        "bit_rotation": ("angle rad", "speed rad/s", "TOB N m"),
        "bit_axial": ("depth m (down positive)", "ROP m/s", "WOB N"),
    },
    SURFACE_JOINT_STATES: {
        "top_drive": ("angle rad", "speed rad/s", "surface (pipe) torque N m"),
        "hook": ("bit depth m", "ROP m/s", "applied WOB N"),
    },
    SURFACE_MEASURED: {
        "top_drive": ("angle rad", "encoder speed rad/s", "motor torque N m"),
        "quill": ("angle rad", "encoder speed rad/s", "string torque N m (torque sub)"),
        "hook_load": ("bit depth m", "ROP m/s", "measured hook load N (load cell)"),
        "wob_estimate": ("bit depth m", "ROP m/s",
                         "applied WOB estimate N (submerged weight - measured hook load)"),
    },
    STRING_TORSION: {
        STRING_JOINT_PATTERN: ("-", "angular speed rad/s at that depth",
                               "torque N m at that depth (twisting the string below it)"),
    },
    CMD_TOP_DRIVE: {
        "top_drive": ("-", "speed setpoint rad/s (kinematic, speed modes)",
                      "motor torque N m (torque mode)"),
        "hook": ("-", "-", "applied WOB N"),
    },
}
