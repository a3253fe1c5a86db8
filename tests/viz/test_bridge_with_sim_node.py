"""The real sim_node -> rerun_bridge --save, checked against an independent subscriber."""

from __future__ import annotations

import importlib.util
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from drill_sim_ros import topics
from tests.viz import expected as ex
from tests.viz.bridge_process import BridgeProcess, private_topic, remap_telemetry
from tests.viz.rrd_read import read_recording

pytestmark = [
    pytest.mark.ros,
    pytest.mark.skipif(importlib.util.find_spec("drill_sim_ros.ros.sim_node") is None,
                       reason="sim_node not written yet"),
]
F = topics.TELEMETRY_INDEX
RUN_SECONDS = 3.0


def run_sim_node(topic: str) -> subprocess.CompletedProcess:
    exe = Path(sys.prefix) / "bin" / "sim_node"
    args = [*remap_telemetry(topic), "-p", f"run_seconds:={RUN_SECONDS}",
            "-p", "status_line:=false", "-p", "publish_clock:=false"]
    return subprocess.run([str(exe), *args], capture_output=True, text=True, timeout=60,
                          check=False)


def test_sim_node_telemetry_reaches_the_rrd(tmp_path: Path) -> None:
    from tests.viz.telemetry_listener import TelemetryListener

    topic, rrd = private_topic(), tmp_path / "sim.rrd"
    bridge = BridgeProcess("--save", str(rrd), *remap_telemetry(topic))
    listener = TelemetryListener(topic)
    try:
        assert bridge.wait_ready(30.0), bridge.output()
        sim = run_sim_node(topic)
        assert sim.returncode == 0, sim.stderr
        time.sleep(0.5)                       # the last messages reach both subscribers
    finally:
        heard = listener.close()
        code = bridge.stop()
    assert code == 0, bridge.output()
    assert len(heard) >= 50, "the sim's first samples precede discovery; most must arrive"
    logged = read_recording(rrd)["/timeseries/rpm/bit"]
    t_logged = logged.time_ns
    t_heard = np.round(heard[:, F["sim_time_s"]] * 1e9).astype(np.int64)
    start = max(t_logged[0], t_heard[0])      # both joined by then (discovery is racy)
    keep = t_heard >= start
    np.testing.assert_allclose(t_logged[t_logged >= start], t_heard[keep], atol=1)
    np.testing.assert_array_equal(logged.scalars()[t_logged >= start],
                                  heard[keep, F["bit_rpm"]])
    assert set(ex.SCALARS) <= set(read_recording(rrd))
