"""Every payload of a block of samples, packed into CDR by one compiled call.

A :class:`SampleFrame` lays the CDR templates of :mod:`drill_sim_ros.ros.cdr` side by side in
one 8-byte-aligned buffer per sample, each starting 4 bytes past a multiple of 8, so that every
float64 of the CDR body (8-aligned after the 4-byte encapsulation header) is an element of the
buffer's float64 view. :func:`_fill` writes the SI telemetry rows of a block (from
:mod:`drill_sim_ros.model.telemetry`, the one SI conversion), their stamps and modes into
those buffers; Python then slices the payloads and hands them to rclpy's publishers as bytes.
The bytes equal rclpy's serialization of the same values (tests/ros/test_frame.py).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from drill_sim_ros import topics
from drill_sim_ros.model.params import RPM_PER_RAD_S
from drill_sim_ros.model.telemetry import NS_PER_S, TELEMETRY_FIELDS
from drill_sim_ros.ros.cdr import (
    Layout,
    clock_layout,
    float64_layout,
    joint_state_layout,
    multi_array_layout,
    uint8_layout,
)

F = topics.TELEMETRY_INDEX
N_FIELDS = len(TELEMETRY_FIELDS)
FLOAT64_TOPICS = {topics.BIT_WOB: "wob_n", topics.BIT_TOB: "tob_nm", topics.BIT_ROP: "rop_m_s",
                  topics.BIT_RPM: "bit_rpm", topics.BIT_DEPTH_OF_CUT: "depth_of_cut_m"}
# JointState doubles, (field, in rad/s): the positions, velocities, then efforts of the two
# joints of topics.py.
BIT_JOINT_VALUES = (("bit_angle_rad", False), ("bit_depth_m", False), ("bit_rpm", True),
                    ("rop_m_s", False), ("tob_nm", False), ("wob_n", False))
SURFACE_JOINT_VALUES = (("surface_angle_rad", False), ("bit_depth_m", False),
                        ("surface_rpm", True), ("rop_m_s", False),
                        ("surface_torque_nm", False), ("applied_wob_n", False))
MEASURED_JOINT_VALUES = (("surface_angle_rad", False), ("surface_angle_rad", False),
                         ("bit_depth_m", False), ("bit_depth_m", False),
                         ("drive_speed_measured_rad_s", False),
                         ("drive_speed_measured_rad_s", False),
                         ("rop_m_s", False), ("rop_m_s", False),
                         ("motor_torque_measured_nm", False),
                         ("string_torque_measured_nm", False),
                         ("hook_load_measured_n", False), ("applied_wob_estimate_n", False))
SAMPLE_TOPICS = (*FLOAT64_TOPICS, topics.BIT_MODE, topics.BIT_JOINT_STATES,
                 topics.SURFACE_JOINT_STATES, topics.SURFACE_MEASURED, topics.TELEMETRY)
TELEMETRY_LABEL = ",".join(TELEMETRY_FIELDS)

_MODE = F["mode"]
# plan: [n_doubles, n_stamps, mode byte, then (float64 index, field, in rad/s) per double,
# then the int32 index of each stamp's seconds]
_HEAD = 3


def _layouts() -> dict[str, tuple[Layout, list[tuple[str, bool]]]]:
    """Each sample topic's layout and the (field, in rad/s) of its doubles, in order."""
    out: dict[str, tuple[Layout, list[tuple[str, bool]]]] = {
        topic: (float64_layout(), [(field, False)]) for topic, field in FLOAT64_TOPICS.items()}
    out[topics.BIT_MODE] = (uint8_layout(), [])
    for topic, names, values in ((topics.BIT_JOINT_STATES, topics.BIT_JOINTS, BIT_JOINT_VALUES),
                                 (topics.SURFACE_JOINT_STATES, topics.SURFACE_JOINTS,
                                  SURFACE_JOINT_VALUES),
                                 (topics.SURFACE_MEASURED, topics.MEASURED_JOINTS,
                                  MEASURED_JOINT_VALUES)):
        out[topic] = (joint_state_layout(names), list(values))
    out[topics.TELEMETRY] = (multi_array_layout(TELEMETRY_LABEL, N_FIELDS),
                             [(name, False) for name in TELEMETRY_FIELDS])
    out[topics.CLOCK] = (clock_layout(), [])
    return out


