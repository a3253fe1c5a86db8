"""Fixed-layout CDR templates: the bytes of a message whose size never changes, written once
with zeroed alignment padding, and the byte offsets where each sample's values go.

rclpy publishes ``bytes`` without converting or serializing a message object, which saves a
large part of the CPU a small message costs. Only the layouts sim_node publishes are here;
:mod:`drill_sim_ros.ros.frame` patches the values in, and tests check the result against
rclpy's own serializer (tests/ros/test_frame.py).
"""

from __future__ import annotations

import struct
from dataclasses import dataclass

CDR_HEADER = b"\x00\x01\x00\x00"     # encapsulation: plain CDR, little endian


@dataclass(frozen=True)
class Layout:
    """A message's CDR bytes with zeroed values, and where its values go (payload offsets).

    ``doubles``: offsets of the float64 values, in the order the message lists them;
    ``stamp``: offset of a builtin_interfaces/Time (int32 sec, uint32 nanosec) or None;
    ``byte``: offset of a uint8 value or None.
    """

    template: bytes
    doubles: tuple[int, ...] = ()
    stamp: int | None = None
    byte: int | None = None


class CdrBuffer:
    """Plain little-endian CDR, written field by field with zeroed alignment padding.

    Only what the layouts below need; alignment counts from the end of the 4-byte
    encapsulation header, as in rclpy's (Fast-CDR's) serialization. Writers return the
    payload offset of what they wrote.
    """

    def __init__(self) -> None:
        self.data = bytearray(CDR_HEADER)

    def _align(self, size: int) -> None:
        self.data += bytes(-(len(self.data) - len(CDR_HEADER)) % size)

    def uint32(self, value: int) -> int:
        self._align(4)
        self.data += struct.pack("<I", value)
        return len(self.data) - 4

    def uint8(self) -> int:
        self.data += b"\x00"
        return len(self.data) - 1

    def stamp(self) -> int:
        """builtin_interfaces/Time zero (int32 sec, uint32 nanosec)."""
        at = self.uint32(0)
        self.uint32(0)
        return at

    def string(self, text: str) -> None:
        raw = text.encode() + b"\x00"
        self.uint32(len(raw))
        self.data += raw

    def doubles(self, count: int, sequence: bool = True) -> tuple[int, ...]:
        """``count`` zero float64 values (a sequence: length first)."""
        if sequence:
            self.uint32(count)
        self._align(8)
        start = len(self.data)
        self.data += bytes(8 * count)
        return tuple(start + 8 * i for i in range(count))

    def layout(self, **slots: object) -> Layout:
        self._align(4)                  # rclpy pads a message to a multiple of 4 bytes
        return Layout(bytes(self.data), **slots)


def float64_layout() -> Layout:
    """std_msgs/Float64."""
    cdr = CdrBuffer()
    return cdr.layout(doubles=cdr.doubles(1, sequence=False))


def uint8_layout() -> Layout:
    """std_msgs/UInt8."""
    cdr = CdrBuffer()
    return cdr.layout(byte=cdr.uint8())


def clock_layout() -> Layout:
    """rosgraph_msgs/Clock."""
    cdr = CdrBuffer()
    return cdr.layout(stamp=cdr.stamp())


def joint_state_layout(names: tuple[str, ...], with_position: bool = True) -> Layout:
    """sensor_msgs/JointState with fixed joint names and an empty frame_id; the doubles are
    position (none without ``with_position``: an empty array), then velocity, then effort,
    one per joint."""
    cdr = CdrBuffer()
    at = cdr.stamp()
    cdr.string("")                             # header.frame_id
    cdr.uint32(len(names))
    for name in names:
        cdr.string(name)
    values: list[int] = []
    if with_position:
        values += cdr.doubles(len(names))
    else:
        cdr.uint32(0)                          # position: an empty array
    values += [offset for _ in range(2) for offset in cdr.doubles(len(names))]
    return cdr.layout(doubles=tuple(values), stamp=at)


def string_profile_layout(frame_id: str, depths: int) -> Layout:
    """drill_sim_msgs/StringProfile of ``depths`` depths; the doubles are depth_m, then
    speed_rad_s, then torque_nm, one per depth."""
    cdr = CdrBuffer()
    at = cdr.stamp()
    cdr.string(frame_id)
    values = [offset for _ in range(3) for offset in cdr.doubles(depths)]
    return cdr.layout(doubles=tuple(values), stamp=at)


def multi_array_layout(label: str, length: int) -> Layout:
    """std_msgs/Float64MultiArray of one dimension (size = stride = length) of ``length``
    values."""
    cdr = CdrBuffer()
    cdr.uint32(1)                               # layout.dim: one MultiArrayDimension
    cdr.string(label)
    cdr.uint32(length)
    cdr.uint32(length)
    cdr.uint32(0)                               # layout.data_offset
    return cdr.layout(doubles=cdr.doubles(length))
