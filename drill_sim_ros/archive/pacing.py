"""Drift-free pacing of a replay on the monotonic clock.

Every message has an absolute target ``start + (log_time - first_log_time) / rate``; waiting
for that target (rather than sleeping each log-time gap) keeps errors from accumulating, and
after a stall the replay catches up instead of shifting everything later.
"""

from __future__ import annotations

import time
from collections.abc import Callable

# Sleep in slices no longer than this, so a shutdown request is noticed promptly.
MAX_SLEEP_S = 0.1


class Pacer:
    """Maps log times (ns) to monotonic wall targets at ``rate`` x real time."""

    def __init__(self, first_log_ns: int, rate: float) -> None:
        if not rate > 0:
            raise ValueError(f"rate must be positive, got {rate}")
        self.first_log_ns = first_log_ns
        self.rate = rate
        self.start_s = time.monotonic()

    def restart(self) -> None:
        self.start_s = time.monotonic()

    def target_s(self, log_time_ns: int) -> float:
        return self.start_s + (log_time_ns - self.first_log_ns) * 1e-9 / self.rate

    def wait_until(self, log_time_ns: int, keep_going: Callable[[], bool]) -> bool:
        """Sleep until the message's target; False if ``keep_going`` turned False meanwhile."""
        target = self.target_s(log_time_ns)
        while (remaining := target - time.monotonic()) > 0:
            if not keep_going():
                return False
            time.sleep(min(remaining, MAX_SLEEP_S))
        return keep_going()
