"""Screenshot a recorded run's dashboard the way a user sees it: rerun's web viewer on
127.0.0.1, rendered in headless Chromium, saved as PNGs (default 1600x1000 and 2560x1440).

    .venv/bin/python docs/render_dashboard.py RUN.rrd [-o docs/img] [--wait-s 60]

Needs Debian's chromium (`apt-get install -y chromium`) and, once,
`npm install --prefix docs/screenshots` (puppeteer-core; node_modules is not committed).
rerun's analytics are turned off and read back from rerun itself before the viewer starts.
"""

from __future__ import annotations

import argparse
import os
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path
from urllib.parse import quote

from drill_sim_ros.viz.analytics_off import disable_analytics, rerun_reads_disabled

HERE = Path(__file__).resolve().parent
SHOT_JS = HERE / "screenshots" / "shot.mjs"
LOOPBACK = "127.0.0.1"
SIZES = ("1600x1000", "2560x1440")


def free_port() -> int:
    with socket.socket() as sock:
        sock.bind((LOOPBACK, 0))
        return sock.getsockname()[1]


def wait_listening(port: int, timeout_s: float) -> None:
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        with socket.socket() as sock:
            if sock.connect_ex((LOOPBACK, port)) == 0:
                return
        time.sleep(0.2)
    raise TimeoutError(f"nothing listens on {LOOPBACK}:{port} after {timeout_s} s")


def serve(rrd: Path, web_port: int, grpc_port: int) -> subprocess.Popen:
    """rerun's web viewer for ``rrd``, bound to 127.0.0.1 (HTTP and gRPC), in its own
    process group (the CLI wrapper starts the viewer binary as a child). BROWSER=true: the
    viewer's own attempt to open a browser does nothing; the screenshot browser is ours."""
    rerun = Path(sys.executable).with_name("rerun")
    return subprocess.Popen([str(rerun), "--web-viewer", "--bind", LOOPBACK,
                             "--web-viewer-port", str(web_port), "--port", str(grpc_port),
                             str(rrd)], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                            env={**os.environ, "BROWSER": "true"}, start_new_session=True)


def stop(viewer: subprocess.Popen) -> None:
    """End the viewer's process group (the wrapper and the binary), then reap the wrapper."""
    try:
        os.killpg(viewer.pid, signal.SIGTERM)
        viewer.wait(timeout=10)
    except (ProcessLookupError, subprocess.TimeoutExpired):
        os.killpg(viewer.pid, signal.SIGKILL)
        viewer.wait(timeout=5)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("rrd", type=Path)
    parser.add_argument("-o", "--out-dir", type=Path, default=HERE / "img")
    parser.add_argument("--name", default="dashboard", help="PNG name stem")
    parser.add_argument("--wait-s", type=float, default=60.0)
    parser.add_argument("--sizes", nargs="+", default=list(SIZES), metavar="WxH")
    args = parser.parse_args(argv)
    disable_analytics()
    if not rerun_reads_disabled():
        print("render_dashboard: rerun does not read its analytics as off; not starting it",
              file=sys.stderr)
        return 1
    if not (HERE / "screenshots" / "node_modules").exists():
        print("render_dashboard: run `npm install --prefix docs/screenshots` first",
              file=sys.stderr)
        return 1
    args.out_dir.mkdir(parents=True, exist_ok=True)
    web_port, grpc_port = free_port(), free_port()
    viewer = serve(args.rrd, web_port, grpc_port)
    try:
        wait_listening(web_port, 30.0)
        wait_listening(grpc_port, 30.0)
        source = quote(f"rerun+http://{LOOPBACK}:{grpc_port}/proxy", safe="")
        url = f"http://{LOOPBACK}:{web_port}/?url={source}"
        shots = [f"{args.out_dir / f'{args.name}_{size}.png'}:{size}" for size in args.sizes]
        subprocess.run(["node", str(SHOT_JS), url, str(args.wait_s), *shots], check=True,
                       timeout=args.wait_s + 120)
    finally:
        stop(viewer)
    return 0


if __name__ == "__main__":
    sys.exit(main())
