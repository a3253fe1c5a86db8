"""Every payload of one sample, converted and packed by one compiled call.

A :class:`SampleFrame` lays the CDR templates of :mod:`drill_sim_ros.ros.cdr` side by side in
one 8-byte-aligned buffer, each starting 4 bytes past a multiple of 8, so that every float64
of the CDR body (8-aligned after the 4-byte encapsulation header) is an element of the
buffer's float64 view. :func:`_fill` turns one kernel sample (dimensionless, ``kernel.C_*``
columns) into the SI telemetry row (``topics.TELEMETRY_FIELDS``) and writes the row, the
stamps and the mode into the buffer; Python then only slices the bytes and publishes them.

On a 10 ms tick of a 2-core VM the caches are cold, and each Python operation costs ten
times what a warm benchmark says: this path replaces about a hundred of them per sample.
The SI row equals :func:`drill_sim_ros.ros.conversions.telemetry_rows` bit for bit (the same
IEEE operations in the same order), and the bytes equal rclpy's serialization of the same
values (tests/ros/test_frame.py).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from drill_sim_ros import topics
from drill_sim_ros.model.params import RPM_PER_RAD_S, Scales
from drill_sim_ros.ros.cdr import (
    Layout,
    clock_layout,
    float64_layout,
    joint_state_layout,
    multi_array_layout,
    uint8_layout,
)
from drill_sim_ros.ros.conversions import (
    NS_PER_S,
    SOURCE_COLUMNS,
    SOURCE_FIELDS,
    SOURCE_KERNEL_COLUMNS,
    field_scales,
)

F = topics.TELEMETRY_INDEX
N_FIELDS = len(topics.TELEMETRY_FIELDS)
FLOAT64_TOPICS = {topics.BIT_WOB: "wob_n", topics.BIT_TOB: "tob_nm", topics.BIT_ROP: "rop_m_s",
                  topics.BIT_RPM: "bit_rpm", topics.BIT_DEPTH_OF_CUT: "depth_of_cut_m"}
# JointState doubles, (field, in rad/s): the positions, velocities, then efforts of the two
# joints of topics.py.
BIT_JOINT_VALUES = (("bit_angle_rad", False), ("bit_depth_m", False), ("bit_rpm", True),
                    ("rop_m_s", False), ("tob_nm", False), ("wob_n", False))
SURFACE_JOINT_VALUES = (("surface_angle_rad", False), ("bit_depth_m", False),
                        ("surface_rpm", True), ("rop_m_s", False),
                        ("surface_torque_nm", False), ("hook_load_n", False))
SAMPLE_TOPICS = (*FLOAT64_TOPICS, topics.BIT_MODE, topics.BIT_JOINT_STATES,
                 topics.SURFACE_JOINT_STATES, topics.TELEMETRY)
TELEMETRY_LABEL = ",".join(topics.TELEMETRY_FIELDS)

# The kernel column of each telemetry field it comes from, and what is added before scaling
# (as telemetry_rows: the rebasing offsets of depth and angles).
_FIELD, _COLUMN = SOURCE_FIELDS, SOURCE_KERNEL_COLUMNS
_ADD = np.array([1 if name == "bit_depth_m" else 2 if name.endswith("angle_rad") else 0
                 for name in SOURCE_COLUMNS], dtype=np.int64)
_TIME, _APPLIED, _HOOK, _MODE = F["sim_time_s"], F["applied_wob_n"], F["hook_load_n"], F["mode"]
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
                                  SURFACE_JOINT_VALUES)):
        out[topic] = (joint_state_layout(names), list(values))
    out[topics.TELEMETRY] = (multi_array_layout(TELEMETRY_LABEL, N_FIELDS),
                             [(name, False) for name in topics.TELEMETRY_FIELDS])
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


def _aligned(offset: int, size: int) -> int:
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
            doubles += [_aligned(start + at, 8), F[field], int(rad_s)]
        if layout.stamp is not None:
            stamps.append(_aligned(start + layout.stamp, 4))
        if layout.byte is not None:
            mode_at = start + layout.byte
    return np.array([len(doubles) // 3, len(stamps), mode_at, *doubles, *stamps],
                    dtype=np.int64)


class SampleFrame:
    """The payloads of one sample (``topics`` order, /clock last if ``with_clock``)."""

    def __init__(self, scales: Scales, with_clock: bool) -> None:
        self.topics = (*SAMPLE_TOPICS, topics.CLOCK) if with_clock else SAMPLE_TOPICS
        self._factors = field_scales(scales)
        self.row = np.zeros(N_FIELDS)          # the last SI row, TELEMETRY_FIELDS order
        layouts = _layouts()
        chosen = [layouts[topic] for topic in self.topics]
        starts, size = _starts([len(layout.template) for layout, _ in chosen])
        self._buffer = np.zeros(size // 8, dtype=np.float64)
        raw = self._buffer.view(np.uint8)
        self._slices = [slice(start, start + len(layout.template))
                        for start, (layout, _) in zip(starts, chosen, strict=True)]
        for part, (layout, _) in zip(self._slices, chosen, strict=True):
            raw[part] = np.frombuffer(layout.template, np.uint8)
        self._plan = _plan([(start, layout, values)
                            for start, (layout, values) in zip(starts, chosen, strict=True)])

    def pack(self, samples: np.ndarray, index: int, offsets: tuple[float, float],
             time_ns: int, submerged_weight_n: float) -> list[bytes]:
        """The payloads of kernel sample ``samples[index]`` (``kernel.C_*`` columns; depth and
        angles less ``offsets``) stamped ``time_ns`` of simulated time; fills :attr:`row`."""
        _fill(samples, index, offsets[0], offsets[1], time_ns, submerged_weight_n,
              self._factors, self.row, self._buffer, self._plan)
        return list(map(self._buffer.tobytes().__getitem__, self._slices))


@njit(cache=True)
def _fill(samples: np.ndarray, index: int, depth_offset: float, angle_offset: float,
          time_ns: int, submerged_weight_n: float, factors: np.ndarray, row: np.ndarray,
          buffer: np.ndarray, plan: np.ndarray) -> None:
    """SI row of one sample into ``row``; its values, stamps and mode into ``buffer``."""
    for i in range(_FIELD.shape[0]):
        value = samples[index, _COLUMN[i]]
        if _ADD[i] == 1:
            value = value + depth_offset
        elif _ADD[i] == 2:
            value = value + angle_offset
        row[_FIELD[i]] = value * factors[_FIELD[i]]
    row[_TIME] = time_ns / NS_PER_S
    row[_HOOK] = submerged_weight_n - row[_APPLIED]
    n_doubles, n_stamps = plan[0], plan[1]
    for j in range(n_doubles):
        at, field, rad_s = plan[_HEAD + 3 * j], plan[_HEAD + 3 * j + 1], plan[_HEAD + 3 * j + 2]
        buffer[at] = row[field] / RPM_PER_RAD_S if rad_s else row[field]
    words = buffer.view(np.int32)
    for j in range(n_stamps):
        at = plan[_HEAD + 3 * n_doubles + j]
        words[at] = time_ns // NS_PER_S
        words[at + 1] = time_ns % NS_PER_S
    if plan[2] >= 0:
        buffer.view(np.uint8)[plan[2]] = np.uint8(int(row[_MODE]))
