"""Does a length for the wall's static-to-dynamic drop make the deviated break-away converge?

(Prints figures, no asserts; docs/string.md, "A length for the drop".) The wall law of the
package and of the independent solver (``tests/model/fv_reference.py``) drops from mu_s to
mu_d at once when a contact leaves its stick band: no length scale, and on the deviated
preset the break-away moves with the cell at every cell tried. Fault mechanics' answer
(Rice 1993; Shaw 1997) is a slip-weakening distance L: mu falls linearly over a slip L, a
sliding patch is unstable only beyond a nucleation length

    h* = pi sqrt(G J L / ((mu_s - mu_d) N r_o^2))       (torsion)
    h*_a = pi sqrt(E A L / ((mu_s - mu_d) N))           (axial)

(the lowest mode of a patch held at both ends, (pi / h)^2 G J, against the weakening's
negative stiffness (mu_s - mu_d) N r_o^2 / L per metre), and a front running at the wave
speed c with a surface slip rate u weakens over Lambda = c L / u behind it (u at least the
band's r_o w_band for a sliding face: Lambda <= c L / (r_o w_band)).

First the table of h* and Lambda along the preset's string for each ``--weakening-um``
(with the bend term, the normal force of the solver); then the solver's start-up
(``field_8p5in_deviated``, 30 rpm in 10 s, 25 s, Courant 1) at each L and ``--cells``
(multiples of 27: whole cells in both sections), one row per run as it finishes, and
after the table each run's train of slip pulses: when a sliding front first passes 750 m
(below the upper build) and the deepest face it reaches before the string below 750 m is
stuck again (2700 m: the bit; 2500 m: the collars' top).

Usage: PYTHONPATH=. nice .venv/bin/python benchmarks/fv_slip_weakening.py
       [--weakening-um 0 100 1000] [--cells 675 1350 2700 5400] [--seconds 25] [--table-only]
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import time

import numpy as np

from benchmarks.fv_startup_convergence import cell
from tests.model import fv_cases
from tests.model import fv_reference as fv

FIGURES = ("breakaway_s", "breakaway_turns", "breakaway_torque_nm", "first_slip_s",
           "peak_motor_torque_nm", "stick_fraction")
DEPTHS_M = (310.0, 400.0, 500.0, 690.0, 1000.0, 1400.0, 2000.0, 2600.0)
BELOW_BUILD_M = 750.0


class PulseWatch:
    """Records at each sample the deepest inner face below ``BELOW_BUILD_M`` whose slip is
    outside the band (0: none), from ``run_startup``'s ``on_sample``."""

    def __init__(self) -> None:
        self.t_s: list[float] = []
        self.front_m: list[float] = []

    def __call__(self, t_s: float, line: fv.Line) -> None:
        faces_m = 0.5 * (line.depth_m[:-1] + line.depth_m[1:])
        sliding = (np.abs(line.w_face[:-1] * line.arm[:-1]) > line.band[:-1]) \
            & (faces_m > BELOW_BUILD_M)
        self.t_s.append(t_s)
        self.front_m.append(float(faces_m[sliding].max()) if sliding.any() else 0.0)

    def pulses(self) -> list[tuple[float, float]]:
        """(start s, reach m) of each run of at least three samples with a front below the
        build; a face at the bit counts as the bit (2700 m)."""
        t, front = np.array(self.t_s), np.array(self.front_m)
        edges = np.flatnonzero(np.diff(np.concatenate(([0], (front > 0).astype(int), [0]))))
        return [(float(t[s]), float(front[s:e].max()))
                for s, e in zip(edges[::2], edges[1::2], strict=True) if e - s >= 3]


def section_at(case: fv.Case, md_m: float) -> tuple[fv.Section, float]:
    """The section holding ``md_m`` and its top depth."""
    top = 0.0
    for s in case.sections:
        if md_m < top + s.length_m:
            return s, top
        top += s.length_m
    return case.sections[-1], top - case.sections[-1].length_m


