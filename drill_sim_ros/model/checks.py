"""The small checks that every reader of user input shares: known keys, numbers, blade counts.

ROS-free and below every reader (a preset file, a formation layer, a scenario, a map's axes):
each error is one :class:`ParameterError` line naming the place, the value and what is allowed.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from typing import Any

from drill_sim_ros.model.errors import ParameterError


def as_number(value: Any) -> float | int | None:
    """``value`` as a number; YAML 1.1 reads ``79.3e9`` (no dot, no exponent sign) as a
    string, so a string that is a number counts as one (``abc`` does not)."""
    if isinstance(value, bool):
        return None
    if isinstance(value, (int, float)):
        return value
    if isinstance(value, str):
        try:
            return float(value)
        except ValueError:
            return None
    return None


def check_blade_counts(values: Iterable[float], where: str) -> None:
    """Every value of n a whole number: n counts the blades and is never rounded."""
    for value in values:
        if not float(value).is_integer():
            raise ParameterError(f"{where}: n = {value:g} is not a whole number (n counts the "
                                 "blades; it is never rounded)")


def check_known_keys(values: dict[Any, Any], known: tuple[str, ...], where: str = "") -> None:
    """ParameterError naming the keys of ``values`` that are not ``known`` (and the known)."""
    unknown = sorted(str(k) for k in set(values) - set(known))
    if unknown:
        place = f" in '{where}'" if where else ""
        raise ParameterError(f"unknown key(s) {', '.join(unknown)}{place}; known: "
                             f"{', '.join(known)}")


def number_in(label: str, value: Any, low: float, high: float, low_open: bool = False) -> float:
    """``value`` as a float in [low, high] ((low, high] with ``low_open``), or one
    ParameterError line: ``<label> = <value> must be a number in [low, high]`` (``label`` as
    the reader names the input: ``'well.survey[0].md_m'``, ``--rpm``)."""
    number = as_number(value)
    x = math.nan if number is None else float(number)
    if not (math.isfinite(x) and (x > low if low_open else x >= low) and x <= high):
        bracket = "(" if low_open else "["
        raise ParameterError(f"{label} = {value!r} must be a number in {bracket}{low:g}, "
                             f"{high:g}]")
    return x
