"""``drill_sim fit`` on logs made by the simulator with known parameters (issue 51; prints
figures, no asserts).

Each log: a start-up of field_8p5in_deviated (its side friction and torsional damping the
truth) from rest, 0 to 30 rpm in 10 s, 60 s at 100 Hz, measured by the sensors of the
noisy_delayed_sensors scenario (noise and quantisation; delays left out), a seed per log.
The fit adjusts well.side_friction.static, .dynamic, .stick_speed_rad_s and
string.torsional_damping_per_s (or --params), starting from a preset with each of them
20 % below the truth (``--start``), on a local Dask cluster of --workers (0: in this
process); ``--substeps`` sets the wave step (54: 2.0 ms, the tests'; default the preset's).
Resumable: each log's replays go to a cache and each finished log to a JSON line in
``--dir``; run again, the finished logs are read back and an interrupted fit goes on where
it stopped (``--seeds A:B`` picks the logs). Printed per log: the fitted
values' errors against the truth, whether each 95 % interval covers it, the misfit at the
fit and at the truth (the same weights), the recorded and fitted cycles (period, mean,
std; and over the replays averaged at the fit and at the truth, each feature's mean and
standard deviation and the logged one's z: docs/fit.md, the cycle is one draw of a branching
threshold dynamics) and the wall time; then the coverage counts (issue 51: within 5 % and
>= 17 of 20).
Other start-ups: ``--preset`` (a name, a YAML path, or ``tangent``: the Well B-like mapping
of tests/model/fv_cases.py, whose cycle does not branch: docs/fit.md), ``--rpm``,
``--ramp-s`` (default field_8p5in_deviated, 30 rpm in 10 s). Several start-ups, fitted
jointly as ``drill_sim fit`` fits the start-ups of one log: ``--rpm 40,120 --ramp-s 2,6``
(a start-up a speed, each 60 s from rest, the second's sensor noise seeded apart: the
off-bottom torque at two speeds, which is what tells the string's viscous loss, growing
with speed, from the wall's Coulomb friction: docs/fit.md).
Usage: .venv/bin/python benchmarks/bench_fit.py [--seeds 1:20] [--workers 2]
       [--params a,b] [--start 0.8] [--substeps 54] [--dir /tmp/bench_fit]
       [--preset field_8p5in_deviated] [--rpm 30[,R2...]] [--ramp-s 10[,S2...]]
       [--follow speed|setpoint] [--markdown]
(``--markdown``: each log as a row of docs/fit.md's coverage tables; run again with the same
arguments, the finished logs are only read back.)
"""

from __future__ import annotations

import argparse
import contextlib
import json
import sys
import time
from pathlib import Path

import numpy as np

from drill_sim_ros.fit import engine, objective, synthetic
from drill_sim_ros.fit.params import get_path, parse_fit, with_values
from drill_sim_ros.model.analysis import lowpass
from drill_sim_ros.model.presets import preset_from_dict, preset_path, read_preset_data
from drill_sim_ros.model.replay import FOLLOW
from drill_sim_ros.study.engine import connect
from tests.model import fv_cases

PRESET = "field_8p5in_deviated"
PARAMS = ("well.side_friction.static,well.side_friction.dynamic,"
          "well.side_friction.stick_speed_rad_s,string.torsional_damping_per_s")
START_SHARE = 0.8


def preset_data(name: str) -> dict:
    """The preset mapping: ``tangent`` from tests/model/fv_cases.py, else a name or path (a
    survey file it names made absolute, for the fit's replays that build it without a
    base directory)."""
    if name == "tangent":
        return fv_cases.tangent()
    return read_preset_data(preset_path(name))


SEED_APART = 10_000   # a log's k-th start-up has its sensor noise seeded seed + k x this


