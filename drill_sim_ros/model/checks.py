"""The small checks that every reader of user input shares: known keys, numbers, blade counts.

ROS-free and below every reader (a preset file, a formation layer, a scenario, a map's axes):
each error is one :class:`ParameterError` line naming the place, the value and what is allowed.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from typing import Any

from drill_sim_ros.model.errors import ParameterError


def as_number(value: Any) -> float | None:
    """``value`` as a float, the one number parser of every input path; None if it is no
    number (``abc``, ``true``, a list). YAML 1.1 reads ``79.3e9``, ``6.0e4`` and ``1e1`` (no
    dot or no exponent sign) as strings, so a string that is a number counts as one. An
    integer beyond a double (``10**400``) is +-inf, which the callers' finiteness check
    names, instead of Python's OverflowError."""
    if isinstance(value, bool):
        return None
    if isinstance(value, int):
        try:
            return float(value)
        except OverflowError:
            return math.inf if value > 0 else -math.inf
    if isinstance(value, float):
        return value
    if isinstance(value, str):
        try:
            return float(value)
        except ValueError:
            return None
    return None


def shown(value: Any) -> str:
    """``value`` as an error line shows it: its repr, but an integer too long to read (one
    beyond a double has over 300 digits) as its order of magnitude."""
    if isinstance(value, int) and not isinstance(value, bool) and abs(value) >= 10**30:
        sign = "-" if value < 0 else ""
        return f"{sign}~1e{len(str(abs(value))) - 1} (an integer of {len(str(abs(value)))} digits)"
    return repr(value)


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
        raise ParameterError(f"{label} = {shown(value)} must be a number in {bracket}{low:g}, "
                             f"{high:g}]")
    return x
