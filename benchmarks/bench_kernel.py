"""Kernel speed: ns per step for the Fig. 8 beta = 0.3 case at dtau = 1e-5, tau in [0, 600].

Uses the production path (bottom-hole profile delay, as sim_node does), compilation excluded.
Beside it, in the same run, the naive reference step of the tests (tests/model/reference.py:
the same lumped step written plainly in one njit loop, the same profile delay, nodes and
statistics) and the kernel's ns/step as a ratio to it (issue 35): a change that brings
reference counting or an object-mode fallback into the step loop shows as a ratio well
above today's. Prints figures only; no asserts. Run: `make bench` (or python
benchmarks/bench_kernel.py).
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

from drill_sim_ros.model import analysis
from drill_sim_ros.model.params import DimensionlessParams
from drill_sim_ros.model.simulator import SimConfig, Simulator

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))   # for tests.model.reference
from tests.model import reference

FIG8A = DimensionlessParams(n=6, psi=50.0, beta=0.3, lam=5.0, w0=7.0, omega0=5.0)


def one_run(method: str, dtau: float, tau_end: float) -> tuple[float, int, Simulator]:
    sim = Simulator(FIG8A, SimConfig(dtau=dtau, method=method, tau_avg=tau_end / 2),
                    perturb_v=0.01)
    sim.advance(0, every=1)                       # compile / load the cache first
    steps = sim.steps_for(tau_end)
    start = time.perf_counter()
    sim.advance(steps)
    return time.perf_counter() - start, steps, sim


def reference_run(dtau: float, tau_end: float) -> tuple[float, int]:
    """(wall s, steps) of the naive reference step over the same run as :func:`one_run`
    (one row at the start, the statistics over tau >= tau_end / 2)."""
    nodes = SimConfig(dtau=dtau).n_nodes
    p = FIG8A
    steps = round(tau_end / dtau)
    args = (float(p.n), p.beta, p.lam, p.psi, p.w0, p.omega0, dtau)
    state, profile = reference.initial_state(p, 0.01, 0.0, nodes)
    reference.run_reference(state, profile.copy(), *args, 10, 10, tau_end / 2)   # compile
    start = time.perf_counter()
    reference.run_reference(state, profile, *args, steps, steps, tau_end / 2)
    return time.perf_counter() - start, steps


def print_ratio(args: argparse.Namespace) -> None:
    """The naive step's ns/step and the kernel's (profile method) as a ratio to it, from
    runs in alternating pairs (so both see the same load)."""
    kernel_ns, naive_ns = [], []
    for _ in range(args.repeats):
        seconds, steps, _ = one_run("profile", args.dtau, args.tau_end)
        kernel_ns.append(1e9 * seconds / steps)
        seconds, steps = reference_run(args.dtau, args.tau_end)
        naive_ns.append(1e9 * seconds / steps)
    ratios = [a / b for a, b in zip(kernel_ns, naive_ns, strict=True)]
    print(f"naive step (tests/model/reference.py, the lumped step in one plain njit loop): "
          f"ns/step best {min(naive_ns):.2f}, median {statistics.median(naive_ns):.2f}")
    print(f"kernel / naive step (profile method, {args.repeats} alternating pairs): best "
          f"{min(kernel_ns) / min(naive_ns):.2f}, median of the pairs "
          f"{statistics.median(ratios):.2f}")


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
    print_ratio(args)


if __name__ == "__main__":
    main()