def one_log(seed: int, data: dict, names: str, client: object, share: float, cache: Path,
            startup: tuple[str, tuple[float, ...], tuple[float, ...]] = (PRESET, (30.0,),
                                                                         (10.0,)),
            follow: str = "speed") -> dict:
    name, rpms, ramps_s = startup
    truth_preset = preset_from_dict(name, data)
    logs = [synthetic.synthetic_log(truth_preset, rpm, ramp_s, 60.0,
                                    synthetic.scenario_sensors(seed + k * SEED_APART))
            for k, (rpm, ramp_s) in enumerate(zip(rpms, ramps_s, strict=True))]
    paths = names.split(",")
    truth = np.array([float(get_path(data, p)) for p in paths])
    start = with_values(data, {p: share * v for p, v in zip(paths, truth, strict=True)})
    targets = [objective.make_target(log, truth_preset) for log in logs]
    log, target = logs[0], targets[0]     # the cycle reported: the first start-up's

    def progress(text: str) -> None:
        print(f"\rlog {seed}: {text}", end="", file=sys.stderr, flush=True)
    evaluator = engine.Evaluator(start, parse_fit(names, start), targets, client, cache,
                                 progress, follow=follow)
    t0, c0 = time.perf_counter(), time.process_time()
    result = engine.fit(evaluator)
    seconds, cpu_s = time.perf_counter() - t0, time.process_time() - c0
    at_truth = evaluator.evaluate([truth])[0].misfit
    run = evaluator.map_runs(evaluator.values_of(result.x))[0]
    logged = lowpass(log.torque_nm, log.sample_s, target.cutoff_hz)[target.torque.cycle]
    fitted = target.model_torque(run[0])[target.torque.cycle]
    print(file=sys.stderr)
    return {"seed": seed, "error": (result.x / truth - 1.0).tolist(),
            "covers": ((result.low95 <= truth) & (truth <= result.high95)).tolist(),
            "interval": np.column_stack((result.low95 / truth - 1.0,
                                         result.high95 / truth - 1.0)).tolist(),
            "misfit": (result.misfit_after, at_truth), "seconds": seconds,
            "cpu_s": cpu_s, "replays": result.replays,
            "stages": {k: list(v) for k, v in result.stages.items()},
            "cycle": (objective.cycle_features(logged, log.sample_s)[:3].tolist(),
                      objective.cycle_features(fitted, log.sample_s)[:3].tolist()),
            "replayed_cycles": {"fitted": _spread(result.cycles[0]),
                                "truth": _spread(evaluator.replayed_cycles(truth)[0])}}


def _spread(cycles: np.ndarray | None) -> list[list[float]] | None:
    """The mean and standard deviation of period, mean and std over a point's replays
    (None for one replay)."""
    if cycles is None or len(cycles) < 2:
        return None
    return np.column_stack((cycles.mean(axis=0), cycles.std(axis=0, ddof=1))).tolist()


def show(r: dict) -> None:
    (rec, fit), error_pct = r["cycle"], 100 * np.array(r["error"])
    band = "; ".join(f"{100 * lo:+.1f} to {100 * hi:+.1f}" for lo, hi in r["interval"])
    stages = ", ".join(f"{k} {n} replays {s:.0f} s" for k, (n, s) in r["stages"].items())
    print(f"log {r['seed']:2d}: error % {np.array2string(error_pct, precision=1)} "
          f"(95 % {band}) covered {np.array(r['covers']).astype(int)} misfit "
          f"{r['misfit'][0]:.3g} (truth "
          f"{r['misfit'][1]:.3g}); cycle period {rec[0]:.2f}/{fit[0]:.2f} s, mean "
          f"{rec[1]:.0f}/{fit[1]:.0f} N m, std {rec[2]:.0f}/{fit[2]:.0f} N m "
          f"(logged/fitted); {r['replays']} replays in {r['seconds']:.0f} s ({r['cpu_s']:.0f} s "
          f"of this process's CPU; {stages})", flush=True)
    for which, spread in r.get("replayed_cycles", {}).items():
        if spread:
            print(f"        its replays at the {which}: " + ", ".join(
                f"{name} {m:.4g} +- {sd:.3g} (logged at z {(logged - m) / sd:+.1f})"
                for name, (m, sd), logged in zip(("period s", "mean N m", "std N m"), spread,
                                                 rec, strict=True)), flush=True)


