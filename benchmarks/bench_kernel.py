"""Kernel speed: ns per step for the Fig. 8 beta = 0.3 case at dtau = 1e-5, tau in [0, 600].

Uses the production path (bottom-hole profile delay, as sim_node does), compilation excluded.
Prints figures only; no asserts. Run: `make bench` (or python benchmarks/bench_kernel.py).
"""

from __future__ import annotations

import argparse
import statistics
import time

from drill_sim_ros.model import analysis
from drill_sim_ros.model.params import DimensionlessParams
from drill_sim_ros.model.simulator import SimConfig, Simulator

FIG8A = DimensionlessParams(n=6, psi=50.0, beta=0.3, lam=5.0, w0=7.0, omega0=5.0)


def one_run(method: str, dtau: float, tau_end: float) -> tuple[float, int, Simulator]:
    sim = Simulator(FIG8A, SimConfig(dtau=dtau, method=method, tau_avg=tau_end / 2),
                    perturb_v=0.01)
    sim.advance(0, every=1)                       # compile / load the cache first
    steps = sim.steps_for(tau_end)
    start = time.perf_counter()
    sim.advance(steps)
    return time.perf_counter() - start, steps, sim


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--dtau", type=float, default=1e-5)
    parser.add_argument("--tau-end", type=float, default=600.0)
    args = parser.parse_args()
    for method in ("profile", "exact"):
        times = []
        for _ in range(args.repeats):
            seconds, steps, sim = one_run(method, args.dtau, args.tau_end)
            times.append(seconds)
        ns = [1e9 * t / steps for t in times]
        avg = analysis.cycle_averages(FIG8A, sim.accumulators)
        stick, _ = analysis.first_event_tau(sim.accumulators)
        tag = " (sim_node's method)" if method == "profile" else " (reference path)"
        print(f"{method}{tag}: {steps:,} steps; ns/step best {min(ns):.2f}, median "
              f"{statistics.median(ns):.2f}; wall {min(times):.2f} s")
        print(f"  Fig. 8a metrics: first stick tau = {stick:.3f}, omega_max/omega0 = "
              f"{avg.omega_max / FIG8A.omega0:.3f}, kappa = {avg.kappa:.4f}, "
              f"stick fraction = {avg.stick_fraction:.3f}")


if __name__ == "__main__":
    main()
