"""The issue-35 figures in one run: every script below, one after the other, on this machine
(prints, no asserts; the figures of docs/benchmarks.md "In one run").

Each script prints its own figures as ratios against a reference measured beside them; this
one runs them in sequence, with the commit, the time and the load average before each, so
that one sitting gives one comparable set:
- kernel ns/step against the naive reference step (bench_kernel.py);
- sim_node's free run, distributed and lumped, each against a bare rclpy publisher of the
  same topics, and its CPU at 100 Hz real time against that publisher, beside the floors of
  a Python node (that publisher plus the simulation's own work; bench_node.py --floors);
- the closed-loop bench in process, both strings (bench_closed_loop.py);
- the gym's steps/s on every shipped scenario (bench_gym.py).
Usage: .venv/bin/python benchmarks/bench_summary.py
"""

from __future__ import annotations

import datetime
import os
import subprocess
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
RUNS = (
    ("kernel ns/step / the naive step", ["bench_kernel.py", "--repeats", "3"]),
    ("sim_node on the distributed default: real time and free run against the bare "
     "publisher; (e) the string profiles and the lumped twin",
     ["bench_node.py", "--pairs", "2", "--floors"]),
    ("sim_node on the lumped twin against the bare publisher",
     ["bench_node.py", "--preset", "field_8p5in_shale_lumped", "--pairs", "2",
      "--rounds", "0"]),
    ("closed-loop bench in process, both strings",
     ["bench_closed_loop.py", "--dds-seconds", "0"]),
    ("gym steps/s per scenario", ["bench_gym.py"]),
)


def commit() -> str:
    """The checkout's commit (and + when it has changes), or '?' outside git."""
    try:
        head = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=HERE, text=True,
                              capture_output=True, check=True, timeout=10).stdout.strip()
        dirty = subprocess.run(["git", "status", "--porcelain"], cwd=HERE, text=True,
                               capture_output=True, timeout=10).stdout.strip()
    except (OSError, subprocess.SubprocessError):
        return "?"
    return head + ("+" if dirty else "")


def cpu_model() -> str:
    """The processor's model name (/proc/cpuinfo), or '?': figures differ between VMs."""
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return "?"


def header(title: str) -> str:
    now = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M:%S UTC")
    load = " ".join(f"{x:.2f}" for x in os.getloadavg())
    return f"\n== {title}  [{now}, load average {load}]"


def main() -> int:
    print(f"drill_sim_ros benchmarks in one run: commit {commit()}, {os.cpu_count()} cores "
          f"({cpu_model()}), Python {sys.version.split()[0]}")
    failed = []
    for title, argv in RUNS:
        print(header(title), flush=True)
        result = subprocess.run([sys.executable, str(HERE / argv[0]), *argv[1:]], timeout=3600)
        if result.returncode != 0:
            failed.append(argv[0])
    print(header("done") + (f"; failed: {', '.join(failed)}" if failed else ""))
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
