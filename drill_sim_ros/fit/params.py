"""The preset parameters a fit adjusts, by dotted path, with their bounds.

``--fit`` names them, comma-separated, each optionally with its bounds:
``well.side_friction.static`` or ``well.side_friction.static=0.2:1.5``. A path reaches a
number of the preset file (``string.torsional_damping_per_s``,
``physical.friction_weakening.floor_ratio``); a path the preset does not hold is refused.
Without bounds a parameter takes its row of :data:`DEFAULT_BOUNDS`, or, for a path not
there, [initial / 4, initial x 4].
"""

from __future__ import annotations

import copy
from dataclasses import dataclass
from typing import Any

from drill_sim_ros.model.errors import DrillSimError

# Default bounds, (low, high), wide enough for a rig's unknowns:
DEFAULT_BOUNDS: dict[str, tuple[float, float]] = {
    # Coulomb coefficients of the wall: 0.05-1.5 (Aarsnes & Shor 2018 fitted 0.425-0.885)
    "well.side_friction.static": (0.05, 1.5),
    "well.side_friction.dynamic": (0.05, 1.5),
    # the speed band the static coefficient holds in, rad/s (theirs: 0.9)
    "well.side_friction.stick_speed_rad_s": (0.05, 5.0),
    # viscous string losses, 1/s (Aarsnes & van de Wouw 2019: 0.42 on this string)
    "string.torsional_damping_per_s": (0.01, 3.0),
    "string.axial_damping_per_s": (0.01, 3.0),
    # the bit law's weakening (model/bit_rock.py FrictionWeakening)
    "physical.friction_weakening.floor_ratio": (0.05, 1.0),
    "physical.friction_weakening.speed_rad_s": (0.1, 50.0),
}
FALLBACK_FACTOR = 4.0


@dataclass(frozen=True)
class FitParameter:
    """One fitted number: its dotted ``path`` in the preset, its value there and bounds."""

    path: str
    initial: float
    low: float
    high: float


def get_path(data: dict[str, Any], path: str) -> Any:
    """The value at dotted ``path`` of a preset mapping; DrillSimError naming it if absent."""
    node: Any = data
    for key in path.split("."):
        if not isinstance(node, dict) or key not in node:
            raise DrillSimError(f"--fit {path}: the preset has no {key!r} there")
        node = node[key]
    return node


def with_values(data: dict[str, Any], values: dict[str, float]) -> dict[str, Any]:
    """A copy of the preset mapping with each dotted path set to its value."""
    out = copy.deepcopy(data)
    for path, value in values.items():
        *parents, last = path.split(".")
        node = out
        for key in parents:
            node = node[key]
        node[last] = float(value)
    return out


def parse_fit(text: str, data: dict[str, Any]) -> list[FitParameter]:
    """The ``--fit`` list against the preset mapping ``data`` (module doc)."""
    params: list[FitParameter] = []
    for item in (part.strip() for part in text.split(",")):
        if not item:
            continue
        path, _, bounds = item.partition("=")
        value = get_path(data, path)
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise DrillSimError(f"--fit {path}: the preset's value {value!r} is not a number")
        low, high = _bounds(path, float(value), bounds)
        if not low <= float(value) <= high:
            raise DrillSimError(f"--fit {path}: the preset's value {value:g} lies outside its "
                                f"bounds [{low:g}, {high:g}]; give bounds with {path}=LOW:HIGH")
        params.append(FitParameter(path, float(value), low, high))
    if not params:
        raise DrillSimError("--fit needs at least one preset path, e.g. "
                            "well.side_friction.static")
    if len({p.path for p in params}) != len(params):
        raise DrillSimError(f"--fit {text!r} names a parameter twice")
    return params


def parse_span(text: str, malformed: str, unordered: str) -> tuple[float, float]:
    """``A:B`` as two numbers with A < B (bounds, a window), or DrillSimError with the
    caller's one-line ``malformed`` or ``unordered`` message."""
    try:
        low, high = (float(x) for x in text.split(":"))
    except ValueError:
        raise DrillSimError(malformed) from None
    if not low < high:
        raise DrillSimError(unordered)
    return low, high


def _bounds(path: str, value: float, text: str) -> tuple[float, float]:
    if text:
        return parse_span(text, f"--fit {path}={text}: bounds are LOW:HIGH numbers",
                          f"--fit {path}={text}: LOW must be below HIGH")
    if path in DEFAULT_BOUNDS:
        return DEFAULT_BOUNDS[path]
    if value <= 0.0:
        raise DrillSimError(f"--fit {path}: no default bounds for a value of {value:g}; give "
                            f"them as {path}=LOW:HIGH")
    return value / FALLBACK_FACTOR, value * FALLBACK_FACTOR