def _starts(lengths: list[int]) -> tuple[list[int], int]:
    """Where each payload starts (4 past a multiple of 8, so the CDR body's float64 values
    are 8-aligned) and the buffer size in bytes."""
    starts, end = [], 4
    for length in lengths:
        starts.append(end)
        end += -(-length // 8) * 8
    return starts, -(-end // 8) * 8


def aligned_index(offset: int, size: int) -> int:
    """``offset`` in units of ``size`` bytes (a layout change that breaks alignment raises)."""
    if offset % size:
        raise ValueError(f"payload value at byte {offset} is not {size}-byte aligned")
    return offset // size


def _plan(placed: list[tuple[int, Layout, list[tuple[str, bool]]]]) -> np.ndarray:
    """The int64 plan of :func:`_fill` for layouts placed at the given buffer offsets."""
    doubles: list[int] = []
    stamps: list[int] = []
    mode_at = -1
    for start, layout, values in placed:
        for at, (field, rad_s) in zip(layout.doubles, values, strict=True):
            doubles += [aligned_index(start + at, 8), F[field], int(rad_s)]
        if layout.stamp is not None:
            stamps.append(aligned_index(start + layout.stamp, 4))
        if layout.byte is not None:
            mode_at = start + layout.byte
    return np.array([len(doubles) // 3, len(stamps), mode_at, *doubles, *stamps],
                    dtype=np.int64)


class SampleFrame:
    """The payloads of a sample (``topics`` order, /clock last if ``with_clock``)."""

    def __init__(self, with_clock: bool) -> None:
        self.topics = (*SAMPLE_TOPICS, topics.CLOCK) if with_clock else SAMPLE_TOPICS
        layouts = _layouts()
        chosen = [layouts[topic] for topic in self.topics]
        starts, size = _starts([len(layout.template) for layout, _ in chosen])
        self._template = np.zeros(size // 8, dtype=np.float64)
        raw = self._template.view(np.uint8)
        self._slices = [slice(start, start + len(layout.template))
                        for start, (layout, _) in zip(starts, chosen, strict=True)]
        for part, (layout, _) in zip(self._slices, chosen, strict=True):
            raw[part] = np.frombuffer(layout.template, np.uint8)
        self._plan = _plan([(start, layout, values)
                            for start, (layout, values) in zip(starts, chosen, strict=True)])
        self._buffers = np.tile(self._template, (1, 1))

    def pack(self, rows: np.ndarray, stamps_ns: np.ndarray) -> list[list[bytes]]:
        """The payloads of each SI row (``TELEMETRY_FIELDS`` order) stamped ``stamps_ns``."""
        count = rows.shape[0]
        if count > self._buffers.shape[0]:
            self._buffers = np.tile(self._template, (count, 1))
        _fill(rows, stamps_ns, self._buffers, self._plan)
        return [list(map(self._buffers[i].tobytes().__getitem__, self._slices))
                for i in range(count)]


@njit(cache=True)
def _fill(rows: np.ndarray, stamps_ns: np.ndarray, buffers: np.ndarray,
          plan: np.ndarray) -> None:
    """Each SI row's values, stamps and mode into its template buffer (row i -> buffers[i])."""
    n_doubles, n_stamps = plan[0], plan[1]
    for i in range(rows.shape[0]):
        row, buffer, time_ns = rows[i], buffers[i], stamps_ns[i]
        for j in range(n_doubles):
            at, field = plan[_HEAD + 3 * j], plan[_HEAD + 3 * j + 1]
            rad_s = plan[_HEAD + 3 * j + 2]
            buffer[at] = row[field] / RPM_PER_RAD_S if rad_s else row[field]
        words = buffer.view(np.int32)
        for j in range(n_stamps):
            at = plan[_HEAD + 3 * n_doubles + j]
            words[at] = time_ns // NS_PER_S
            words[at + 1] = time_ns % NS_PER_S
        if plan[2] >= 0:
            buffer.view(np.uint8)[plan[2]] = np.uint8(int(row[_MODE]))
