"""Run the ``rerun_bridge`` console script as a subprocess and watch its status line."""

from __future__ import annotations

import os
import re
import signal
import subprocess
import sys
import threading
import time
import uuid
from pathlib import Path

STATUS = re.compile(r"(\d+) telemetry samples logged")


def private_topic(name: str = "telemetry") -> str:
    """A topic no other session on this machine uses (domain ids can collide)."""
    return f"/viz_test_{os.getpid()}_{uuid.uuid4().hex[:8]}/{name}"


def remap_telemetry(topic: str) -> list[str]:
    """ROS arguments that move the node's /drill/telemetry to ``topic``."""
    return ["--ros-args", "-r", f"/drill/telemetry:={topic}"]


class BridgeProcess:
    """``rerun_bridge *args``; stderr is drained by a thread so the pipe never fills."""

    def __init__(self, *args: str) -> None:
        exe = Path(sys.prefix) / "bin" / "rerun_bridge"
        self.proc = subprocess.Popen([str(exe), *args], stdout=subprocess.PIPE,
                                     stderr=subprocess.STDOUT, text=True)
        self.lines: list[str] = []
        self._reader = threading.Thread(target=self._drain, daemon=True)
        self._reader.start()

    def _drain(self) -> None:
        for line in self.proc.stdout:
            self.lines.append(line)

    def logged(self) -> int:
        counts = [int(m.group(1)) for line in list(self.lines) if (m := STATUS.search(line))]
        return max(counts, default=0)

    def wait_ready(self, timeout_s: float) -> bool:
        """Until the node has subscribed and is about to spin."""
        deadline = time.monotonic() + timeout_s
        while time.monotonic() < deadline and self.proc.poll() is None:
            if "ready:" in self.output():
                return True
            time.sleep(0.05)
        return "ready:" in self.output()

    def wait_logged(self, count: int, timeout_s: float) -> bool:
        deadline = time.monotonic() + timeout_s
        while time.monotonic() < deadline and self.proc.poll() is None:
            if self.logged() >= count:
                return True
            time.sleep(0.1)
        return self.logged() >= count

    def stop(self, timeout_s: float = 20.0, signum: int = signal.SIGINT) -> int:
        """``signum``, then SIGKILL if it does not exit in time; return the exit code."""
        if self.proc.poll() is None:
            self.proc.send_signal(signum)
            try:
                self.proc.wait(timeout=timeout_s)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait(timeout=5)
        self._reader.join(timeout=5)
        return self.proc.returncode

    def output(self) -> str:
        return "".join(self.lines)


def bridge_logs(rows, *args: str, signum: int = signal.SIGINT) -> tuple[BridgeProcess, int]:
    """Start ``rerun_bridge *args`` on a private topic, publish ``rows`` to it at 400 Hz, wait
    until it logged them all (bounded), stop it with ``signum``: (the bridge, its exit code)."""
    from tests.viz.telemetry_publisher import TelemetryPublisher
    topic = private_topic()
    bridge = BridgeProcess(*args, *remap_telemetry(topic))
    publisher = TelemetryPublisher(topic)
    try:
        assert publisher.wait_for_subscriber(30.0), bridge.output()
        publisher.publish(rows, rate_hz=400.0)
        assert bridge.wait_logged(len(rows), 30.0), bridge.output()
    finally:
        publisher.close()
        code = bridge.stop(signum=signum)
    return bridge, code
