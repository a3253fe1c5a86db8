"""CPU use of rerun_bridge at the sim's default rates: prints % of one core (no asserts).

Runs the real sim_node (100 Hz telemetry, real time) and rerun_bridge --save on a private
topic, and reads the bridge's CPU time from /proc/<pid>/stat over a steady interval.
Usage: .venv/bin/python benchmarks/bench_bridge.py [--seconds 20] [--flush-hz 4]
"""

from __future__ import annotations

import argparse
import os
import re
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))   # for tests.process_probes
from drill_sim_ros.ros.closed_loop import ros_environment
from tests.process_probes import cpu_seconds

BIN = Path(sys.prefix) / "bin"


def logged(text: str) -> int:
    counts = [int(n) for n in re.findall(r"(\d+) telemetry samples logged", text)]
    return max(counts, default=0)


def measure(seconds: float, flush_hz: float, workdir: Path) -> tuple[float, float, int]:
    """(bridge CPU %, sim_node CPU %, samples logged) over ``seconds`` of steady running."""
    env, topic = ros_environment(), f"/bench_{os.getpid()}/telemetry"
    remap = ["--ros-args", "-r", f"/drill/telemetry:={topic}"]
    log = (workdir / "bridge.log").open("w")
    bridge = subprocess.Popen([str(BIN / "rerun_bridge"), "--save", str(workdir / "b.rrd"),
                               "--flush-hz", str(flush_hz), *remap], env=env,
                              stdout=log, stderr=subprocess.STDOUT)
    sim = subprocess.Popen([str(BIN / "sim_node"), *remap, "-p", "status_line:=false",
                            "-p", f"run_seconds:={seconds + 8.0}"], env=env,
                           stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        time.sleep(5.0)                                   # imports, discovery, JIT warm-up
        b0, s0, w0 = cpu_seconds(bridge.pid), cpu_seconds(sim.pid), time.monotonic()
        time.sleep(seconds)
        b1, s1, w1 = cpu_seconds(bridge.pid), cpu_seconds(sim.pid), time.monotonic()
    finally:
        for proc in (sim, bridge):
            if proc.poll() is None:
                proc.send_signal(signal.SIGINT)
        for proc in (sim, bridge):
            try:
                proc.wait(timeout=20)
            except subprocess.TimeoutExpired:
                proc.kill()
        log.close()
    wall = w1 - w0
    text = (workdir / "bridge.log").read_text()
    return 100.0 * (b1 - b0) / wall, 100.0 * (s1 - s0) / wall, logged(text)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=20.0)
    parser.add_argument("--flush-hz", type=float, default=4.0)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        bridge, sim, count = measure(args.seconds, args.flush_hz, Path(tmp))
    print(f"rerun_bridge at sim defaults (100 Hz telemetry, flush {args.flush_hz:g} Hz): "
          f"{bridge:.2f} % of one core over {args.seconds:g} s "
          f"(sim_node {sim:.1f} %, {count} samples logged)")


if __name__ == "__main__":
    main()
