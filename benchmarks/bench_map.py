"""Map throughput: points/s/core of a (W0', omega0) map at tau = 600 on Dask, against the
single-process `drill_sim run` loop in the same run, the 10 000-point extrapolation for
this machine, and the dtau that keeps kappa within 1 % of its converged value.

Prints figures only; no asserts. Run: `make bench` (or python benchmarks/bench_map.py).
The map uses the Fig. 11 case (n = 6, psi = 63, beta = 0.28, lam = 4.70588), W0' in
[1.2, 2.0] and omega0 in [2, 8], tau in [0, 600], averages over [300, 600].
"""

from __future__ import annotations

import argparse
import os
import tempfile
import time
from argparse import Namespace
from pathlib import Path

import numpy as np

from drill_sim_ros import cli
from drill_sim_ros.model.presets import load_preset
from drill_sim_ros.study import engine
from drill_sim_ros.study.grid import Axis, MapSpec, Numerics
from drill_sim_ros.study.point import COLUMN, evaluate_point

TARGET_POINTS = 10_000
DTAUS = (3.2e-3, 1.6e-3, 8e-4, 4e-4, 2e-4, 1e-4, 5e-5, 2.5e-5)
REGULAR = 0.002            # the two finest steps agree within this: a converged point


def grid_spec(side: int, dtau: float) -> MapSpec:
    base = load_preset("fig11").params
    axes = (Axis("w0_ratio", tuple(np.linspace(1.2, 2.0, side))),
            Axis("omega0", tuple(np.linspace(2.0, 8.0, side))))
    return MapSpec(base, axes, Numerics(tau_end=600.0, average_from=300.0, dtau=dtau))


def run_loop(spec: MapSpec) -> float:
    """The reference: `drill_sim run`'s simulate() over the points, one process."""
    args = cli.build_parser().parse_args(["run"])
    cli.simulate(cli._resolve(args))                       # load the kernel first
    start = time.perf_counter()
    for flat in range(spec.size):
        p = spec.point(flat)
        point = Namespace(**{**vars(args), **{g: getattr(p, g) for g in cli.GROUPS},
                             "dtau": spec.numerics.dtau, "tau_end": 600.0,
                             "average_from": 300.0})
        cli.simulate(cli._resolve(point))
    return spec.size / (time.perf_counter() - start)


def run_dask(spec: MapSpec, workers: int) -> tuple[float, float, float]:
    """(points/s of the map, cluster start-up s, run_map s) on a LocalCluster."""
    t0 = time.perf_counter()
    with tempfile.TemporaryDirectory() as tmp, engine.connect(workers=workers) as client:
        client.run(engine.warm_up)
        startup = time.perf_counter() - t0
        result = engine.run_map(spec, Path(tmp) / "bench.nc", client)
    return result.computed / result.seconds, startup, result.seconds


def kappa_convergence(points: list[tuple[float, float]]) -> tuple[list[tuple[float, float]],
                                                                 list[tuple[float, float, float]]]:
    """(dtau, worst relative kappa error against the finest step) over the points whose two
    finest steps agree within REGULAR, and (W0', omega0, spread) of the others (irregular
    cycles whose window average does not settle with dtau)."""
    base = load_preset("fig11").params
    table = {}
    for ratio, omega0 in points:
        p = base.with_(w0=ratio * base.lam, omega0=omega0)
        table[(ratio, omega0)] = np.array([
            evaluate_point(p, Numerics(tau_end=600.0, average_from=300.0, dtau=d))[
                COLUMN["kappa"]] for d in DTAUS])
    regular = {key: k for key, k in table.items()
               if abs(k[-1]) > 1e-3 and abs(k[-2] - k[-1]) <= REGULAR * abs(k[-1])}
    irregular = [(*key, float(np.ptp(k) / abs(k[-1]))) for key, k in table.items()
                 if key not in regular and abs(k[-1]) > 1e-3]
    worst = [(dtau, max(abs(k[i] - k[-1]) / abs(k[-1]) for k in regular.values())
              if regular else float("nan")) for i, dtau in enumerate(DTAUS[:-1])]
    return worst, irregular


def run_points_in_process(spec: MapSpec) -> float:
    """evaluate_point (what a worker runs) over the points, this process."""
    evaluate_point(spec.point(0), Numerics(tau_end=0.01, average_from=0.0))
    start = time.perf_counter()
    for flat in range(spec.size):
        evaluate_point(spec.point(flat), spec.numerics)
    return spec.size / (time.perf_counter() - start)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--side", type=int, default=6, help="grid points per axis")
    parser.add_argument("--dtau", type=float, default=1e-4)
    parser.add_argument("--workers", type=int, default=os.cpu_count() or 1)
    args = parser.parse_args()
    spec = grid_spec(args.side, args.dtau)
    print(f"map: {spec.size} points of (W0', omega0), tau = 600, dtau = {args.dtau:g}, "
          f"{args.workers} workers on {os.cpu_count()} cores (shared machine: as measured)")
    loop_rate = run_loop(spec)
    print(f"  single-process drill_sim run loop: {loop_rate:.2f} points/s (1 core)")
    point_rate = run_points_in_process(spec)
    print(f"  map points (evaluate_point) in this process: {point_rate:.2f} points/s (1 core)")
    rate, startup, seconds = run_dask(spec, args.workers)
    per_core = rate / args.workers
    print(f"  Dask map: {rate:.2f} points/s in {seconds:.1f} s = {per_core:.2f} points/s/core "
          f"({per_core / loop_rate:.2f} x the loop per core); cluster start-up {startup:.1f} s")
    wall = TARGET_POINTS / rate + startup
    print(f"  extrapolated {TARGET_POINTS} points at dtau = {args.dtau:g}: "
          f"{wall / 60:.1f} min on {args.workers} workers (target <= 10 min)")
    grid = [(r, w) for r in (1.2, 1.5, 1.8) for w in (2.5, 4.5, 6.5)]
    print("kappa against dtau (Fig. 11 case, W0' in {1.2, 1.5, 1.8} x omega0 in "
          "{2.5, 4.5, 6.5}; reference: dtau = 2.5e-5):")
    worst, irregular = kappa_convergence(grid)
    for dtau, err in worst:
        print(f"  dtau = {dtau:g}: kappa within {100 * err:.3f} % of the reference")
    for ratio, omega0, spread in irregular:
        print(f"  W0' = {ratio:g}, omega0 = {omega0:g}: irregular cycle, kappa spread "
              f"{100 * spread:.1f} % over the steps (window average, not dtau)")
    ok = [d for d, e in worst if e <= 0.01]
    if ok:
        best = max(ok)
        best_spec = grid_spec(max(args.side, 12), best)     # enough points to amortise tasks
        best_rate, best_startup, best_s = run_dask(best_spec, args.workers)
        wall = TARGET_POINTS / best_rate + best_startup
        print(f"  largest dtau within 1 %: {best:g}; Dask map of {best_spec.size} points there: "
              f"{best_rate:.2f} points/s "
              f"({best_s:.1f} s); {TARGET_POINTS} points: {wall / 60:.1f} min on "
              f"{args.workers} workers (target <= 10 min)")
    else:
        print("  no tested dtau keeps kappa within 1 %")


if __name__ == "__main__":
    main()
