"""Simulator samples -> SI telemetry rows -> ROS messages.

:class:`TelemetryConverter` turns dimensionless kernel samples into rows of
``topics.TELEMETRY_FIELDS`` (SI, rpm for speeds) with plain Python floats, the cheapest way
for the one or few rows of a tick; :func:`telemetry_rows` is the column-wise numpy reference
it must agree with bit for bit (the same IEEE operations in the same order).
:class:`SampleMessages` holds every message of one sample, all with the same (simulated)
stamp, in two forms: the CDR bytes to publish, packed straight from the row into fixed-layout
templates (:mod:`drill_sim_ros.ros.cdr`; rclpy publishes bytes without converting or
serializing them), and preallocated message objects, refilled in place, for the recorder.
Tests check the bytes against rclpy's serializer (they differ only in alignment padding,
which rclpy leaves uninitialized and the templates zero, so lockstep bytes are reproducible).
"""

from __future__ import annotations

from array import array

import numpy as np
from builtin_interfaces.msg import Time
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import JointState
from std_msgs.msg import Float64, Float64MultiArray, MultiArrayDimension, MultiArrayLayout, UInt8

from drill_sim_ros import topics
from drill_sim_ros.model import kernel as k
from drill_sim_ros.model.params import RPM_PER_RAD_S, Scales
from drill_sim_ros.model.simulator import Samples
from drill_sim_ros.ros.cdr import (
    CDR_HEADER,
    CLOCK_CDR,
    FLOAT64_CDR,
    UINT8_CDR,
    JointStateFrame,
    Pair,
    TelemetryFrame,
)

F = topics.TELEMETRY_INDEX
N_FIELDS = len(topics.TELEMETRY_FIELDS)
NS_PER_S = 1_000_000_000
# Kernel column of each telemetry field but sim_time_s and hook_load_n (filled separately).
SOURCE_COLUMNS = {
    "bit_angle_rad": k.C_PHI, "bit_rpm": k.C_OMEGA, "bit_depth_m": k.C_U, "rop_m_s": k.C_V,
    "wob_n": k.C_WOB, "tob_nm": k.C_TOB, "depth_of_cut_m": k.C_DOC, "wearflat_wob_n": k.C_WF,
    "mode": k.C_MODE, "surface_angle_rad": k.C_PHI_S, "surface_rpm": k.C_OMEGA_S,
    "surface_torque_nm": k.C_T_PIPE, "applied_wob_n": k.C_W_APP,
}
_FIELDS = np.array([F[name] for name in SOURCE_COLUMNS])
_COLUMNS = np.array(list(SOURCE_COLUMNS.values()))
_DEPTH = F["bit_depth_m"]
_ANGLES = [F["bit_angle_rad"], F["surface_angle_rad"]]
FLOAT64_FIELDS = ((topics.BIT_WOB, F["wob_n"]), (topics.BIT_TOB, F["tob_nm"]),
                  (topics.BIT_ROP, F["rop_m_s"]), (topics.BIT_RPM, F["bit_rpm"]),
                  (topics.BIT_DEPTH_OF_CUT, F["depth_of_cut_m"]))


def field_scales(scales: Scales) -> np.ndarray:
    """SI factor of each telemetry field (1 for sim time, mode and hook load), shape (F,)."""
    rpm = RPM_PER_RAD_S / scales.time_s
    factors = {"bit_rpm": rpm, "surface_rpm": rpm, "bit_depth_m": scales.length_m,
               "rop_m_s": scales.length_m / scales.time_s, "depth_of_cut_m": scales.length_m,
               "wob_n": scales.force_n, "wearflat_wob_n": scales.force_n,
               "applied_wob_n": scales.force_n, "tob_nm": scales.torque_nm,
               "surface_torque_nm": scales.torque_nm}
    out = np.ones(N_FIELDS)
    for name, factor in factors.items():
        out[F[name]] = factor
    return out


def telemetry_rows(samples: Samples, scales: Scales, sim_times_s: np.ndarray,
                   submerged_weight_n: float) -> np.ndarray:
    """SI rows, shape (len(samples), N_FIELDS), columns in ``TELEMETRY_FIELDS`` order.

    Each value is ``(column + rebasing offset) * factor``, as :meth:`Samples.column` gives it.
    """
    factors = field_scales(scales)
    out = np.empty((len(samples), N_FIELDS))
    out[:, _FIELDS] = samples.data[:, _COLUMNS]
    out[:, _DEPTH] += samples.depth_offset
    out[:, _ANGLES] += samples.angle_offset
    out *= factors
    out[:, F["sim_time_s"]] = sim_times_s
    out[:, F["hook_load_n"]] = submerged_weight_n - out[:, F["applied_wob_n"]]
    return out


class TelemetryConverter:
    """Kernel samples -> SI telemetry rows as lists of Python floats (no numpy per row)."""

    def __init__(self, scales: Scales) -> None:
        factors = field_scales(scales).tolist()
        self._rpm = factors[F["bit_rpm"]]
        self._length = factors[F["bit_depth_m"]]
        self._speed = factors[F["rop_m_s"]]
        self._force = factors[F["wob_n"]]
        self._torque = factors[F["tob_nm"]]

    def rows(self, samples: Samples, sim_times_s: list[float],
             submerged_weight_n: float) -> list[list[float]]:
        """One list of N_FIELDS floats per sample, in ``TELEMETRY_FIELDS`` order."""
        depth, angle = samples.depth_offset, samples.angle_offset
        return [self._row(raw, time_s, depth, angle, submerged_weight_n)
                for raw, time_s in zip(samples.data.tolist(), sim_times_s, strict=True)]

    def _row(self, r: list[float], time_s: float, depth_offset: float, angle_offset: float,
             submerged_weight_n: float) -> list[float]:
        applied_wob_n = r[k.C_W_APP] * self._force
        return [time_s, (r[k.C_PHI] + angle_offset) * 1.0, r[k.C_OMEGA] * self._rpm,
                (r[k.C_U] + depth_offset) * self._length, r[k.C_V] * self._speed,
                r[k.C_WOB] * self._force, r[k.C_TOB] * self._torque,
                r[k.C_DOC] * self._length, r[k.C_WF] * self._force, r[k.C_MODE] * 1.0,
                (r[k.C_PHI_S] + angle_offset) * 1.0, r[k.C_OMEGA_S] * self._rpm,
                r[k.C_T_PIPE] * self._torque, applied_wob_n,
                submerged_weight_n - applied_wob_n]


