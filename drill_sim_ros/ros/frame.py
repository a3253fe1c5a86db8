"""Every payload of one sample, converted and packed by one compiled call.

A :class:`SampleFrame` lays the CDR templates of :mod:`drill_sim_ros.ros.cdr` side by side in
one 8-byte-aligned buffer, each starting 4 bytes past a multiple of 8, so that every float64
of the CDR body (8-aligned after the 4-byte encapsulation header) is an element of the
buffer's float64 view. :func:`_fill` turns one kernel sample (dimensionless, ``kernel.C_*``
columns) into the SI telemetry row (``topics.TELEMETRY_FIELDS``) and writes the row, the
stamps and the mode into the buffer. A :class:`FramePublisher` then hands each payload to
rcl's C call from the same compiled loop (:mod:`drill_sim_ros.ros.rcl_publish`), so a run of
samples is filled and published without a return to Python.

On a 10 ms tick of a 2-core VM the caches are cold, and each Python operation costs ten
times what a warm benchmark says: this path replaces a few hundred of them per sample.
The SI row equals :func:`drill_sim_ros.ros.conversions.telemetry_rows` bit for bit (the same
IEEE operations in the same order), and the bytes equal rclpy's serialization of the same
values (tests/ros/test_frame.py).
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np
from numba import njit

from drill_sim_ros import topics
from drill_sim_ros.model import kernel as k
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
from drill_sim_ros.ros.rcl_publish import (
    addresses,
    rcl_publish_serialized,
    serialized_messages,
    take_rcl_error,
)

_log = logging.getLogger(__name__)

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
        return self.payloads()

    def payloads(self) -> list[bytes]:
        """The payloads of the sample packed or published last."""
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


class PublishError(RuntimeError):
    """rcl refused a payload (the context was shut down, or the publisher is gone)."""


class FramePublisher:
    """Fills and publishes the samples of a :class:`SampleFrame` in one compiled call.

    ``publishers`` are rclpy publishers of ``frame.topics``, in that order; they must outlive
    every :meth:`publish`. Where rcl's C call cannot be bound (another rcl build), each
    payload goes through the publisher's own binding instead, with the same bytes.
    """

    def __init__(self, frame: SampleFrame, publishers: Sequence[Any]) -> None:
        if len(publishers) != len(frame.topics):
            raise ValueError(f"{len(publishers)} publishers for {len(frame.topics)} topics")
        self.frame = frame
        try:
            self._c_publish: Callable[[int, int, int], int] | None = rcl_publish_serialized()
        except (OSError, AttributeError) as exc:
            _log.warning("publishing through rclpy: cannot bind rcl's C call (%s)", exc)
            self._c_publish = None
        self._raw = [publisher.handle.publish_raw for publisher in publishers]
        self._handles = np.array([publisher.handle.pointer for publisher in publishers],
                                 dtype=np.uint64)
        self._structs = serialized_messages(frame._buffer, frame._slices)
        self._messages = addresses(self._structs)
        # load the compiled loop now, not on the first tick
        self.publish(np.zeros((1, k.N_COLS)), 0, 0, (0.0, 0.0), 0, 0, 0.0)

    @property
    def compiled(self) -> bool:
        return self._c_publish is not None

    def publish(self, samples: np.ndarray, first: int, count: int,
                offsets: tuple[float, float], time_ns: int, period_ns: int,
                submerged_weight_n: float) -> None:
        """Publish kernel samples ``first .. first + count - 1``, the first stamped
        ``time_ns`` and each next one ``period_ns`` later (as :meth:`SampleFrame.pack`)."""
        frame = self.frame
        if self._c_publish is None:
            for i in range(count):
                payloads = frame.pack(samples, first + i, offsets, time_ns + i * period_ns,
                                      submerged_weight_n)
                for publish, payload in zip(self._raw, payloads, strict=True):
                    publish(payload)
            return
        _, topic, ret = _fill_and_publish(samples, first, count, offsets[0], offsets[1],
                                          time_ns, period_ns, submerged_weight_n,
                                          *self.compiled_args())
        if topic >= 0:
            self.fail(topic, ret)

    def compiled_args(self) -> tuple[Any, ...]:
        """The arguments of :func:`_fill_and_publish` after the submerged weight."""
        frame = self.frame
        return (frame._factors, frame.row, frame._buffer, frame._plan, self._c_publish,
                self._handles, self._messages)

    def fail(self, topic: int, ret: int) -> None:
        """Raise the PublishError of rcl's ``ret`` on topic number ``topic``."""
        raise PublishError(f"publishing on {self.frame.topics[topic]} failed: "
                           f"{take_rcl_error(ret)}")


@njit(cache=True)
def _fill_and_publish(samples: np.ndarray, first: int, count: int, depth_offset: float,
                      angle_offset: float, time_ns: int, period_ns: int,
                      submerged_weight_n: float, factors: np.ndarray, row: np.ndarray,
                      buffer: np.ndarray, plan: np.ndarray, publish: Any, handles: np.ndarray,
                      messages: np.ndarray) -> tuple[int, int, int]:
    """:func:`_fill` then rcl_publish_serialized_message of every payload, for ``count``
    samples: (samples published, index of the topic that failed or -1, its rcl_ret_t)."""
    for i in range(count):
        _fill(samples, first + i, depth_offset, angle_offset, time_ns + i * period_ns,
              submerged_weight_n, factors, row, buffer, plan)
        for j in range(handles.shape[0]):
            ret = publish(handles[j], messages[j], 0)
            if ret != 0:
                return i, j, ret
    return count, -1, 0
