"""Controllers that fail in each way a user's controller can (for the isolation tests)."""

from __future__ import annotations

import math
import os
import time

from drill_sim_ros.control.command import Command, SurfaceMeasurement

FAIL_AT_S = 0.5     # simulated time of the first wrong answer


class _Base:
    """The bare protocol; ``answer(m)`` is the command once ``m.time_s`` >= FAIL_AT_S."""

    def __init__(self, **_: object) -> None:
        pass

    def reset(self) -> None:
        pass

    def update(self, m: SurfaceMeasurement | None) -> object:
        if m is None or m.time_s < FAIL_AT_S:
            return Command(speed_rad_s=6.0)
        return self.answer(m)

    def answer(self, m: SurfaceMeasurement) -> object:
        return Command(speed_rad_s=6.0)


class RaisesInInit(_Base):
    def __init__(self, **_: object) -> None:
        raise RuntimeError("no gain for you")


class RaisesInStep(_Base):
    def answer(self, m: SurfaceMeasurement) -> object:
        raise ValueError("step exploded")


class ReturnsNone(_Base):
    def answer(self, m: SurfaceMeasurement) -> object:
        return None


class ReturnsFloat(_Base):
    def answer(self, m: SurfaceMeasurement) -> object:
        return 6.0


class ReturnsString(_Base):
    def answer(self, m: SurfaceMeasurement) -> object:
        return "fast please"


class ReturnsNaN(_Base):
    def answer(self, m: SurfaceMeasurement) -> object:
        return Command(speed_rad_s=math.nan)


class ReturnsHuge(_Base):
    """A finite command far beyond the drive's limit: clamped, not refused."""

    def answer(self, m: SurfaceMeasurement) -> object:
        return Command(speed_rad_s=1e308)


class Slow(_Base):
    """Its first step takes 0.25 s of wall time, the rest are quick."""

    def __init__(self, **_: object) -> None:
        self.slept = False

    def answer(self, m: SurfaceMeasurement) -> object:
        if not self.slept:
            self.slept = True
            time.sleep(0.25)
        return Command(speed_rad_s=6.0)


class Stalls(_Base):
    """Blocks from FAIL_AT_S on (until interrupted); touches STALL_FLAG first."""

    def answer(self, m: SurfaceMeasurement) -> object:
        flag = os.environ.get("STALL_FLAG")
        if flag:
            open(flag, "w").close()
        time.sleep(3600)
        return Command(speed_rad_s=6.0)
