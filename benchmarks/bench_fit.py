"""``drill_sim fit`` on logs made by the simulator with known parameters (issue 51; prints
figures, no asserts).

Each log: a start-up of field_8p5in_deviated (its side friction and torsional damping the
truth) from rest, 0 to 30 rpm in 10 s, 60 s at 100 Hz, measured by the sensors of the
noisy_delayed_sensors scenario (noise and quantisation; delays left out), a seed per log.
The fit adjusts well.side_friction.static, .dynamic, .stick_speed_rad_s and
string.torsional_damping_per_s (or --params), starting from a preset with each of them
20 % below the truth, on a local Dask cluster of --workers. Printed per log: the fitted
values' errors against the truth, whether each 95 % interval covers it, the misfit at the
fit and at the truth (the same weights), the recorded and fitted cycles (period, mean,
std) and the wall time; then the coverage counts (issue 51: within 5 % and >= 17 of 20).
Usage: .venv/bin/python benchmarks/bench_fit.py [--logs 20] [--workers 2]
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from drill_sim_ros.fit import engine, objective, synthetic
from drill_sim_ros.fit.params import get_path, parse_fit, with_values
from drill_sim_ros.model.analysis import lowpass
from drill_sim_ros.model.presets import preset_from_dict, preset_path
from drill_sim_ros.model.validate_input import read_preset_file
from drill_sim_ros.study.engine import connect

PRESET = "field_8p5in_deviated"
PARAMS = ("well.side_friction.static,well.side_friction.dynamic,"
          "well.side_friction.stick_speed_rad_s,string.torsional_damping_per_s")
START_SHARE = 0.8


def one_log(seed: int, data: dict, names: str, client: object) -> dict:
    truth_preset = preset_from_dict(PRESET, data)
    log = synthetic.synthetic_log(truth_preset, 30.0, 10.0, 60.0,
                                  synthetic.scenario_sensors(seed))
    paths = names.split(",")
    truth = np.array([float(get_path(data, p)) for p in paths])
    start = with_values(data, {p: START_SHARE * v for p, v in zip(paths, truth, strict=True)})
    target = objective.make_target(log, truth_preset)
    evaluator = engine.Evaluator(start, parse_fit(names, start), [target], client)
    t0 = time.perf_counter()
    result = engine.fit(evaluator)
    seconds = time.perf_counter() - t0
    at_truth = evaluator.evaluate([truth])[0].misfit
    run = evaluator.map_runs(evaluator.values_of(result.x))[0]
    logged = lowpass(log.torque_nm, log.sample_s, target.cutoff_hz)[target.torque.cycle]
    fitted = target.model_torque(run[0])[target.torque.cycle]
    return {"seed": seed, "error": result.x / truth - 1.0,
            "covers": (result.low95 <= truth) & (truth <= result.high95),
            "misfit": (result.misfit_after, at_truth), "seconds": seconds,
            "replays": result.replays,
            "cycle": (objective.cycle_features(logged, log.sample_s)[:3],
                      objective.cycle_features(fitted, log.sample_s)[:3])}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--logs", type=int, default=20)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--params", default=PARAMS)
    args = ap.parse_args()
    data = read_preset_file(preset_path(PRESET))
    paths = args.params.split(",")
    rows = []
    with connect(None, args.workers) as client:
        for seed in range(1, args.logs + 1):
            r = one_log(seed, data, args.params, client)
            rows.append(r)
            (rec, fit) = r["cycle"]
            print(f"log {seed:2d}: error % {np.array2string(100 * r['error'], precision=1)} "
                  f"covered {r['covers'].astype(int)} misfit {r['misfit'][0]:.3g} (truth "
                  f"{r['misfit'][1]:.3g}); cycle period {rec[0]:.2f}/{fit[0]:.2f} s, mean "
                  f"{rec[1]:.0f}/{fit[1]:.0f} N m, std {rec[2]:.0f}/{fit[2]:.0f} N m "
                  f"(logged/fitted); {r['replays']} replays in {r['seconds']:.0f} s", flush=True)
    errors = np.array([r["error"] for r in rows])
    covers = np.array([r["covers"] for r in rows])
    for i, path in enumerate(paths):
        print(f"{path}: within 5 % in {int(np.sum(np.abs(errors[:, i]) <= 0.05))}/{len(rows)}, "
              f"median |error| {100 * np.median(np.abs(errors[:, i])):.1f} %, 95 % interval "
              f"covers the truth in {int(covers[:, i].sum())}/{len(rows)}")
    print(f"wall time per fit: median {np.median([r['seconds'] for r in rows]):.0f} s, max "
          f"{np.max([r['seconds'] for r in rows]):.0f} s on {args.workers} workers "
          f"({len(paths)} parameters, a 60 s start-up)")


if __name__ == "__main__":
    main()
