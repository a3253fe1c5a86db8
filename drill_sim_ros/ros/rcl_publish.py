"""rcl's C call for publishing serialized messages, for compiled code (ctypes, no rclpy API).

On a 10 ms tick of a 2-core VM the caches are cold, and each trip through the interpreter and
rclpy's binding costs tens of microseconds per message. :func:`rcl_publish_serialized` binds
``rcl_publish_serialized_message`` of the librcl that rclpy has loaded, so that a numba
function can publish a whole sample (ten payloads) without returning to Python;
:func:`serialized_messages` lays out the ``rcl_serialized_message_t`` structs it takes.

The C arguments are declared as ``size_t``: on the platforms numba targets a pointer is passed
like an unsigned word, and numba then takes plain integers (``Publisher.handle.pointer`` is
the address of the ``rcl_publisher_t``). The caller keeps every publisher alive while it
publishes: sim_node stops its ticker before it destroys them.
"""

from __future__ import annotations

import ctypes
from collections.abc import Callable

import numpy as np

RCL_LIBRARY = "librcl.so"
# rcl/types.h: what rcl_publish_serialized_message returns
RCL_RET_NAMES = {0: "RCL_RET_OK", 1: "RCL_RET_ERROR", 10: "RCL_RET_BAD_ALLOC",
                 11: "RCL_RET_INVALID_ARGUMENT", 300: "RCL_RET_PUBLISHER_INVALID"}
# rcutils_uint8_array_t (= rcl_serialized_message_t): buffer, buffer_length, buffer_capacity,
# then an rcutils_allocator_t of five words, which publishing does not use.
MESSAGE_WORDS = 8
_BUFFER, _LENGTH, _CAPACITY = 0, 1, 2


def rcl_publish_serialized() -> Callable[[int, int, int], int]:
    """``rcl_publish_serialized_message(publisher, message, allocation)`` of the loaded rcl.

    Import rclpy first: the library is then found by its soname among the loaded ones, so
    this is rclpy's own copy. Raises OSError or AttributeError when it cannot be bound.
    """
    import rclpy.impl.implementation_singleton  # noqa: F401  (loads librcl)
    function = ctypes.CDLL(RCL_LIBRARY).rcl_publish_serialized_message
    function.argtypes = [ctypes.c_size_t, ctypes.c_size_t, ctypes.c_size_t]
    function.restype = ctypes.c_int32
    return function


def serialized_messages(buffer: np.ndarray, spans: list[slice]) -> np.ndarray:
    """One ``rcl_serialized_message_t`` per byte span of ``buffer`` (rows of uint64 words).

    The structs point into ``buffer``: keep it alive, and in place, while they are used.
    """
    if not buffer.flags.c_contiguous:
        raise ValueError("the payload buffer must be C-contiguous")
    structs = np.zeros((len(spans), MESSAGE_WORDS), dtype=np.uint64)
    base, size = buffer.ctypes.data, buffer.nbytes
    for row, span in zip(structs, spans, strict=True):
        if not 0 <= span.start < span.stop <= size:
            raise ValueError(f"payload span {span} lies outside the {size}-byte buffer")
        row[_BUFFER] = base + span.start
        row[_LENGTH] = row[_CAPACITY] = span.stop - span.start
    return structs


def addresses(structs: np.ndarray) -> np.ndarray:
    """The address of each row of ``structs`` (what the C call takes)."""
    return structs.ctypes.data + structs.strides[0] * np.arange(len(structs), dtype=np.uint64)


class _ErrorString(ctypes.Structure):
    _fields_ = [("text", ctypes.c_char * 1024)]   # rcutils_error_string_t


def take_rcl_error(ret: int) -> str:
    """The name of ``ret`` and rcl's error message of this thread, which is then cleared (as
    rclpy does), so that later rcl calls do not warn about overwriting it."""
    rcutils = ctypes.CDLL("librcutils.so")
    rcutils.rcutils_get_error_string.restype = _ErrorString
    text = rcutils.rcutils_get_error_string().text.decode(errors="replace")
    rcutils.rcutils_reset_error()
    name = RCL_RET_NAMES.get(ret, f"rcl_ret_t {ret}")
    return f"{name}: {text}" if text else name
