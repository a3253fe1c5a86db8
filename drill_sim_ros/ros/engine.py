"""sim_node's tick loop, compiled: wait for the deadline, step, fill and publish, in one call.

A 10 ms tick costs little work, but on a 2-core VM every trip through the interpreter after a
sleep runs on cold caches: the Python glue around the kernel (lock, pacing, dispatch, the
publish loop) cost about a third of the node's CPU. :func:`_run` keeps the whole real-time
loop in compiled code with the GIL released: it waits for each deadline in ``ppoll`` on the
ticker's eventfd, steps the kernel (:mod:`drill_sim_ros.model.kernel`), and fills and
publishes every payload through rcl (:class:`~drill_sim_ros.ros.frame.FramePublisher`). It
returns to Python only when Python has work to do:

- the eventfd was written: a callback waits for the node's lock (:class:`~drill_sim_ros.ros.
  ticker.HandoffLock` wakes the ticker; ``requests[0] != 0``), or the schedule changed, or
  the ticker stops. The callback then runs in the slack before the deadline, not after it;
- the sample budget is spent (the next severity snapshot, rebase check or recorded sample);
- the next deadline is further away than ``short_wait_ns`` (the ticker then waits on its
  eventfd, which a wake() cuts short);
- the kernel failed, or rcl refused a payload.

The schedule is the :class:`~drill_sim_ros.ros.pacing.Pacer`'s own arrays, kept with the same
compiled functions, so the pacing, overrun and lateness rules are those of pacing.py.
"""

from __future__ import annotations

import ctypes
from collections.abc import Callable
from typing import Any

import numpy as np
from numba import njit

from drill_sim_ros.model.kernel import STATUS_OK, advance
from drill_sim_ros.ros.frame import FramePublisher, _fill_and_publish
from drill_sim_ros.ros.pacing import Pacer, complete, deadline, due
from drill_sim_ros.ros.session import SimSession

# why _run returned (EXIT_WAKE: the eventfd was written, or a lock request is pending)
EXIT_BUDGET, EXIT_WAKE, EXIT_WAIT, EXIT_FAULT, EXIT_PUBLISH = range(5)
# result: exit reason, samples advanced, kernel steps taken, kernel status, failed topic
# (-1: none) and its rcl_ret_t
R_EXIT, R_SAMPLES, R_STEPS, R_STATUS, R_TOPIC, R_RCL = range(6)
CLOCK_MONOTONIC = 1                        # <time.h> on Linux
POLLIN = 1
NS_PER_S = 1_000_000_000
_NO_PACE, _NO_RING = np.zeros(5, dtype=np.int64), np.zeros(1, dtype=np.int64)


def libc_calls() -> tuple[Callable[..., int], ...]:
    """``clock_gettime``, ``ppoll`` and ``read`` of the C library, taking integer addresses.
    Raises OSError or AttributeError where there are none (not Linux)."""
    libc = ctypes.CDLL(None)
    word = ctypes.c_size_t
    calls = []
    for name, argtypes, restype in (("clock_gettime", [ctypes.c_int, word], ctypes.c_int),
                                    ("ppoll", [word, word, word, word], ctypes.c_int),
                                    ("read", [ctypes.c_int, word, word], ctypes.c_ssize_t)):
        function = getattr(libc, name)
        function.argtypes, function.restype = argtypes, restype
        calls.append(function)
    return tuple(calls)