def stamp(time_ns: int) -> Time:
    """builtin_interfaces/Time of an integer nanosecond count."""
    sec, nanosec = divmod(int(time_ns), NS_PER_S)
    return Time(sec=sec, nanosec=nanosec)


def _joint_state(names: tuple[str, ...], when: Time) -> JointState:
    msg = JointState(name=list(names))
    msg.header.stamp = when
    msg.position = array("d", [0.0, 0.0])
    msg.velocity = array("d", [0.0, 0.0])
    msg.effort = array("d", [0.0, 0.0])
    return msg


def bit_joints(v: list[float]) -> tuple[Pair, Pair, Pair]:
    """Position, velocity, effort of ``bit_rotation`` and ``bit_axial`` (see topics.py)."""
    return ((v[F["bit_angle_rad"]], v[F["bit_depth_m"]]),
            (v[F["bit_rpm"]] / RPM_PER_RAD_S, v[F["rop_m_s"]]),
            (v[F["tob_nm"]], v[F["wob_n"]]))


def surface_joints(v: list[float]) -> tuple[Pair, Pair, Pair]:
    """Position, velocity, effort of ``top_drive`` and ``hook`` (see topics.py)."""
    return ((v[F["surface_angle_rad"]], v[F["bit_depth_m"]]),
            (v[F["surface_rpm"]] / RPM_PER_RAD_S, v[F["rop_m_s"]]),
            (v[F["surface_torque_nm"]], v[F["hook_load_n"]]))


def _fill_joints(msg: JointState, position: Pair, velocity: Pair, effort: Pair) -> None:
    msg.position[0], msg.position[1] = position
    msg.velocity[0], msg.velocity[1] = velocity
    msg.effort[0], msg.effort[1] = effort


class SampleMessages:
    """The messages of one sample: :meth:`payloads` packs a row into CDR bytes to publish,
    :meth:`fill` writes it into the message objects (for the recorder), in place.

    The joint states and /clock share one ``Time``. ``messages(with_clock)`` lists
    ``(topic, message)`` in publishing order, the order of the payloads.
    """

    def __init__(self) -> None:
        self._when = Time()
        self._scalars = [(index, Float64()) for _, index in FLOAT64_FIELDS]
        self._mode = UInt8()
        self._bit = _joint_state(topics.BIT_JOINTS, self._when)
        self._surface = _joint_state(topics.SURFACE_JOINTS, self._when)
        dim = MultiArrayDimension(label=",".join(topics.TELEMETRY_FIELDS), size=N_FIELDS,
                                  stride=N_FIELDS)
        self._telemetry = Float64MultiArray(layout=MultiArrayLayout(dim=[dim]))
        self._clock = Clock(clock=self._when)
        self._bit_frame = JointStateFrame(topics.BIT_JOINTS)
        self._surface_frame = JointStateFrame(topics.SURFACE_JOINTS)
        self._telemetry_frame = TelemetryFrame(dim, N_FIELDS)
        scalar_topics = [topic for topic, _ in FLOAT64_FIELDS]
        self._listed = [*zip(scalar_topics, [m for _, m in self._scalars], strict=True),
                        (topics.BIT_MODE, self._mode), (topics.BIT_JOINT_STATES, self._bit),
                        (topics.SURFACE_JOINT_STATES, self._surface),
                        (topics.TELEMETRY, self._telemetry)]

    def messages(self, with_clock: bool) -> list[tuple[str, object]]:
        """``(topic, message)`` of every sample topic, and /clock if ``with_clock``."""
        return [*self._listed, (topics.CLOCK, self._clock)] if with_clock else list(self._listed)

    def payloads(self, v: list[float], time_ns: int) -> list[bytes]:
        """CDR bytes of every message of one SI row stamped ``time_ns``, /clock last."""
        sec, nanosec = divmod(time_ns, NS_PER_S)
        out = [FLOAT64_CDR.pack(CDR_HEADER, v[index]) for index, _ in self._scalars]
        out.append(UINT8_CDR.pack(CDR_HEADER, int(v[F["mode"]])))
        out.append(self._bit_frame.pack(sec, nanosec, *bit_joints(v)))
        out.append(self._surface_frame.pack(sec, nanosec, *surface_joints(v)))
        out.append(self._telemetry_frame.pack(v))
        out.append(CLOCK_CDR.pack(CDR_HEADER, sec, nanosec))
        return out

    def fill(self, v: list[float], time_ns: int) -> None:
        """Write one SI row (``TELEMETRY_FIELDS`` order) stamped ``time_ns`` of sim time."""
        self._when.sec, self._when.nanosec = divmod(time_ns, NS_PER_S)
        for index, msg in self._scalars:
            msg.data = v[index]
        self._mode.data = int(v[F["mode"]])
        _fill_joints(self._bit, *bit_joints(v))
        _fill_joints(self._surface, *surface_joints(v))
        self._telemetry.data = array("d", v)
