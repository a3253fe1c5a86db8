"""rerun_bridge --connect: a viewer that goes away (or stops reading) mid-run is cut (one
warning, memory bounded, the .rrd complete, SIGINT still stops the bridge) and reconnected
when one listens again at the URL.

The viewer is a stand-in (tests/viz/viewer_standin.py: rerun's SDK gRPC server in its own
process), killed with SIGKILL (or stopped with SIGSTOP) and restarted on the same port.
"""

from __future__ import annotations

import signal
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from drill_sim_ros.model.presets import load_preset
from tests.process_probes import free_port, rss_bytes
from tests.viz.bridge_process import BridgeProcess, private_topic, remap_telemetry
from tests.viz.rrd_read import read_recording
from tests.viz.sim_telemetry import telemetry_rows
from tests.viz.telemetry_publisher import TelemetryPublisher
from tests.viz.viewer_standin import ViewerStandIn

pytestmark = pytest.mark.ros

RATE_HZ = 400.0          # 4x the sim's default telemetry rate: more to buffer, sooner
AWAY_S = 8.0             # how long the bridge runs on without a viewer (4 checks)
STATIC_BYTES = 10_000     # far more than a gRPC handshake; the layout and static views
GONE = "stopped listening"
BACK = ": streaming from sim_time"


def wait_output(bridge: BridgeProcess, text: str, timeout_s: float) -> bool:
    deadline = time.monotonic() + timeout_s
    while text not in bridge.output() and time.monotonic() < deadline:
        time.sleep(0.05)
    return text in bridge.output()


def run_on(bridge: BridgeProcess, viewer: ViewerStandIn | None, seconds: float,
           ) -> tuple[int, int, float]:
    """Over ``seconds``: (the bridge's RSS growth, bytes; samples it logged; bytes a second
    the viewer received, 0 without one)."""
    pid = bridge.proc.pid
    rss, logged, start = rss_bytes(pid), bridge.logged(), time.monotonic()
    received = viewer.bytes_received() if viewer else 0
    time.sleep(seconds)
    rate = (viewer.bytes_received() - received) / (time.monotonic() - start) if viewer else 0.0
    return rss_bytes(pid) - rss, bridge.logged() - logged, rate


def warnings(bridge: BridgeProcess) -> list[str]:
    return [line for line in bridge.lines if "[WARN]" in line and "[rerun_bridge]" in line]


@dataclass
class LiveRun:
    """A viewer stand-in listening, a bridge saving ``rrd`` and streaming to it, and a feeder
    publishing ``rows`` at RATE_HZ, the bridge already logging; ``code``: the bridge's exit
    status once the ``with`` block has ended."""

    rows: np.ndarray
    rrd: Path
    viewer: ViewerStandIn
    bridge: BridgeProcess
    feeder: threading.Thread
    code: int | None = None

    def feed_to_the_end(self) -> None:
        """Wait for the feeder to publish every row and the bridge to log them all."""
        self.feeder.join(timeout=60.0)
        assert not self.feeder.is_alive()
        assert self.bridge.wait_logged(len(self.rows), 30.0), self.bridge.output()


@contextmanager
def live_run(tmp_path: Path, sim_seconds: float, **stop: Any) -> Iterator[LiveRun]:
    """Start a :class:`LiveRun` of ``sim_seconds`` of the field preset's telemetry; at the
    end close the publisher, stop the bridge (``stop``: BridgeProcess.stop's arguments) and
    kill the viewer."""
    rows = telemetry_rows(load_preset("field_8p5in_shale_lumped"), sim_seconds)
    viewer = ViewerStandIn(free_port())
    viewer.start()
    topic = private_topic()
    rrd = tmp_path / "live.rrd"
    bridge = BridgeProcess("--save", str(rrd), "--connect", viewer.url, *remap_telemetry(topic))
    publisher = TelemetryPublisher(topic)
    feeder = threading.Thread(target=publisher.publish, args=(rows, RATE_HZ), daemon=True)
    run = LiveRun(rows, rrd, viewer, bridge, feeder)
    try:
        assert publisher.wait_for_subscriber(30.0), bridge.output()
        feeder.start()
        assert bridge.wait_logged(400, 30.0), bridge.output()
        yield run
    finally:
        publisher.close()
        run.code = bridge.stop(**stop)
        viewer.kill()


