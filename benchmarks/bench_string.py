"""The distributed string's cost (issue 21; prints figures, no asserts).

(a) kernel ns/step of the lumped string (Fig. 8a, dtau 1e-5), this build against the kernel
    before the string existed (commit 855bfb7, read from git), alternated in one run;
(b) the session alone, periods/s, and the in-process closed-loop bench (soft_torque, 100 Hz),
    on the distributed field preset and on its lumped twin, alternated;
(c) sim_node at 100 Hz real time: CPU % on the distributed field preset against the same
    node on the lumped twin, alternated pairs in one run.
Usage: .venv/bin/python benchmarks/bench_string.py [--node-seconds 20] [--pairs 2]
"""

from __future__ import annotations

import argparse
import importlib.util
import os
import random
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
os.environ.pop("ROS_LOCALHOST_ONLY", None)
os.environ.setdefault("ROS_DOMAIN_ID", str(random.randint(1, 101)))
os.environ.setdefault("AMENT_PREFIX_PATH", sys.prefix)

import numpy as np
from bench_node import start_node, stop  # the sibling script (benchmarks/ on sys.path)

from drill_sim_ros.control.bench import run_in_process, session_config
from drill_sim_ros.control.scenario import Scenario
from drill_sim_ros.model import kernel as k
from drill_sim_ros.model.params import DimensionlessParams
from drill_sim_ros.model.session import SimSession
from drill_sim_ros.model.simulator import SimConfig, Simulator
from tests.process_probes import cpu_seconds

ROOT = Path(__file__).resolve().parents[1]
FIG8A = DimensionlessParams(n=6, psi=50.0, beta=0.3, lam=5.0, w0=7.0, omega0=5.0)
PRESETS = ("field_8p5in_shale", "field_8p5in_shale_lumped")


def old_kernel():
    """The kernel module of commit 855bfb7, imported from git into a temporary file."""
    source = subprocess.run(["git", "-C", str(ROOT), "show", "855bfb7:drill_sim_ros/model/"
                             "kernel.py"], capture_output=True, text=True, check=True).stdout
    path = Path(tempfile.mkdtemp()) / "kernel_855bfb7.py"
    path.write_text(source)
    spec = importlib.util.spec_from_file_location("kernel_855bfb7", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def kernel_ns_per_step(old, steps: int = 10_000_000) -> tuple[float, float]:
    sim = Simulator(FIG8A, SimConfig(dtau=1e-5), perturb_v=0.01)
    args = (sim._state, sim._prm, sim._targets, sim._profile)
    st16, prm13 = args[0][:16].copy(), args[1][:13].copy()
    out16, out18 = np.empty((0, 16)), np.empty((0, 18))
    old.advance(st16.copy(), prm13, args[2], args[3].copy(), k.NO_HISTORY, k.NO_META.copy(),
                k.new_accumulators(), out16, 10, 0, False)
    k.advance(args[0].copy(), args[1], args[2], args[3].copy(), k.NO_HISTORY,
              k.NO_META.copy(), k.new_accumulators(), out18, None, None, None, 10, 0, False)
    start = time.perf_counter()
    old.advance(st16, prm13, args[2], args[3].copy(), k.NO_HISTORY, k.NO_META.copy(),
                k.new_accumulators(), out16, steps, 0, False)
    t_old = time.perf_counter() - start
    start = time.perf_counter()
    k.advance(args[0].copy(), args[1], args[2], args[3].copy(), k.NO_HISTORY,
              k.NO_META.copy(), k.new_accumulators(), out18, None, None, None, steps, 0,
              False)
    t_new = time.perf_counter() - start
    return 1e9 * t_old / steps, 1e9 * t_new / steps


def session_rate(preset: str, seconds: float = 60.0) -> float:
    scenario = Scenario(preset=preset, controller="none", duration_s=seconds, enable_at_s=0.0)
    session = SimSession(session_config(scenario, scenario.load_preset()))
    start = time.perf_counter()
    for _ in range(scenario.periods):
        session.run(1)
    return scenario.periods / (time.perf_counter() - start)


def bench_rate(preset: str, seconds: float = 60.0) -> float:
    scenario = Scenario(preset=preset, controller="soft_torque", duration_s=seconds,
                        enable_at_s=20.0)
    run = run_in_process(scenario)
    return scenario.periods / run.wall_s


def node_cpu_percent(preset: str, seconds: float) -> float:
    proc = start_node(preset, 1.0)
    try:
        time.sleep(5.0)                       # start-up and compilation out of the window
        c0, t0 = cpu_seconds(proc.pid), time.monotonic()
        time.sleep(seconds)
        return 100.0 * (cpu_seconds(proc.pid) - c0) / (time.monotonic() - t0)
    finally:
        stop(proc)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--node-seconds", type=float, default=20.0)
    parser.add_argument("--pairs", type=int, default=2)
    args = parser.parse_args()
    old = old_kernel()
    pairs = [kernel_ns_per_step(old) for _ in range(3)]
    print("(a) lumped kernel ns/step, 855bfb7 / this build: " + ", ".join(
        f"{o:.1f} / {n:.1f} ({n / o:.2f}x)" for o, n in pairs))
    for preset in PRESETS:                    # compile, warm up
        run_in_process(Scenario(preset=preset, controller="soft_torque", duration_s=1.0,
                                enable_at_s=0.0))
    for _ in range(args.pairs):
        rates = {p: (session_rate(p), bench_rate(p)) for p in PRESETS}
        d, lump = rates[PRESETS[0]], rates[PRESETS[1]]
        print(f"(b) session alone: distributed {d[0]:,.0f} periods/s ({d[0] / 100:.0f}x real "
              f"time), lumped {lump[0]:,.0f}; closed-loop bench (soft_torque): distributed "
              f"{d[1]:,.0f} periods/s ({d[1] / 100:.0f}x), lumped {lump[1]:,.0f} "
              f"({lump[1] / 100:.0f}x)")
    ratios = []
    for _ in range(args.pairs):
        lumped = node_cpu_percent(PRESETS[1], args.node_seconds)
        distributed = node_cpu_percent(PRESETS[0], args.node_seconds)
        ratios.append(distributed / lumped)
        print(f"(c) sim_node at 100 Hz real time: CPU distributed {distributed:.1f} %, lumped "
              f"{lumped:.1f} %, ratio {distributed / lumped:.2f}")
    print(f"(c) median ratio {statistics.median(ratios):.2f} (target <= 1.5)")


if __name__ == "__main__":
    main()
