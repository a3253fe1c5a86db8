"""``--serve`` hosts rerun's gRPC server on 127.0.0.1 only, never 0.0.0.0."""

from __future__ import annotations

from pathlib import Path

import pytest

from drill_sim_ros.viz.blueprint import build_blueprint
from drill_sim_ros.viz.frames import Extents, view_frames
from drill_sim_ros.viz.paper_units import PaperUnits
from drill_sim_ros.viz.recording import close_recording, open_recording
from tests.process_probes import free_port, wait_listening
from tests.viz.bridge_process import BridgeProcess


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
