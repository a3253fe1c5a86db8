"""The real sim_node -> rerun_bridge --save, checked against an independent subscriber."""

from __future__ import annotations

import importlib.util
import signal
import subprocess
import sys
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

from drill_sim_ros import topics
from drill_sim_ros.model.presets import DEFAULT_PRESET, load_preset
from tests.viz import expected as ex
from tests.viz.bridge_process import BridgeProcess, private_topic, remap_telemetry
from tests.viz.rrd_read import read_recording, view_origins

pytestmark = [
    pytest.mark.ros,
    pytest.mark.skipif(importlib.util.find_spec("drill_sim_ros.ros.sim_node") is None,
                       reason="sim_node not written yet"),
]
F = topics.TELEMETRY_INDEX
WANTED = 100                 # samples both subscribers must have before the sim stops


def start_sim_node(topic: str) -> subprocess.Popen:
    exe = Path(sys.prefix) / "bin" / "sim_node"
    args = [*remap_telemetry(topic), "-p", "status_line:=false", "-p", "publish_clock:=false"]
    return subprocess.Popen([str(exe), *args], stdout=subprocess.DEVNULL,
                            stderr=subprocess.PIPE, text=True)


def wait_until(condition: Callable[[], bool], timeout_s: float) -> bool:
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline and not condition():
        time.sleep(0.1)
    return condition()


def stop(proc: subprocess.Popen) -> int:
    proc.send_signal(signal.SIGINT)
    try:
        return proc.wait(timeout=20)
    except subprocess.TimeoutExpired:
        proc.kill()
        return proc.wait(timeout=5)


def test_sim_node_telemetry_reaches_the_rrd(tmp_path: Path) -> None:
    """Discovery across processes takes 0.1-3 s here, so the sim runs until both listen."""
    from tests.viz.telemetry_listener import TelemetryListener

    topic, rrd = private_topic(), tmp_path / "sim.rrd"
    bridge = BridgeProcess("--save", str(rrd), *remap_telemetry(topic))
    listener = TelemetryListener(topic)
    sim = None
    try:
        assert bridge.wait_ready(30.0), bridge.output()
        sim = start_sim_node(topic)
        assert wait_until(lambda: len(listener.rows) >= WANTED and bridge.logged() >= WANTED,
                          40.0), bridge.output()
        assert stop(sim) == 0, sim.stderr.read()
        time.sleep(0.5)                       # the last messages reach both subscribers
    finally:
        if sim is not None and sim.poll() is None:
            sim.kill()
        heard = listener.close()
        code = bridge.stop(signum=signal.SIGTERM)
    assert code == 0, bridge.output()
    logged = read_recording(rrd)["/timeseries/rpm/bit"]
    t_logged = logged.time_ns
    t_heard = np.round(heard[:, F["sim_time_s"]] * 1e9).astype(np.int64)
    # both had discovered the sim by then; the .rrd's times may lie 1 ns below the stamps
    # (rerun's float seconds), so a first sample logged at stamp - 1 ns still counts
    start = max(t_logged[0], t_heard[0]) - 1
    keep = t_heard >= start
    np.testing.assert_allclose(t_logged[t_logged >= start], t_heard[keep], atol=1)
    np.testing.assert_array_equal(logged.scalars()[t_logged >= start],
                                  heard[keep, F["bit_rpm"]])
    assert set(ex.SCALARS) <= set(read_recording(rrd))
    # the default preset's string is distributed: its profiles at 10 Hz of sim time, as
    # StringProfile (string.message typed, the default): over their depths in m, not the
    # 0.1 m of JointState names
    bars = read_recording(rrd)["/string/speed"]
    assert len(bars.time_ns) >= 3 and np.all(bars.time_ns % 100_000_000 == 0)
    length_m = load_preset(DEFAULT_PRESET).string.length_m
    depths_m = (np.arange(64) + 0.5) * length_m / 64
    assert not np.allclose(depths_m, np.round(depths_m, 1))
    np.testing.assert_allclose(bars.columns["BarChart:abscissa"][-1][0]["buffer"], depths_m,
                               rtol=1e-12)
    assert {"/string/depth_time", "/string/speed"} <= set(view_origins(rrd).values())
