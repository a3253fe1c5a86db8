"""rerun_bridge faults: no viewer listening, a busy or invalid --serve port or memory limit,
SIGHUP (a viewer lost mid-run: test_bridge_viewer_watchdog.py)."""

from __future__ import annotations

import signal
import socket
import subprocess
import sys
from pathlib import Path

import pytest

from drill_sim_ros.model.presets import load_preset
from tests.process_probes import free_port
from tests.viz.bridge_process import bridge_logs
from tests.viz.rrd_read import read_recording
from tests.viz.sim_telemetry import telemetry_rows

pytestmark = pytest.mark.ros


def _bridge(*args: str) -> subprocess.CompletedProcess:
    exe = Path(sys.prefix) / "bin" / "rerun_bridge"
    return subprocess.run([str(exe), *args], capture_output=True, text=True, timeout=60)


def _nowhere() -> str:
    return f"rerun+http://127.0.0.1:{free_port()}/proxy"


def test_no_viewer_and_no_other_sink_is_one_line_at_start() -> None:
    done = _bridge("--connect", _nowhere())
    assert done.returncode == 2 and "Traceback" not in done.stderr
    lines = [line for line in (done.stdout + done.stderr).splitlines() if line.strip()]
    assert len(lines) == 1 and "no viewer listening" in lines[0], lines


def test_a_busy_serve_port_fails_at_start() -> None:
    with socket.socket() as busy:
        busy.bind(("127.0.0.1", 0))
        busy.listen()
        done = _bridge("--serve", "--serve-port", str(busy.getsockname()[1]))
    assert done.returncode == 2 and "cannot listen" in done.stderr
    assert "ready:" not in done.stdout + done.stderr


@pytest.mark.parametrize("args", [["--serve", "--serve-port", "99999"],
                                  ["--serve", "--serve-memory-limit", "0"],
                                  ["--serve", "--serve-memory-limit", "1GiB"],
                                  ["--save", "x.rrd", "--flush-hz", "0"],
                                  ["--save", "x.rrd", "--window-s", "nan"]])
def test_bad_options_are_usage_errors(args, tmp_path) -> None:
    done = _bridge(*args)
    assert done.returncode == 2 and "Traceback" not in done.stderr
    assert done.stderr.strip().splitlines()[-1].startswith("rerun_bridge: error: ")


@pytest.mark.parametrize("signum", [signal.SIGHUP, signal.SIGTERM])
def test_no_viewer_beside_save_warns_and_the_signal_finishes_the_rrd(tmp_path, signum) -> None:

    rows = telemetry_rows(load_preset("field_8p5in_shale_lumped"), 2.0)
    rrd = tmp_path / "live.rrd"
    bridge, code = bridge_logs(rows, "--save", str(rrd), "--connect", _nowhere(),
                               signum=signum)
    assert code == 0, bridge.output()
    assert bridge.output().count("no viewer listening") == 1
    assert len(read_recording(rrd)["/timeseries/rop/bit"].time_ns) == len(rows)


def test_an_existing_save_file_is_refused_unless_overwrite(tmp_path) -> None:
    kept = tmp_path / "kept.rrd"
    kept.write_bytes(b"an earlier run")
    done = _bridge("--save", str(kept))
    assert done.returncode == 2 and "Traceback" not in done.stderr
    lines = [line for line in (done.stdout + done.stderr).splitlines() if line.strip()]
    assert len(lines) == 1 and "exists" in lines[0] and "--overwrite" in lines[0], lines
    assert kept.read_bytes() == b"an earlier run"
