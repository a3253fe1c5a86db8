"""The ROS interface of drill_sim_ros: topic names, message types and telemetry fields.

Pure data (no rclpy import), shared by the sim node, the MCAP archive and the rerun bridge.
Units are SI unless the name says otherwise (rpm = rev/min).
"""

from __future__ import annotations

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
TELEMETRY = "/drill/telemetry"                # std_msgs/Float64MultiArray (TELEMETRY_FIELDS)
DIAGNOSTICS = "/diagnostics"                  # diagnostic_msgs/DiagnosticArray, 1 Hz
CLOCK = "/clock"                              # rosgraph_msgs/Clock (publish_clock)

# ---- subscribed by sim_node ------------------------------------------------------------
CMD_SURFACE_RPM = "/drill/cmd/surface_rpm"    # std_msgs/Float64, rev/min
CMD_WOB = "/drill/cmd/wob"                    # std_msgs/Float64, N

MSG_TYPES: dict[str, str] = {
    BIT_WOB: "std_msgs/msg/Float64",
    BIT_TOB: "std_msgs/msg/Float64",
    BIT_ROP: "std_msgs/msg/Float64",
    BIT_RPM: "std_msgs/msg/Float64",
    BIT_DEPTH_OF_CUT: "std_msgs/msg/Float64",
    BIT_MODE: "std_msgs/msg/UInt8",
    BIT_JOINT_STATES: "sensor_msgs/msg/JointState",
    SURFACE_JOINT_STATES: "sensor_msgs/msg/JointState",
    TELEMETRY: "std_msgs/msg/Float64MultiArray",
    DIAGNOSTICS: "diagnostic_msgs/msg/DiagnosticArray",
    CLOCK: "rosgraph_msgs/msg/Clock",
    CMD_SURFACE_RPM: "std_msgs/msg/Float64",
    CMD_WOB: "std_msgs/msg/Float64",
}

# JointState joints: position / velocity / effort
BIT_JOINTS = ("bit_rotation", "bit_axial")
# bit_rotation: angle rad, angular speed rad/s, torque on bit N m
# bit_axial:    depth m (down positive), rate of penetration m/s, weight on bit N
SURFACE_JOINTS = ("top_drive", "hook")
# top_drive: angle rad, speed rad/s, surface (pipe) torque N m
# hook:      bit depth m, rate of penetration m/s, hook load N

# One flat, atomic record per published sample (layout.dim[0].label lists these names).
TELEMETRY_FIELDS = (
    "sim_time_s",
    "bit_angle_rad",
    "bit_rpm",
    "bit_depth_m",
    "rop_m_s",
    "wob_n",
    "tob_nm",
    "depth_of_cut_m",
    "wearflat_wob_n",
    "mode",
    "surface_angle_rad",
    "surface_rpm",
    "surface_torque_nm",
    "applied_wob_n",
    "hook_load_n",
)
TELEMETRY_INDEX = {name: i for i, name in enumerate(TELEMETRY_FIELDS)}

MODE_NAMES = ("cutting", "lost_contact", "stuck", "off_bottom")
