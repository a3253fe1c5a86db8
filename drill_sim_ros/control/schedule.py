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

from dataclasses import dataclass
from typing import Any

from drill_sim_ros.model.checks import number_in
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


# each value's range: sim_node's model.surface_rpm and model.applied_wob_n (the schedule
# moves them), times within any run (a run is at most 2e6 periods: scenario_check)
RANGES = {"t_s": (0.0, 1e9), "rpm": (0.0, 1e4), "wob_n": (0.0, 1e9), "ramp_s": (0.0, 1e9)}


def _number(i: int, point: dict[str, Any], key: str) -> float | None:
    """``schedule[i].key`` as a float in its range (checks.number_in: YAML 1.1's ``6.0e4``
    text counts as its number), None when the point does not give it."""
    if key not in point:
        return None
    return number_in(f"'schedule[{i}].{key}'", point[key], *RANGES[key])


def _point(i: int, point: Any) -> dict[str, Any]:
    """Point ``i`` checked: its keys, its numbers (as floats), a point that sets something,
    and no ``ramp_s`` where nothing ramps (``off_bottom`` is an action, never ramped)."""
    if not isinstance(point, dict) or set(point) - set(KEYS):
        raise ParameterError(f"'schedule[{i}]' must be a mapping of {', '.join(KEYS)}; got "
                             f"{point!r}")
    out: dict[str, Any] = {key: _number(i, point, key) for key in RANGES if key in point}
    if "off_bottom" in point:
        out["off_bottom"] = _flag(i, point)
    if not set(out) & {"rpm", "wob_n", "off_bottom"}:
        raise ParameterError(f"'schedule[{i}]' = {point!r} sets nothing (give rpm, wob_n or "
                             "off_bottom)")
    if "ramp_s" in out and not set(out) & {"rpm", "wob_n"}:
        raise ParameterError(f"'schedule[{i}].ramp_s' = {point['ramp_s']!r} has no effect: "
                             "the point has no rpm or wob_n to ramp (off_bottom is an action "
                             "at t_s, never ramped)")
    return out


def check_points(points: Any, duration_s: float | None = None) -> tuple[dict[str, Any], ...]:
    """The schedule's points checked (:func:`_point`), in time order and, with a
    ``duration_s``, each before the run's end (a later point never acts)."""
    if not isinstance(points, list):
        raise ParameterError(f"'schedule' = {points!r} must be a list of mappings, e.g. "
                             "[{t_s: 0, rpm: 60}]")
    checked = tuple(_point(i, p) for i, p in enumerate(points))
    times = [p.get("t_s") or 0.0 for p in checked]
    for i in range(1, len(times)):
        if times[i] < times[i - 1]:
            raise ParameterError(f"'schedule[{i}].t_s' = {times[i]:g} comes before "
                                 f"{times[i - 1]:g}; points must be in time order")
    late = late_points(checked, duration_s)
    if late:
        raise ParameterError(f"'schedule[{late[0]}].t_s' = {times[late[0]]:g} s is at or past "
                             f"the run's end (duration_s = {duration_s:g} s): it would never "
                             "act")
    return checked


def late_points(points: tuple[dict[str, Any], ...], duration_s: float | None) -> list[int]:
    """The indices of the points at or past ``duration_s`` (a point at 0 always acts)."""
    if duration_s is None:
        return []
    return [i for i, p in enumerate(points) if (p.get("t_s") or 0.0) > 0.0
            and p["t_s"] >= duration_s]


def schedule_from_list(points: list[dict[str, Any]] | None, rpm0: float,
                       wob0_n: float) -> Schedule:
    """A :class:`Schedule` from scenario points, starting at ``rpm0`` and ``wob0_n``."""
    rpm_changes: list[Change] = []
    wob_changes: list[Change] = []
    lifts: list[Change] = []
    off0 = False
    for point in check_points(list(points or [])):
        t_s, ramp_s = point.get("t_s") or 0.0, point.get("ramp_s") or 0.0
        rpm, wob, lift = point.get("rpm"), point.get("wob_n"), point.get("off_bottom")
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


def _flag(i: int, point: dict[str, Any]) -> bool:
    if not isinstance(point["off_bottom"], bool):
        raise ParameterError(f"'schedule[{i}].off_bottom' = {point['off_bottom']!r} must be "
                             "true or false")
    return point["off_bottom"]
