"""The wall's friction per cell: start-up figures against the wave step (issue 50).

Prints, no asserts. For a preset with a walled string, ``drill_sim startup``'s figures
(model/startup.py) with the wave guide stepped every ``--substeps`` steps of the bit law
(string.bit_substeps; a walled string's cells are one wave step long, so this is the
friction's resolution too), each resolution's change against the finest, and the time each
run took.
With ``--statics``: instead, the torque at the top when the bit breaks away on a slow
ramp inside the stick band (to a tenth of it in 60 s) against the integral of r_o mu_s N, and
the mean torque at the top turning steadily at 60 rpm (the last 20 s of 120) against the
integral of r_o mu_d N plus the viscous drag, both integrals taken here on 20 000 pieces.
With ``--ensemble N``: at each resolution N runs whose ramps span --ramp-s x (1 +- 0.2 %)
(a rig cannot set a ramp closer than that), each member's break-away figures: which slip
pulse frees the bit, as a distribution (docs/string.md, "Which slip pulse frees the bit").
Usage: .venv/bin/python benchmarks/wall_convergence.py --params field_8p5in_deviated
       [--rpm 40 --ramp-s 2 --seconds 120] [--substeps 54 27 14 7] [--statics]
       [--ensemble 5]
"""

from __future__ import annotations

import argparse
import time
from dataclasses import replace

import numpy as np

from drill_sim_ros.model import startup
from drill_sim_ros.model.presets import Preset, load_preset

ENSEMBLE_SPAN = 4e-3    # the members' ramps span this, relative, centred on --ramp-s
FIGURES = ("breakaway_s", "breakaway_turns", "breakaway_torque_nm", "first_slip_s",
           "peak_motor_torque_nm", "period_s", "stick_fraction")


def change(value: object, finest: object, name: str) -> str:
    """The relative change against the finest (stick_fraction: the difference)."""
    if not isinstance(value, float) or not isinstance(finest, float) or finest == 0.0:
        return "-"
    if name == "stick_fraction":
        return f"{value - finest:+.3f}"
    return f"{100.0 * (value - finest) / finest:+.2f}%"


def wall_integral_nm(preset: Preset, mu: float, pieces: int = 20_000) -> float:
    """The integral of r_o mu N along the string, N m (midpoint rule, per section)."""
    well, top, total = preset.string.well, 0.0, 0.0
    for s in preset.string.sections:
        total += s.outer_radius_m * mu * well.normal_force_n(
            top, top + s.length_m, s.area_m2, s.density_kg_m3, pieces)
        top += s.length_m
    return total


def statics(preset: Preset) -> None:
    """The slow break-away and the steady sliding torque against the integrals."""
    mu = preset.string.well.side_friction
    slow_rpm = 0.1 * mu.stick_speed_rad_s * startup.RPM_PER_RAD_S
    run = startup.run_startup(preset, slow_rpm, 60.0, 1500.0)
    scores = startup.startup_scores(run)
    static = wall_integral_nm(preset, mu.static)
    print(f"slow ramp to {slow_rpm:.2f} rpm: break-away at {scores['breakaway_s']} s with "
          f"{scores['breakaway_torque_nm']:.1f} N m; integral of r_o mu_s N {static:.1f} N m "
          f"({100 * (scores['breakaway_torque_nm'] / static - 1):+.2f} %)")
    run = startup.run_startup(preset, 60.0, 10.0, 120.0)
    omega = 60.0 / startup.RPM_PER_RAD_S
    viscous = sum(s.torsional_damping_per_s * s.density_kg_m3 * s.polar_moment_m4
                  * s.length_m * omega for s in preset.string.sections)
    expected = wall_integral_nm(preset, mu.dynamic) + viscous
    last = run.t_s >= run.t_s[-1] - 20.0
    mean = float(np.mean(run.surface_torque_nm[last]))
    print(f"steady 60 rpm: mean top torque {mean:.1f} N m (bit {np.mean(run.bit_rpm[last]):.1f}"
          f" rpm); integral of r_o mu_d N {expected - viscous:.1f} + viscous {viscous:.1f} = "
          f"{expected:.1f} N m ({100 * (mean / expected - 1):+.2f} %)")


def ensemble(preset: Preset, args: argparse.Namespace) -> None:
    """Each resolution's members, their ramps spread over ENSEMBLE_SPAN."""
    members = args.ensemble
    for sub in args.substeps:
        p = replace(preset, string=replace(preset.string, bit_substeps=sub))
        for k in range(members):
            relative = ENSEMBLE_SPAN * (k / (members - 1) - 0.5)
            scores = startup.startup_scores(
                startup.run_startup(p, args.rpm, args.ramp_s * (1.0 + relative), args.seconds))
            print(f"substeps {sub}, ramp {100 * relative:+.2f} %: "
                  + ", ".join(f"{name} {scores.get(name)!r:.8}" for name in FIGURES[:5]),
                  flush=True)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--params", default="field_8p5in_deviated")
    parser.add_argument("--rpm", type=float, default=40.0)
    parser.add_argument("--ramp-s", type=float, default=2.0)
    parser.add_argument("--seconds", type=float, default=120.0)
    parser.add_argument("--substeps", type=int, nargs="+", default=[54, 27, 14, 7])
    parser.add_argument("--statics", action="store_true")
    parser.add_argument("--ensemble", type=int, default=1, metavar="N")
    args = parser.parse_args()
    preset = load_preset(args.params)
    if args.statics:
        statics(preset)
        return
    if args.ensemble > 1:
        ensemble(preset, args)
        return
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