def markdown_row(r: dict) -> str:
    """One row of docs/fit.md's coverage tables (the first fitted parameter)."""
    (rec, fit), (low, high) = r["cycle"], r["interval"][0]
    return (f"| {r['seed']} | {100 * r['error'][0]:+.1f} % | {100 * low:+.1f} to "
            f"{100 * high:+.1f} % | {'yes' if r['covers'][0] else 'no'} | "
            f"{r['misfit'][0]:.3g} / {r['misfit'][1]:.3g} | {rec[0]:.2f}/{fit[0]:.2f} s, "
            f"{rec[1]:.0f}/{fit[1]:.0f}, {rec[2]:.0f}/{fit[2]:.0f} N m | {r['replays']}, "
            f"{r['seconds']:.0f} s |")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", default="1:20", help="A:B, the logs' seeds (inclusive)")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--params", default=PARAMS)
    ap.add_argument("--start", type=float, default=START_SHARE)
    ap.add_argument("--substeps", type=int, help="the preset's bit_substeps (wave step)")
    ap.add_argument("--dir", type=Path, default=Path("/tmp/bench_fit"))
    ap.add_argument("--preset", default=PRESET,
                    help="a preset name, a YAML path, or tangent (tests/model/fv_cases.py)")
    ap.add_argument("--rpm", default="30", help="R[,R2...]: a start-up a speed")
    ap.add_argument("--ramp-s", default="10", help="S[,S2...]: each start-up's ramp")
    ap.add_argument("--follow", choices=FOLLOW, default="speed",
                    help="what the replays' drive follows (drill_sim fit --follow)")
    ap.add_argument("--markdown", action="store_true",
                    help="print each log as a row of docs/fit.md's tables")
    args = ap.parse_args()
    data = preset_data(args.preset)
    if args.substeps:
        data["string"]["bit_substeps"] = args.substeps
    paths = args.params.split(",")
    first, last = (int(v) for v in args.seeds.split(":"))
    args.dir.mkdir(parents=True, exist_ok=True)
    replays = engine.SETPOINT_REPLAYS if args.follow == "setpoint" else engine.REPLAYS_PER_POINT
    tag = f"{len(paths)}p_{args.start:g}_{args.substeps or 'preset'}_r{replays}_profile"
    rpms = tuple(float(v) for v in args.rpm.split(","))
    ramps_s = tuple(float(v) for v in args.ramp_s.split(","))
    if len(rpms) != len(ramps_s):
        sys.exit(f"--rpm names {len(rpms)} start-ups and --ramp-s {len(ramps_s)}: give one "
                 "ramp a start-up")
    startup = (args.preset, rpms, ramps_s)
    if startup != (PRESET, (30.0,), (10.0,)):
        tag += (f"_{Path(args.preset).stem}_{'+'.join(f'{r:g}' for r in rpms)}rpm_"
                f"{'+'.join(f'{r:g}' for r in ramps_s)}s")
    if args.follow != "speed":
        tag += f"_follow_{args.follow}"
    done_path = args.dir / f"done_{tag}.jsonl"
    done = {}
    if done_path.exists():
        for line in done_path.read_text().splitlines():
            r = json.loads(line)
            if r.get("params") == args.params:
                done[r["seed"]] = r
    rows = []
    with connect(None, args.workers) if args.workers else contextlib.nullcontext() as client:
        for seed in range(first, last + 1):
            if seed in done:
                r = done[seed]
            else:
                r = one_log(seed, data, args.params, client, args.start,
                            args.dir / f"cache_{tag}_{seed}.jsonl", startup, args.follow)
                r["params"] = args.params
                with done_path.open("a") as f:
                    f.write(json.dumps(r) + "\n")
            rows.append(r)
            print(markdown_row(r), flush=True) if args.markdown else show(r)
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