def lengths_m(case: fv.Case, md_m: float, weakening_m: float) -> tuple[float, ...]:
    """(N N/m, torsional h* m, axial h*_a m, Lambda m) at ``md_m`` for L = ``weakening_m``."""
    s, _ = section_at(case, md_m)
    n = float(fv.normal_force_n_per_m(case, s, np.array([md_m]))[0])
    drop = (case.mu_static - case.mu_dynamic) * n
    gj = s.shear_modulus_pa * s.polar_moment_m4
    h_t = math.pi * math.sqrt(gj * weakening_m / (drop * s.outer_radius_m**2))
    h_a = math.pi * math.sqrt(s.youngs_modulus_pa * s.area_m2 * weakening_m / drop)
    c_t = math.sqrt(s.shear_modulus_pa / s.density_kg_m3)
    cohesive = c_t * weakening_m / (s.outer_radius_m * case.stick_band_rad_s)
    return n, h_t, h_a, cohesive


def length_table(case: fv.Case, weakenings_m: list[float]) -> str:
    head = " | ".join(f"L = {w * 1e6:g} um: h* / h*_a / Lambda" for w in weakenings_m)
    lines = [f"| md m | N N/m | {head} |", "|---" * (len(weakenings_m) + 2) + "|"]
    for md in DEPTHS_M:
        cells = []
        for w in weakenings_m:
            n, h_t, h_a, lam = lengths_m(case, md, w)
            cells.append(f"{h_t:.1f} / {h_a:.1f} / {lam:.1f}")
        lines.append(f"| {md:g} | {n:.0f} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def run_row(case: fv.Case, weakening_m: float, cells: int, seconds: float,
            cutoff_hz: float) -> tuple[str, str]:
    """The table row of one run and its pulse train."""
    dx = case.sections[0].length_m / fv.cell_counts(case, cells)[0]
    watch = PulseWatch()
    start = time.perf_counter()
    run = fv.run_startup(dataclasses.replace(case, slip_weakening_m=weakening_m), 30.0, 10.0,
                         seconds, cells, courant=1.0, on_sample=watch)
    figures = fv.startup_figures(run, cutoff_hz)
    wall_s = time.perf_counter() - start
    row = " | ".join(cell(figures[key], key) for key in FIGURES)
    label = f"{weakening_m * 1e6:g} | {cells} ({dx:.3g} m)"
    train = ", ".join(f"{t:.1f}>{reach:.0f}" for t, reach in watch.pulses())
    return f"| {label} | {row} | {wall_s:.0f} s |", f"L {label}: {train}"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--weakening-um", type=float, nargs="+", default=[0.0, 100.0, 1000.0])
    parser.add_argument("--cells", type=int, nargs="+", default=[675, 1350, 2700, 5400])
    parser.add_argument("--seconds", type=float, default=25.0)
    parser.add_argument("--table-only", action="store_true")
    args = parser.parse_args()
    case = fv.case_from_preset(fv_cases.deviated(), bend_term=True)
    weakenings_m = [w * 1e-6 for w in args.weakening_um]
    print("field_8p5in_deviated, with the bend term: nucleation lengths (m)")
    print(length_table(case, [w for w in weakenings_m if w > 0.0] or [1e-5, 1e-4, 1e-3]))
    if args.table_only:
        return
    cutoff_hz = 2.0 * fv.torsional_modes_hz(case)[-1]
    print(f"\nthe solver, 30 rpm in 10 s, {args.seconds:g} s, Courant 1 "
          f"(cut-off {cutoff_hz:.4f} Hz)")
    print("| L um | cells (pipe) | " + " | ".join(f"`{k}`" for k in FIGURES) + " | wall |")
    print("|---" * (len(FIGURES) + 3) + "|", flush=True)
    trains = []
    for w in weakenings_m:
        for n in args.cells:
            row, train = run_row(case, w, n, args.seconds, cutoff_hz)
            print(row, flush=True)
            trains.append(train)
    print("\npulses below the build (start s > reach m):")
    print("\n".join(trains))


if __name__ == "__main__":
    main()