def test_a_viewer_gone_mid_run_is_cut_then_reconnected(tmp_path: Path) -> None:
    with live_run(tmp_path, 120.0, signum=signal.SIGINT) as run:    # 30 s at RATE_HZ
        bridge, viewer, rows = run.bridge, run.viewer, run.rows
        growth_with_viewer, _, streamed_bytes_s = run_on(bridge, viewer, AWAY_S)

        viewer.kill()
        assert wait_output(bridge, GONE, 10.0), bridge.output()
        growth_away, logged_away, _ = run_on(bridge, None, AWAY_S)

        viewer.start()
        assert wait_output(bridge, BACK, 10.0), bridge.output()
        received = viewer.wait_receiving(int(streamed_bytes_s), 10.0)
        run.feed_to_the_end()
    code, rrd = run.code, run.rrd
    out = bridge.output()
    assert code == 0, out
    assert "Traceback" not in out
    # Telemetry kept flowing while no viewer listened, and memory did not follow it: a client
    # buffering for the lost viewer would hold at least what the viewer used to receive.
    assert logged_away >= 0.5 * RATE_HZ * AWAY_S, out
    buffered_bytes = streamed_bytes_s * AWAY_S
    assert buffered_bytes > 1e6, streamed_bytes_s                   # the bound is meaningful
    assert growth_away < growth_with_viewer + 0.5 * buffered_bytes, (
        growth_away, growth_with_viewer, buffered_bytes)
    assert [GONE in line for line in warnings(bridge)] == [True], out
    assert viewer.url in warnings(bridge)[0] and "live.rrd continues" in warnings(bridge)[0]
    assert out.count(BACK) == 1 and "lacks up to" in out, out
    assert received >= streamed_bytes_s, received              # data reaches the new viewer
    assert len(read_recording(rrd)["/timeseries/rop/bit"].time_ns) == len(rows)


def test_a_viewer_started_after_the_bridge_is_connected(tmp_path: Path) -> None:
    rows = telemetry_rows(load_preset("field_8p5in_shale_lumped"), 12.0)
    viewer = ViewerStandIn(free_port())
    topic = private_topic()
    bridge = BridgeProcess("--save", str(tmp_path / "live.rrd"), "--connect", viewer.url,
                           *remap_telemetry(topic))
    publisher = TelemetryPublisher(topic)
    try:
        assert publisher.wait_for_subscriber(30.0), bridge.output()
        publisher.publish(rows, rate_hz=RATE_HZ)
        assert bridge.wait_logged(len(rows), 30.0), bridge.output()
        viewer.start()
        assert wait_output(bridge, BACK, 10.0), bridge.output()
        received = viewer.wait_receiving(STATIC_BYTES, 10.0)
    finally:
        publisher.close()
        code = bridge.stop()
        viewer.kill()
    out = bridge.output()
    assert code == 0, out
    assert [("no viewer listening" in line) for line in warnings(bridge)] == [True], out
    assert f"lacks up to {len(rows)} samples" in out, out
    assert received >= STATIC_BYTES, received           # the layout and static views


def test_a_viewer_that_stops_reading_is_cut_and_the_bridge_still_stops(tmp_path: Path) -> None:
    # 25 s at RATE_HZ; SIGINT must stop the bridge within 10 s, else SIGKILL: rc -9
    with live_run(tmp_path, 100.0, timeout_s=10.0, signum=signal.SIGINT) as run:
        bridge, rows = run.bridge, run.rows
        growth_with_viewer, _, streamed_bytes_s = run_on(bridge, run.viewer, AWAY_S)

        run.viewer.freeze()
        assert wait_output(bridge, "does not read", 10.0), bridge.output()
        growth_frozen, logged_frozen, _ = run_on(bridge, None, AWAY_S)
        run.feed_to_the_end()
    code, rrd = run.code, run.rrd
    out = bridge.output()
    assert code == 0, out
    assert logged_frozen >= 0.5 * RATE_HZ * AWAY_S, out
    assert growth_frozen < growth_with_viewer + 0.5 * streamed_bytes_s * AWAY_S, (
        growth_frozen, growth_with_viewer, streamed_bytes_s)
    assert [("does not read" in line) for line in warnings(bridge)] == [True], out
    assert len(read_recording(rrd)["/timeseries/rop/bit"].time_ns) == len(rows)


def test_a_viewer_restarted_at_once_is_reconnected(tmp_path: Path) -> None:
    with live_run(tmp_path, 60.0) as run:                             # 15 s at RATE_HZ
        bridge, viewer = run.bridge, run.viewer
        viewer.kill()
        viewer.start()          # back within about 2 s: a probe or the failed flush notices
        assert wait_output(bridge, BACK, 10.0), bridge.output()
        received = viewer.wait_receiving(STATIC_BYTES, 10.0)
        run.feeder.join(timeout=60.0)
    code = run.code
    out = bridge.output()
    assert code == 0, out
    assert len(warnings(bridge)) == 1 and out.count(BACK) == 1, out
    assert received >= STATIC_BYTES, received
