"""A stand-in for a rerun viewer: rerun's SDK gRPC server on 127.0.0.1, in its own process.

Never the viewer or the rerun CLI (they send usage analytics on a first run): the process
hosts a ``GrpcServerSink`` (the server a viewer runs, which accepts what SDKs push), after
turning analytics off as the bridge does. What it received is read from the kernel
(``ss``: bytes received on its established connections).

Run as ``python -m tests.viz.viewer_standin PORT``.
"""

from __future__ import annotations

import re
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

from tests.process_probes import wait_listening

READY = "listening"
ROOT = Path(__file__).resolve().parents[2]


class ViewerStandIn:
    """``python -m tests.viz.viewer_standin PORT`` as a subprocess."""

    def __init__(self, port: int) -> None:
        self.port = port
        self.url = f"rerun+http://127.0.0.1:{port}/proxy"
        self.proc: subprocess.Popen | None = None

    def start(self, timeout_s: float = 20.0) -> None:
        self.proc = subprocess.Popen([sys.executable, "-m", "tests.viz.viewer_standin",
                                      str(self.port)], cwd=ROOT, stdout=subprocess.DEVNULL,
                                     stderr=subprocess.DEVNULL)
        if not wait_listening(self.port, timeout_s):
            self.kill()
            raise RuntimeError(f"viewer stand-in not listening on {self.port}")

    def kill(self) -> None:
        """SIGKILL, as a crashed or force-closed viewer."""
        if self.proc is not None and self.proc.poll() is None:
            self.proc.kill()
            self.proc.wait(timeout=10)
        self.proc = None

    def freeze(self) -> None:
        """SIGSTOP: still accepts connections (the kernel does), reads nothing."""
        self.proc.send_signal(signal.SIGSTOP)

    def bytes_received(self) -> int:
        """Bytes received so far on the server's established connections (from ``ss``)."""
        exe = shutil.which("ss")
        if exe is None:
            raise RuntimeError("ss (iproute2) is not installed")
        out = subprocess.run([exe, "-tinH", "state", "established",
                              f"( sport = :{self.port} )"], capture_output=True, text=True,
                             timeout=10, check=True).stdout
        return sum(int(n) for n in re.findall(r"bytes_received:(\d+)", out))

    def wait_receiving(self, min_bytes: int, timeout_s: float) -> int:
        """Until the server has received ``min_bytes`` (bounded); the bytes received."""
        deadline = time.monotonic() + timeout_s
        while (received := self.bytes_received()) < min_bytes and time.monotonic() < deadline:
            time.sleep(0.1)
        return received


def serve(port: int) -> None:
    import rerun as rr

    from drill_sim_ros.viz.analytics_off import disable_analytics
    disable_analytics()
    rec = rr.RecordingStream("viewer_standin")
    rec.set_sinks(rr.GrpcServerSink(bind_ip="127.0.0.1", port=port))
    print(READY, flush=True)
    signal.sigwait({signal.SIGTERM, signal.SIGINT})


if __name__ == "__main__":
    signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGTERM, signal.SIGINT})
    serve(int(sys.argv[1]))