class TickLoop:
    """Runs :func:`_run` for a session, a frame publisher and the node's lock requests."""

    def __init__(self, requests: np.ndarray, wake_fd: int, catch_up: int, batch: int,
                 short_wait_ns: int) -> None:
        self._requests = requests
        self._catch_up, self._batch, self._short_wait_ns = catch_up, batch, short_wait_ns
        self._libc = libc_calls()
        # scratch for the C calls: struct timespec (64-bit Linux), struct pollfd {int fd;
        # short events, revents}, an 8-byte eventfd counter
        self._scratch = np.zeros(4, dtype=np.int64)
        self._scratch.view(np.int32)[4] = wake_fd
        self.result = np.zeros(6, dtype=np.int64)

    def run(self, session: SimSession, publisher: FramePublisher, pacer: Pacer | None,
            max_samples: int, submerged_weight_n: float) -> int:
        """Advance and publish up to ``max_samples`` periods, paced by ``pacer`` (None: as
        fast as possible); returns the ``EXIT_*`` reason. Raises NumericalFault when the
        kernel fails and PublishError when rcl refuses a payload."""
        sim, steps = session.sim, session.steps
        budget = min(max_samples, session.samples_to_snapshot(), sim.open_run(steps) // steps)
        session.reserve(max(self._catch_up, self._batch))
        first_ns = session.sim_time_ns
        offsets = sim.offsets
        pace, ring = (_NO_PACE, _NO_RING) if pacer is None else (pacer.state, pacer.ring)
        r = self.result
        _run(self._requests, pace, ring, pacer is None, self._catch_up, self._batch,
             self._short_wait_ns, budget, *self._libc, self._scratch,
             *sim.kernel_arrays(), sim.exact, session.samples, steps, offsets[0], offsets[1],
             first_ns, session.period_ns, submerged_weight_n, *publisher.compiled_args(), r)
        session.advanced(int(r[R_SAMPLES]))
        sim.close_run(int(r[R_STEPS]), int(r[R_STATUS]))     # raises after a kernel fault
        if r[R_EXIT] == EXIT_PUBLISH:
            publisher.fail(int(r[R_TOPIC]), int(r[R_RCL]))
        return int(r[R_EXIT])


@njit(cache=True, nogil=True)
def _now_ns(gettime: Any, scratch: np.ndarray) -> int:
    gettime(CLOCK_MONOTONIC, scratch.ctypes.data)
    return scratch[0] * NS_PER_S + scratch[1]


@njit(cache=True, nogil=True)
def _wait(ppoll: Any, read: Any, scratch: np.ndarray, wait_ns: int) -> bool:
    """Wait up to ``wait_ns`` for the eventfd of ``scratch``; True when it was written (its
    count is then read, so that it is not seen twice). A signal ends the wait early."""
    scratch[0] = wait_ns // NS_PER_S
    scratch[1] = wait_ns % NS_PER_S
    words = scratch.view(np.int32)
    words[5] = POLLIN                          # events; the kernel sets revents above it
    base = scratch.ctypes.data
    if ppoll(base + 16, 1, base, 0) <= 0:      # timed out (0) or interrupted (-1)
        return False
    read(words[4], base + 24, 8)
    return True


@njit(cache=True, nogil=True)
def _run(requests: np.ndarray, pace: np.ndarray, ring: np.ndarray, free_run: bool,
         catch_up: int, batch: int, short_wait_ns: int, max_samples: int, gettime: Any,
         ppoll: Any, read: Any, scratch: np.ndarray, st: np.ndarray, prm: np.ndarray,
         tgt: np.ndarray, profile: np.ndarray, hist: np.ndarray, meta: np.ndarray, acc: np.ndarray,
         exact: bool, samples: np.ndarray, steps: int, depth_offset: float,
         angle_offset: float, first_ns: int, period_ns: int, submerged_weight_n: float,
         factors: np.ndarray, row: np.ndarray, buffer: np.ndarray, plan: np.ndarray,
         publish: Any, handles: np.ndarray, messages: np.ndarray, result: np.ndarray) -> None:
    """The tick loop (see the module docstring); what happened goes into ``result``."""
    result[:] = 0
    result[R_TOPIC] = -1
    advanced = 0
    while advanced < max_samples:
        if requests[0] != 0:
            result[R_EXIT] = EXIT_WAKE
            return
        count = min(batch if free_run else catch_up, max_samples - advanced)
        if not free_run:
            now_ns = _now_ns(gettime, scratch)
            count = due(pace, now_ns, count)
            if count <= 0:
                wait_ns = deadline(pace) - now_ns
                if wait_ns > short_wait_ns:
                    result[R_EXIT] = EXIT_WAIT
                    return
                if _wait(ppoll, read, scratch, wait_ns):
                    result[R_EXIT] = EXIT_WAKE
                    return
                continue
        status, written = advance(st, prm, tgt, profile, hist, meta, acc, samples,
                                   count * steps, steps, exact)
        result[R_STEPS] += count * steps
        if status != STATUS_OK:
            result[R_STATUS] = status
            result[R_EXIT] = EXIT_FAULT
            return
        _, topic, ret = _fill_and_publish(
            samples, 0, written, depth_offset, angle_offset, first_ns + advanced * period_ns,
            period_ns, submerged_weight_n, factors, row, buffer, plan, publish, handles,
            messages)
        advanced += written              # a failed publish still spends the samples
        result[R_SAMPLES] = advanced
        if topic >= 0:
            result[R_TOPIC], result[R_RCL], result[R_EXIT] = topic, ret, EXIT_PUBLISH
            return
        if not free_run:
            complete(pace, ring, written, _now_ns(gettime, scratch))
    result[R_EXIT] = EXIT_BUDGET
