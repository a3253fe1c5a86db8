"""How rough the misfit of ``drill_sim fit --follow setpoint`` is, with one replay a point and
with the shifted replays it averages (issue 51; prints figures, no asserts).

Logs: the Well B-like tangent (tests/model/fv_cases.py) started from rest to 40 rpm in 2 s
and to 120 rpm in 6 s, 60 s each, measured by the noisy_delayed_sensors scenario's sensors
(sensor seeds ``--seed`` and ``--seed`` + bench_fit.SEED_APART), the wave step of
``--substeps 54`` (2.0 ms). The misfit (fit.engine's Evaluator, the replays following the
logged setpoint through the preset's speed loop) is printed at ``--points`` points on the
segment from ``--from`` (each fitted parameter's relative error, %) to the truth, for 1 and
for ``--replays`` replays a point (fit.engine.shifted_setpoint), with two summaries per
row: the net fall of the misfit along the segment and the sum of its rises (what a
descent has to climb: 0 for a misfit that falls all the way).

The default ``--from`` is where a joint fit with one replay a point stopped on the log of
seed 1 (2026-12-07, docs/fit.md): the four parameters -0.43, -1.19, -0.13 and +6.02 % off.

Usage: .venv/bin/python benchmarks/fit_setpoint_roughness.py [--seed 1]
       [--from -0.43,-1.19,-0.13,6.02] [--points 21] [--replays 4]
"""

from __future__ import annotations

import argparse

import numpy as np

from benchmarks.bench_fit import PARAMS, SEED_APART, preset_data
from drill_sim_ros.fit import engine, objective, synthetic
from drill_sim_ros.fit.params import get_path, parse_fit
from drill_sim_ros.model.presets import preset_from_dict

STARTUPS = ((40.0, 2.0), (120.0, 6.0))     # rpm, ramp s
LOG_S = 60.0


def segment_misfits(evaluator: engine.Evaluator, start: np.ndarray, end: np.ndarray,
                    points: int) -> np.ndarray:
    """The misfit at ``points`` points evenly from ``start`` to ``end`` (parameter values)."""
    xs = [start + s * (end - start) for s in np.linspace(0.0, 1.0, points)]
    return np.array([e.misfit for e in evaluator.evaluate(xs)])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--from", dest="start", default="-0.43,-1.19,-0.13,6.02")
    ap.add_argument("--points", type=int, default=21)
    ap.add_argument("--replays", type=int, default=engine.SETPOINT_REPLAYS)
    args = ap.parse_args()
    data = preset_data("tangent")
    data["string"]["bit_substeps"] = 54
    preset = preset_from_dict("tangent", data)
    logs = [synthetic.synthetic_log(preset, rpm, ramp_s, LOG_S,
                                    synthetic.scenario_sensors(args.seed + k * SEED_APART))
            for k, (rpm, ramp_s) in enumerate(STARTUPS)]
    targets = [objective.make_target(log, preset) for log in logs]
    truth = np.array([float(get_path(data, p)) for p in PARAMS.split(",")])
    start = truth * (1.0 + np.array([float(v) for v in args.start.split(",")]) / 100.0)
    print(f"log {args.seed}: the segment from {args.start} % to the truth, "
          f"{args.points} points")
    for replays in (1, args.replays):
        evaluator = engine.Evaluator(data, parse_fit(PARAMS, data), targets,
                                     replays=replays, follow="setpoint")
        misfits = segment_misfits(evaluator, start, truth, args.points)
        steps = np.diff(misfits)
        print(f"{replays} replay(s) a point: " + " ".join(f"{m:.3f}" for m in misfits))
        print(f"    net fall {misfits[0] - misfits[-1]:.3f}, its rises sum to "
              f"{np.sum(steps[steps > 0.0]):.3f}, the largest {np.max(steps):.3f}")


if __name__ == "__main__":
    main()
