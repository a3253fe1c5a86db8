"""Fixed-layout CDR templates: the bytes of a message whose size never changes, written once
with zeroed alignment padding, with the values of each sample patched in (``struct``).

rclpy publishes ``bytes`` without converting or serializing a message object, which saves a
large part of the CPU a small message costs. Only the layouts sim_node publishes are here;
tests check them against rclpy's own serializer (tests/ros/test_conversions.py).
"""

from __future__ import annotations

import struct

from std_msgs.msg import MultiArrayDimension

CDR_HEADER = b"\x00\x01\x00\x00"     # encapsulation: plain CDR, little endian
FLOAT64_CDR = struct.Struct("<4sd")    # std_msgs/Float64
UINT8_CDR = struct.Struct("<4sB3x")    # std_msgs/UInt8, padded to 4 bytes
CLOCK_CDR = struct.Struct("<4siI")     # rosgraph_msgs/Clock (builtin_interfaces/Time)
STAMP_CDR = struct.Struct("<iI")
PAIR_CDR = struct.Struct("<2d")
Pair = tuple[float, float]


class CdrBuffer:
    """Plain little-endian CDR, written field by field with zeroed alignment padding.

    Only what the fixed-layout templates below need; alignment counts from the end of the
    4-byte encapsulation header, as in rclpy's (Fast-CDR's) serialization.
    """

    def __init__(self) -> None:
        self.data = bytearray(CDR_HEADER)

    def _align(self, size: int) -> None:
        self.data += bytes(-(len(self.data) - len(CDR_HEADER)) % size)

    def uint32(self, value: int) -> int:
        """Append one uint32; returns its offset."""
        self._align(4)
        self.data += struct.pack("<I", value)
        return len(self.data) - 4

    def string(self, text: str) -> None:
        raw = text.encode() + b"\x00"
        self.uint32(len(raw))
        self.data += raw

    def doubles(self, count: int) -> int:
        """A sequence of ``count`` zeros; returns the offset of its first element."""
        self.uint32(count)
        self._align(8)
        self.data += bytes(8 * count)
        return len(self.data) - 8 * count


class JointStateFrame:
    """CDR bytes of a sensor_msgs/JointState with fixed joint names and an empty frame_id;
    the stamp and the two values of position, velocity and effort are patched in."""

    def __init__(self, names: tuple[str, ...]) -> None:
        cdr = CdrBuffer()
        self._stamp_at = cdr.uint32(0)           # header.stamp.sec, then .nanosec
        cdr.uint32(0)
        cdr.string("")                            # header.frame_id
        cdr.uint32(len(names))
        for name in names:
            cdr.string(name)
        self._position_at, self._velocity_at, self._effort_at = (
            cdr.doubles(len(names)) for _ in range(3))
        self._buffer = cdr.data

    def pack(self, sec: int, nanosec: int, position: Pair, velocity: Pair,
             effort: Pair) -> bytes:
        STAMP_CDR.pack_into(self._buffer, self._stamp_at, sec, nanosec)
        PAIR_CDR.pack_into(self._buffer, self._position_at, *position)
        PAIR_CDR.pack_into(self._buffer, self._velocity_at, *velocity)
        PAIR_CDR.pack_into(self._buffer, self._effort_at, *effort)
        return bytes(self._buffer)


class TelemetryFrame:
    """CDR bytes of a std_msgs/Float64MultiArray of one dimension and ``length`` values."""

    def __init__(self, dim: MultiArrayDimension, length: int) -> None:
        cdr = CdrBuffer()
        cdr.uint32(1)                             # layout.dim: one MultiArrayDimension
        cdr.string(dim.label)
        cdr.uint32(dim.size)
        cdr.uint32(dim.stride)
        cdr.uint32(0)                             # layout.data_offset
        self._row_at = cdr.doubles(length)
        self._row = struct.Struct(f"<{length}d")
        self._buffer = cdr.data

    def pack(self, row: list[float]) -> bytes:
        self._row.pack_into(self._buffer, self._row_at, *row)
        return bytes(self._buffer)
