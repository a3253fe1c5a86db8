"""The small checks that every reader of user input shares: known keys, numbers, blade counts.

ROS-free and below every reader (a preset file, a formation layer, a scenario, a map's axes):
each error is one :class:`ParameterError` line naming the place, the value and what is allowed.
"""

from __future__ import annotations

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
