"""``drill_sim params``: every sim_node parameter from the one table
(:data:`drill_sim_ros.ros.parameters.SPECS`) with its type, unit, range, default and whether
it may change at runtime: what ``ros2 param describe /drill_sim <name>`` shows where the
``ros2`` command exists (not in a venv built from PyPI wheels).
"""

from __future__ import annotations

import argparse
import json
import math
import re
from typing import Any

from drill_sim_ros.model.presets import DEFAULT_PRESET, load_preset
from drill_sim_ros.ros.parameters import BOOL, INTEGER, SPECS, STRING, ParamSpec

_BRACKETED_UNIT = re.compile(r"\[([^\]]+)\]")
COLUMNS = ("name", "type", "unit", "range", "default", "runtime")


def unit_of(spec: ParamSpec) -> str:
    """The spec's unit: its own, else the first ``[unit]`` of its description ('' if none)."""
    if spec.unit is not None:
        return spec.unit
    found = _BRACKETED_UNIT.search(spec.description)
    return found.group(1) if found else ""


def range_of(spec: ParamSpec) -> str:
    """``[low, high]``, the choices of a string, or '' (any value of its type)."""
    if spec.choices:
        return " | ".join(spec.choices)
    if spec.kind in (BOOL, STRING) or spec.low is None:
        return ""
    if spec.kind == INTEGER:
        return f"[{int(spec.low)}, {int(spec.high)}]"
    return f"[{spec.low:g}, {spec.high:g}]"


def _shown(value: Any) -> Any:
    if isinstance(value, float) and math.isinf(value):
        return "inf"
    return value


def parameter_rows(preset_name: str = DEFAULT_PRESET) -> list[dict[str, Any]]:
    """One dict per parameter (keys :data:`COLUMNS` and ``description``), defaults from
    the preset ``preset_name`` as sim_node would take them; ``runtime``: yes if ``ros2 param
    set`` may change it while the node runs."""
    preset = load_preset(preset_name)
    rows = []
    for spec in SPECS:
        default = preset_name if spec.name == "model.preset" else spec.default_for(preset)
        rows.append({"name": spec.name, "type": spec.kind, "unit": unit_of(spec),
                     "range": range_of(spec), "default": _shown(default),
                     "runtime": "no" if spec.read_only else "yes",
                     "description": spec.description})
    return rows


def format_rows(rows: list[dict[str, Any]]) -> str:
    """A plain-text table of :func:`parameter_rows`, then each description."""
    cells = [[str(row[c]) if not isinstance(row[c], float) else f"{row[c]:.6g}"
              for c in COLUMNS] for row in rows]
    widths = [max(len(c), *(len(r[i]) for r in cells)) for i, c in enumerate(COLUMNS)]
    lines = ["  ".join(c.ljust(w) for c, w in zip(COLUMNS, widths, strict=True)).rstrip()]
    lines += ["  ".join(v.ljust(w) for v, w in zip(r, widths, strict=True)).rstrip()
              for r in cells]
    lines += ["", *[f"{row['name']}: {row['description']}" for row in rows]]
    return "\n".join(lines)


def run(args: argparse.Namespace) -> int:
    rows = parameter_rows(args.preset)
    print(json.dumps(rows, indent=1) if args.json else format_rows(rows))
    return 0
