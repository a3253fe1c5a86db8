"""The operator's setpoints over time: steps and ramps of surface rpm and WOB, and the
driller picking the bit up off bottom and tagging bottom again (ROS-free).

A schedule is a list of points ``{t_s, rpm, wob_n, ramp_s, off_bottom}``. From ``t_s`` on,
each value given moves to its new level, as a step (``ramp_s`` = 0) or linearly over
``ramp_s`` seconds; a value left out keeps its level. ``off_bottom: true`` picks the bit up
(the hook rises to the string's clearance), ``false`` tags bottom again (the hook's WOB loop
lowers it until the bit cuts); it is an action at ``t_s``, never ramped. The first point's
values are the starting levels (the preset's when left out; on bottom).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from drill_sim_ros.model.errors import ParameterError

KEYS = ("t_s", "rpm", "wob_n", "ramp_s", "off_bottom")


@dataclass(frozen=True)
class Change:
    """From ``t_s``, ``value`` is reached over ``ramp_s`` seconds (0: at once)."""

    t_s: float
    value: float
    ramp_s: float = 0.0


def _level(start: float, changes: tuple[Change, ...], t_s: float) -> float:
    value = start
    for change in changes:
        if t_s < change.t_s:
            break
        if change.ramp_s > 0.0 and t_s < change.t_s + change.ramp_s:
            return value + (change.value - value) * (t_s - change.t_s) / change.ramp_s
        value = change.value
    return value


@dataclass(frozen=True)
class Schedule:
    """Surface rpm (rev/min) and applied WOB (N) as functions of simulated time (s)."""

    rpm0: float
    wob0_n: float
    rpm_changes: tuple[Change, ...] = ()
    wob_changes: tuple[Change, ...] = ()
    off_bottom_changes: tuple[Change, ...] = ()      # value 1.0: picked up, 0.0: on bottom
    off_bottom0: bool = False

    def rpm_at(self, t_s: float) -> float:
        return _level(self.rpm0, self.rpm_changes, t_s)

    def wob_at(self, t_s: float) -> float:
        return _level(self.wob0_n, self.wob_changes, t_s)

    def off_bottom_at(self, t_s: float) -> bool:
        """Whether the driller has the bit picked up off bottom at ``t_s``."""
        return _level(float(self.off_bottom0), self.off_bottom_changes, t_s) == 1.0


def _number(point: dict[str, Any], key: str, low: float) -> float | None:
    if key not in point:
        return None
    value = point[key]
    if isinstance(value, bool) or not isinstance(value, (int, float)) or \
            not (math.isfinite(value) and value >= low):
        raise ParameterError(f"schedule: '{key}' = {value!r} must be a number >= {low:g}")
    return float(value)


def schedule_from_list(points: list[dict[str, Any]] | None, rpm0: float,
                       wob0_n: float) -> Schedule:
    """A :class:`Schedule` from scenario points, starting at ``rpm0`` and ``wob0_n``."""
    rpm_changes: list[Change] = []
    wob_changes: list[Change] = []
    lifts: list[Change] = []
    off0 = False
    last_t = -math.inf
    for point in points or []:
        if not isinstance(point, dict) or set(point) - set(KEYS):
            raise ParameterError(f"schedule: each point is a mapping of {list(KEYS)}, "
                                 f"got {point!r}")
        t_s = _number(point, "t_s", 0.0) or 0.0
        if t_s < last_t:
            raise ParameterError(f"schedule: t_s = {t_s:g} comes before {last_t:g}; "
                                 "points must be in time order")
        last_t = t_s
        ramp_s = _number(point, "ramp_s", 0.0) or 0.0
        rpm, wob = _number(point, "rpm", 0.0), _number(point, "wob_n", 0.0)
        lift = _flag(point, "off_bottom")
        if t_s == 0.0 and lift is not None:
            off0 = lift
        elif lift is not None:
            lifts.append(Change(t_s, float(lift)))
        if t_s == 0.0 and ramp_s == 0.0:
            rpm0, wob0_n = rpm if rpm is not None else rpm0, wob if wob is not None else wob0_n
            continue
        if rpm is not None:
            rpm_changes.append(Change(t_s, rpm, ramp_s))
        if wob is not None:
            wob_changes.append(Change(t_s, wob, ramp_s))
    return Schedule(rpm0, wob0_n, tuple(rpm_changes), tuple(wob_changes), tuple(lifts), off0)


def _flag(point: dict[str, Any], key: str) -> bool | None:
    if key not in point:
        return None
    if not isinstance(point[key], bool):
        raise ParameterError(f"schedule: '{key}' = {point[key]!r} must be true or false")
    return point[key]
