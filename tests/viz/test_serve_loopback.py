"""``--serve`` hosts rerun's gRPC server on 127.0.0.1 only, never 0.0.0.0."""

from __future__ import annotations

import socket
import time
from pathlib import Path

import pytest

from drill_sim_ros.viz.blueprint import build_blueprint
from drill_sim_ros.viz.frames import Extents, view_frames
from drill_sim_ros.viz.paper_units import PaperUnits
from drill_sim_ros.viz.recording import close_recording, open_recording
from tests.viz.bridge_process import BridgeProcess

LISTEN = "0A"


def free_port() -> int:
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return sock.getsockname()[1]


def listening_addresses(port: int) -> set[str]:
    """Hex local addresses (as in /proc/net/tcp*) listening on ``port``."""
    found = set()
    for table in ("/proc/net/tcp", "/proc/net/tcp6"):
        for line in Path(table).read_text().splitlines()[1:]:
            fields = line.split()
            address, port_hex = fields[1].rsplit(":", 1)
            if int(port_hex, 16) == port and fields[3] == LISTEN:
                found.add(address)
    return found


def wait_listening(port: int, timeout_s: float) -> set[str]:
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        if found := listening_addresses(port):
            return found
        time.sleep(0.05)
    return set()


def test_open_recording_serves_on_loopback_only() -> None:
    port = free_port()
    frames = view_frames(PaperUnits.load("fig5_8a"), Extents.typical())
    rec = open_recording(build_blueprint(10.0, frames), serve_port=port)
    try:
        assert wait_listening(port, 10.0) == {"0100007F"}   # 127.0.0.1, no 0.0.0.0 or ::
    finally:
        close_recording(rec)


@pytest.mark.ros
def test_rerun_bridge_serve_binds_loopback(tmp_path: Path) -> None:
    port = free_port()
    bridge = BridgeProcess("--serve", "--serve-port", str(port))
    try:
        assert bridge.wait_ready(30.0), bridge.output()
        found = wait_listening(port, 10.0)
    finally:
        code = bridge.stop()
    assert found == {"0100007F"}, bridge.output()
    assert code == 0, bridge.output()
