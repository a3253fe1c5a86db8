"""Simulator samples -> SI telemetry rows -> ROS messages.

:func:`telemetry_rows` turns dimensionless kernel samples into rows of
``topics.TELEMETRY_FIELDS`` (SI, rpm for speeds); :class:`MessageFactory` builds every
message of one sample from such a row, all with the same (simulated) stamp.
"""

from __future__ import annotations

import numpy as np
from builtin_interfaces.msg import Time
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import JointState
from std_msgs.msg import Float64, Float64MultiArray, MultiArrayDimension, UInt8

from drill_sim_ros import topics
from drill_sim_ros.model import kernel as k
from drill_sim_ros.model.params import RPM_PER_RAD_S, Scales
from drill_sim_ros.model.simulator import Samples

F = topics.TELEMETRY_INDEX
N_FIELDS = len(topics.TELEMETRY_FIELDS)
NS_PER_S = 1_000_000_000


def telemetry_rows(samples: Samples, scales: Scales, sim_times_s: np.ndarray,
                   submerged_weight_n: float) -> np.ndarray:
    """SI rows, shape (len(samples), N_FIELDS), columns in ``TELEMETRY_FIELDS`` order."""
    out = np.empty((len(samples), N_FIELDS))
    out[:, F["sim_time_s"]] = sim_times_s
    out[:, F["bit_angle_rad"]] = samples.column(k.C_PHI)
    out[:, F["bit_rpm"]] = samples.column(k.C_OMEGA) * (RPM_PER_RAD_S / scales.time_s)
    out[:, F["bit_depth_m"]] = samples.column(k.C_U) * scales.length_m
    out[:, F["rop_m_s"]] = samples.column(k.C_V) * (scales.length_m / scales.time_s)
    out[:, F["wob_n"]] = samples.column(k.C_WOB) * scales.force_n
    out[:, F["tob_nm"]] = samples.column(k.C_TOB) * scales.torque_nm
    out[:, F["depth_of_cut_m"]] = samples.column(k.C_DOC) * scales.length_m
    out[:, F["wearflat_wob_n"]] = samples.column(k.C_WF) * scales.force_n
    out[:, F["mode"]] = samples.column(k.C_MODE)
    out[:, F["surface_angle_rad"]] = samples.column(k.C_PHI_S)
    out[:, F["surface_rpm"]] = samples.column(k.C_OMEGA_S) * (RPM_PER_RAD_S / scales.time_s)
    out[:, F["surface_torque_nm"]] = samples.column(k.C_T_PIPE) * scales.torque_nm
    out[:, F["applied_wob_n"]] = samples.column(k.C_W_APP) * scales.force_n
    out[:, F["hook_load_n"]] = submerged_weight_n - out[:, F["applied_wob_n"]]
    return out


def stamp(time_ns: int) -> Time:
    """builtin_interfaces/Time of an integer nanosecond count."""
    sec, nanosec = divmod(int(time_ns), NS_PER_S)
    return Time(sec=sec, nanosec=nanosec)


class MessageFactory:
    """Builds the messages of one telemetry row; ``publish_clock`` adds /clock."""

    def __init__(self) -> None:
        label = ",".join(topics.TELEMETRY_FIELDS)
        self._dim = MultiArrayDimension(label=label, size=N_FIELDS, stride=N_FIELDS)

    def build(self, row: np.ndarray, time_ns: int, with_clock: bool) -> dict[str, object]:
        """Messages of one sample (SI row), all stamped ``time_ns`` of simulated time."""
        values = row.tolist()
        when = stamp(time_ns)
        msgs: dict[str, object] = {
            topics.BIT_WOB: Float64(data=values[F["wob_n"]]),
            topics.BIT_TOB: Float64(data=values[F["tob_nm"]]),
            topics.BIT_ROP: Float64(data=values[F["rop_m_s"]]),
            topics.BIT_RPM: Float64(data=values[F["bit_rpm"]]),
            topics.BIT_DEPTH_OF_CUT: Float64(data=values[F["depth_of_cut_m"]]),
            topics.BIT_MODE: UInt8(data=int(values[F["mode"]])),
            topics.BIT_JOINT_STATES: self._bit_joints(values, when),
            topics.SURFACE_JOINT_STATES: self._surface_joints(values, when),
            topics.TELEMETRY: self._telemetry(values),
        }
        if with_clock:
            msgs[topics.CLOCK] = Clock(clock=when)
        return msgs

    @staticmethod
    def _bit_joints(v: list[float], when: Time) -> JointState:
        msg = JointState(name=list(topics.BIT_JOINTS))
        msg.header.stamp = when
        msg.position = [v[F["bit_angle_rad"]], v[F["bit_depth_m"]]]
        msg.velocity = [v[F["bit_rpm"]] / RPM_PER_RAD_S, v[F["rop_m_s"]]]
        msg.effort = [v[F["tob_nm"]], v[F["wob_n"]]]
        return msg

    @staticmethod
    def _surface_joints(v: list[float], when: Time) -> JointState:
        msg = JointState(name=list(topics.SURFACE_JOINTS))
        msg.header.stamp = when
        msg.position = [v[F["surface_angle_rad"]], v[F["bit_depth_m"]]]
        msg.velocity = [v[F["surface_rpm"]] / RPM_PER_RAD_S, v[F["rop_m_s"]]]
        msg.effort = [v[F["surface_torque_nm"]], v[F["hook_load_n"]]]
        return msg

    def _telemetry(self, values: list[float]) -> Float64MultiArray:
        msg = Float64MultiArray(data=values)
        msg.layout.dim = [self._dim]
        return msg
