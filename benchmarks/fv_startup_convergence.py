"""``drill_sim startup`` against the independent finite-volume solver, and the solver's own
convergence (issue 50, point 2; prints figures, no asserts).

For each case of ``tests/model/fv_cases.py`` (or ``--case``): the solver
(``tests/model/fv_reference.py``) at each of ``--cells`` (default: half, once and twice the
case's cells) at the case's Courant number (or ``--courant``), and ``drill_sim startup
--json`` run as a user runs it; one markdown table per case, the figures in rows: the
solver's columns, the package's, and the package against the solver's ``--against`` cells
(default the case's) in % (stick fraction: the difference). ``--seconds`` overrides the
cases' run length (120: the issue's).

Usage: PYTHONPATH=. .venv/bin/python benchmarks/fv_startup_convergence.py [--case tangent]
       [--cells 1000 2000 4000] [--courant 0.9] [--seconds 120] [--against 2000]
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import yaml

from tests.model import fv_cases
from tests.model import fv_reference as fv

FIGURES = ("breakaway_s", "breakaway_turns", "breakaway_torque_nm", "first_slip_s",
           "peak_motor_torque_nm", "period_s", "stick_fraction")


def package_figures(preset: dict, rpm: float, ramp_s: float, seconds: float) -> dict:
    """``drill_sim startup --json`` on ``preset``, in a subprocess."""
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "case.yaml"
        path.write_text(yaml.safe_dump(preset))
        done = subprocess.run([sys.executable, "-m", "drill_sim_ros.cli", "startup",
                               "--params", str(path), "--rpm", str(rpm), "--ramp-s",
                               str(ramp_s), "--seconds", str(seconds), "--json"],
                              capture_output=True, text=True, check=True)
    return json.loads(done.stdout.strip().splitlines()[-1])


def cell(value: float | None, key: str) -> str:
    if value is None:
        return "–"
    if key.endswith("_nm"):
        return f"{value / 1e3:.2f} k"
    return f"{value:.3f}" if key in ("stick_fraction", "breakaway_turns") else f"{value:.2f}"


def against(ours: float | None, ref: float | None, key: str) -> str:
    if ours is None or ref is None:
        return "–" if ours is ref else "one only"
    if key == "stick_fraction":
        return f"{ours - ref:+.3f}"
    return f"{100.0 * (ours - ref) / ref:+.1f} %"


def table(name: str, seconds: float, cells: list[int] | None, courant: float | None,
          against_cells: int | None) -> str:
    make, rpm, ramp_s, default_s, case_cells, case_courant = fv_cases.CASES[name]
    seconds = seconds or default_s
    cells = cells or [case_cells // 2, case_cells, 2 * case_cells]
    courant = courant or case_courant
    against_cells = against_cells or case_cells
    preset = make()
    case = fv.case_from_preset(preset, fv_cases.package_has_bend_term())
    cutoff_hz = 2.0 * fv.torsional_modes_hz(case)[-1]
    columns, walls = {}, {}
    for n in cells:
        start = time.perf_counter()
        columns[n] = fv.startup_figures(fv.run_startup(case, rpm, ramp_s, seconds, n,
                                                       courant), cutoff_hz)
        walls[n] = time.perf_counter() - start
    start = time.perf_counter()
    package = package_figures(preset, rpm, ramp_s, seconds)
    package_s = time.perf_counter() - start
    against_cells = against_cells if against_cells in columns else cells[-1]
    ref = columns[against_cells]
    head = " | ".join(f"solver {n} cells" for n in cells)
    lines = [f"{name}: {rpm:g} rpm in {ramp_s:g} s, {seconds:g} s, bend term "
             f"{'on' if case.bend_term else 'off'}, Courant {courant:g} "
             f"(cut-off {cutoff_hz:.4f} Hz; package's {package['cutoff_hz']})",
             f"| figure | {head} | drill_sim startup | package vs {against_cells} cells |",
             "|---" * (len(cells) + 3) + "|"]
    for key in FIGURES:
        row = " | ".join(cell(columns[n][key], key) for n in cells)
        lines.append(f"| `{key}` | {row} | {cell(package[key], key)} | "
                     f"{against(package[key], ref[key], key)} |")
    walls_s = ", ".join(f"{n}: {walls[n]:.0f} s" for n in cells)
    lines.append(f"(wall time: solver {walls_s}; package {package_s:.0f} s)")
    return "\n".join(lines)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--case", choices=sorted(fv_cases.CASES), action="append")
    parser.add_argument("--cells", type=int, nargs="+")
    parser.add_argument("--courant", type=float)
    parser.add_argument("--seconds", type=float, default=0.0)
    parser.add_argument("--against", type=int)
    args = parser.parse_args()
    for name in args.case or sorted(fv_cases.CASES):
        print(table(name, args.seconds, args.cells, args.courant, args.against), flush=True)
        print()


if __name__ == "__main__":
    main()
