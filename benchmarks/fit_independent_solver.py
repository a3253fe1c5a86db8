"""``drill_sim fit`` on a log made by the independent finite-volume solver (issue 51: the side
friction recovered within 10 % from a different solver of the same physics; prints figures,
no asserts).

The log: ``tests/model/fv_reference.py`` (numpy only, no code shared with the package) runs a
case of ``tests/model/fv_cases.py`` at its speed and ramp (default ``tangent``: its break-away
and cycle converge in the solver's cells, docs/string.md; the deviated preset's do not with
the bend term) at ``--cells`` (1000: its break-away figures within 0.3 % of 4000's there),
its drive's speed and string torque at the top measured by the noisy_delayed_sensors
scenario's sensors (noise and quantisation, seeded ``--seed``) after 1 s at rest. The fit:
the package's preset of the same case (its own wave step), ``--fit`` (default the static
and dynamic coefficients) from ``--start`` x their true values, on a local Dask cluster of
``--workers`` (0: in this process), a cache beside the log (``--dir``) so that a run
started again resumes.
Printed: the solver's time, each fitted value against the truth with its interval, the
misfits, the wall time.

Usage: .venv/bin/python benchmarks/fit_independent_solver.py [--case tangent]
       [--cells 1000] [--seconds 60] [--workers 0] [--dir /tmp/fit_fv]
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

from drill_sim_ros.fit import engine, objective, synthetic
from drill_sim_ros.fit.log import find_startups
from drill_sim_ros.fit.params import get_path, parse_fit, with_values
from drill_sim_ros.model.presets import preset_from_dict
from tests.model import fv_cases
from tests.model import fv_reference as fv

FIT = "well.side_friction.static,well.side_friction.dynamic"


def csv_path(args: argparse.Namespace) -> Path:
    return args.dir / f"{args.case}_{args.cells}_{args.seconds:g}_{args.seed}.csv"


def fv_log(raw: dict, args: argparse.Namespace) -> synthetic.SurfaceLog:
    """The solver's start-up as the scenario's sensors log it (cached as a CSV)."""
    path = csv_path(args)
    if not path.exists():
        rpm, ramp_s = fv_cases.CASES[args.case][1:3]
        t0 = time.perf_counter()
        series = fv.run_startup(fv.case_from_preset(raw, fv_cases.package_has_bend_term()),
                                rpm, ramp_s, args.seconds, args.cells)
        print(f"solver: {args.cells} cells, {args.seconds:g} s in "
              f"{time.perf_counter() - t0:.0f} s", flush=True)
        log = synthetic.measured_log(series, synthetic.scenario_sensors(args.seed), 1.0,
                                     f"fv_reference {args.case} {args.cells} cells")
        synthetic.write_csv(log, str(path))
    from drill_sim_ros.fit.log import read_log
    return read_log(str(path))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--case", default="tangent", choices=("tangent", "deviated"))
    ap.add_argument("--cells", type=int, default=1000)
    ap.add_argument("--seconds", type=float, default=60.0)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--fit", default=FIT)
    ap.add_argument("--start", type=float, default=0.85)
    ap.add_argument("--workers", type=int, default=0)
    ap.add_argument("--dir", type=Path, default=Path("/tmp/fit_fv"))
    args = ap.parse_args()
    args.dir.mkdir(parents=True, exist_ok=True)
    raw = fv_cases.CASES[args.case][0]()
    raw.pop("description", None)
    log = fv_log(raw, args)
    paths = args.fit.split(",")
    truth = np.array([float(get_path(raw, p)) for p in paths])
    start = with_values(raw, {p: args.start * v for p, v in zip(paths, truth, strict=True)})
    preset = preset_from_dict(args.case, start)
    targets = [objective.make_target(log.part(a, b), preset) for a, b in find_startups(log)]
    cache = args.dir / f"{csv_path(args).stem}_{len(paths)}p_{args.start:g}.jsonl"
    t0 = time.perf_counter()
    if args.workers:
        from drill_sim_ros.study.engine import connect
        with connect(None, args.workers) as client:
            evaluator = engine.Evaluator(start, parse_fit(args.fit, start), targets, client,
                                         cache)
            result = engine.fit(evaluator)
    else:
        evaluator = engine.Evaluator(start, parse_fit(args.fit, start), targets, None, cache)
        result = engine.fit(evaluator)
    at_truth = evaluator.evaluate([truth])[0].misfit
    for i, path in enumerate(paths):
        print(f"{path}: truth {truth[i]:.4g}, fitted {result.x[i]:.4g} "
              f"({100 * (result.x[i] / truth[i] - 1):+.1f} %), 95 % "
              f"[{result.low95[i]:.4g}, {result.high95[i]:.4g}]")
    print(f"misfit {result.misfit_before:.3f} at the start, {result.misfit_after:.3f} fitted, "
          f"{at_truth:.3f} at the truth; {result.replays} replays ({result.reused} from the "
          f"cache) in {time.perf_counter() - t0:.0f} s")


if __name__ == "__main__":
    main()
