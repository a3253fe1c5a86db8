"""rerun_bridge --save --connect when the viewer goes away mid-run: prints memory and stop time.

Runs the real sim_node (100 Hz telemetry, real time) and rerun_bridge on a private topic,
streaming to a viewer stand-in (rerun's SDK gRPC server in its own process, never the viewer:
tests/viz/viewer_standin.py). Prints the bridge's RSS growth with the viewer there and after
it is SIGKILLed, the bytes a second the viewer received, whether the bridge reconnects when
the stand-in listens again on the same port, and how long SIGINT takes to stop the bridge.
``--freeze`` stops the stand-in with SIGSTOP instead (it still accepts connections but reads
nothing), then kills it before the restart. ``--bridge-src DIR`` runs the bridge from another
source tree (e.g. an older commit's drill_sim_ros/ and config/ unpacked with ``git archive``)
for comparison. No asserts.
Usage: .venv/bin/python benchmarks/bench_viewer_loss.py [--seconds 30] [--bridge-src DIR]
"""

from __future__ import annotations

import argparse
import os
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
from drill_sim_ros.ros.closed_loop import ros_environment  # noqa: E402
from tests.process_probes import free_port, rss_bytes  # noqa: E402
from tests.viz.viewer_standin import ViewerStandIn  # noqa: E402

BIN = Path(sys.prefix) / "bin"
MIB = 1024 * 1024
STOP_WAIT_S = 30.0


def bridge_command(src: Path | None) -> list[str]:
    if src is None:
        return [str(BIN / "rerun_bridge")]
    code = (f"import sys; sys.path.insert(0, {str(src)!r}); "
            "from drill_sim_ros.viz.bridge_node import main; sys.exit(main(sys.argv))")
    return [sys.executable, "-c", code]


def wait_for(log: Path, text: str, timeout_s: float) -> bool:
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        if text in log.read_text():
            return True
        time.sleep(0.1)
    return False


def growth_mib_min(pid: int, seconds: float) -> float:
    """RSS growth of ``pid`` over ``seconds``, MiB a minute."""
    before = rss_bytes(pid)
    time.sleep(seconds)
    return (rss_bytes(pid) - before) / MIB * 60.0 / seconds


def run(seconds: float, src: Path | None, freeze: bool, workdir: Path) -> None:
    env, topic = ros_environment(), f"/bench_{os.getpid()}/telemetry"
    remap = ["--ros-args", "-r", f"/drill/telemetry:={topic}"]
    viewer = ViewerStandIn(free_port())
    viewer.start()
    log_path = workdir / "bridge.log"
    log = log_path.open("w")
    bridge = subprocess.Popen([*bridge_command(src), "--save", str(workdir / "b.rrd"),
                               "--connect", viewer.url, *remap], env=env, stdout=log,
                              stderr=subprocess.STDOUT)
    sim = subprocess.Popen([str(BIN / "sim_node"), *remap, "-p", "status_line:=false",
                            "-p", f"run_seconds:={3 * seconds + 40}"], env=env,
                           stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        time.sleep(8.0)                                  # imports, discovery, JIT warm-up
        received = viewer.bytes_received()
        alive = growth_mib_min(bridge.pid, seconds)
        rate_kib_s = (viewer.bytes_received() - received) / 1024 / seconds
        viewer.freeze() if freeze else viewer.kill()
        time.sleep(2.5)                                  # one check period and a flush
        away = growth_mib_min(bridge.pid, seconds)
        viewer.kill()
        viewer.start()
        back = wait_for(log_path, ": streaming from sim_time", 10.0)
        again = viewer.wait_receiving(int(rate_kib_s * 1024 * 3), 10.0) / 1024
        start = time.monotonic()
        bridge.send_signal(signal.SIGINT)
        try:
            code: int | str = bridge.wait(timeout=STOP_WAIT_S)
        except subprocess.TimeoutExpired:
            code = f"none: still running after {STOP_WAIT_S:g} s, killed"
        stop_s = time.monotonic() - start
    finally:
        for proc in (sim, bridge):
            if proc.poll() is None:
                proc.kill()
                proc.wait(timeout=10)
        viewer.kill()
        log.close()
    text = log_path.read_text()
    print(f"bridge from {src or 'this tree'}: RSS growth {alive:+.2f} MiB/min with the viewer "
          f"({rate_kib_s:.1f} KiB/s reached it), {away:+.2f} MiB/min after it was "
          f"{'frozen' if freeze else 'killed'}; "
          f"viewer warnings {text.count('no longer streamed there')}, "
          f"reconnected: {'yes' if back else 'no'} "
          f"({again:.0f} KiB received again); SIGINT stop {stop_s:.2f} s, rc {code}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=30.0,
                        help="length of each phase (viewer there, viewer gone), s")
    parser.add_argument("--bridge-src", type=Path, default=None)
    parser.add_argument("--freeze", action="store_true",
                        help="SIGSTOP the viewer instead of killing it")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        run(args.seconds, args.bridge_src, args.freeze, Path(tmp))


if __name__ == "__main__":
    main()
