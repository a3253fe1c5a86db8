"""The wall's friction per cell: start-up figures against the wave step (issue 50).

Prints, no asserts. For a preset with a walled string, ``drill_sim startup``'s figures
(model/startup.py) with the wave guide stepped every ``--substeps`` steps of the bit law
(string.bit_substeps; a walled string's cells are one wave step long, so this is the
friction's resolution too), each resolution's change against the finest, and the time each
run took.
Usage: .venv/bin/python benchmarks/wall_convergence.py --params field_8p5in_deviated
       [--rpm 40 --ramp-s 2 --seconds 120] [--substeps 54 27 14 7]
"""

from __future__ import annotations

import argparse
import time
from dataclasses import replace

from drill_sim_ros.model import startup
from drill_sim_ros.model.presets import load_preset

FIGURES = ("breakaway_s", "breakaway_turns", "breakaway_torque_nm", "first_slip_s",
           "peak_motor_torque_nm", "period_s", "stick_fraction")


def change(value: object, finest: object, name: str) -> str:
    """The relative change against the finest (stick_fraction: the difference)."""
    if not isinstance(value, float) or not isinstance(finest, float) or finest == 0.0:
        return "-"
    if name == "stick_fraction":
        return f"{value - finest:+.3f}"
    return f"{100.0 * (value - finest) / finest:+.2f}%"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--params", default="field_8p5in_deviated")
    parser.add_argument("--rpm", type=float, default=40.0)
    parser.add_argument("--ramp-s", type=float, default=2.0)
    parser.add_argument("--seconds", type=float, default=120.0)
    parser.add_argument("--substeps", type=int, nargs="+", default=[54, 27, 14, 7])
    args = parser.parse_args()
    preset = load_preset(args.params)
    rows = {}
    for sub in args.substeps:
        p = replace(preset, string=replace(preset.string, bit_substeps=sub))
        start = time.perf_counter()
        run = startup.run_startup(p, args.rpm, args.ramp_s, args.seconds)
        scores = startup.startup_scores(run)
        step_ms = sub * p.dtau * p.scales.time_s * 1e3
        rows[sub] = scores
        print(f"substeps {sub} (wave step {step_ms:.3f} ms, "
              f"{time.perf_counter() - start:.1f} s): "
              + ", ".join(f"{name} {scores.get(name)!r:.8}" for name in FIGURES), flush=True)
    finest = rows[args.substeps[-1]]
    for sub, scores in rows.items():
        print(f"substeps {sub} against {args.substeps[-1]}: "
              + ", ".join(f"{name} {change(scores.get(name), finest.get(name), name)}"
                          for name in FIGURES))


if __name__ == "__main__":
    main()
