"""closed-loop --ros: the controller node's failure is the same one line as in process
(exit 2), a huge finite command is clamped there too, a slow step warns once, Ctrl-C stops
both nodes (exit 130), and sim_node refuses a params file that sets nothing real (one FATAL
line)."""

from __future__ import annotations

import logging
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from tests.robust.faulty_controllers import FAIL_AT_S
from tests.robust.helpers import FAULTY, ROOT, one_error_line, run_cli

pytestmark = pytest.mark.ros
SHORT = ("closed-loop", "--ros", "--t-end", "1", "--no-baseline", "--json")


@pytest.fixture(autouse=True)
def _from_root(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(ROOT)


def test_a_nan_command_over_dds_is_one_line_not_a_full_score(capsys) -> None:
    rc, out, err = run_cli(capsys, *SHORT, "--controller", f"{FAULTY}:ReturnsNaN")
    one_error_line(rc, err, "ReturnsNaN", f"t = {FAIL_AT_S:.3f} s", "speed_rad_s = nan",
                   "over DDS")
    assert out == ""


@pytest.mark.parametrize(("cls", "names"), [
    ("RaisesInInit", ("RaisesInInit", "cannot be built", "no gain for you")),
    ("RaisesInStep", ("RaisesInStep", f"t = {FAIL_AT_S:.3f} s", "step exploded")),
    ("ReturnsString", ("ReturnsString", f"t = {FAIL_AT_S:.3f} s", "'fast please'")),
])
def test_a_failing_controller_over_dds_is_the_same_one_line(capsys, cls: str,
                                                            names: tuple[str, ...]) -> None:
    rc, out, err = run_cli(capsys, *SHORT, "--controller", f"{FAULTY}:{cls}")
    one_error_line(rc, err, *names, "over DDS")
    assert out == ""


def test_a_slow_controller_over_dds_warns_once(capsys, caplog) -> None:
    with caplog.at_level(logging.WARNING, logger="drill_sim_ros.ros.closed_loop"):
        rc, out, err = run_cli(capsys, *SHORT, "--controller", f"{FAULTY}:Slow")
    assert rc == 0, err
    warnings = [r.getMessage() for r in caplog.records if "slow" in r.getMessage()]
    assert len(warnings) == 1, warnings
    assert "Slow" in warnings[0] and "of wall time" in warnings[0], warnings
    assert warnings[0].endswith("(over DDS)") and '"path": "ros"' in out


def test_ctrl_c_over_dds_stops_both_nodes(tmp_path: Path) -> None:
    flag = tmp_path / "stalled"
    process = subprocess.Popen(
        [sys.executable, "-m", "drill_sim_ros.cli", *SHORT, "--controller",
         f"{FAULTY}:Stalls"], cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
        text=True, env={**os.environ, "STALL_FLAG": str(flag)})
    deadline = time.monotonic() + 120
    while not flag.exists() and time.monotonic() < deadline and process.poll() is None:
        time.sleep(0.05)
    assert flag.exists(), process.communicate(timeout=10)
    process.send_signal(signal.SIGINT)
    out, err = process.communicate(timeout=60)      # the controller node's sleep ends too
    assert process.returncode == 130, err
    assert "Traceback" not in err and out == ""
    lines = err.strip().splitlines()
    assert len(lines) == 1 and "interrupted" in lines[0], lines


def test_a_huge_finite_command_over_dds_is_clamped(capsys) -> None:
    rc, out, err = run_cli(capsys, *SHORT, "--controller", f"{FAULTY}:ReturnsHuge")
    assert rc == 0, err
    assert '"path": "ros"' in out


def test_sim_node_refuses_a_misspelt_params_file(tmp_path) -> None:
    params = tmp_path / "sim.yaml"
    params.write_text("drill_sim:\n  ros__parameters:\n    publish_rate_hzz: 50.0\n")
    done = subprocess.run([sys.executable, "-m", "drill_sim_ros.ros.sim_node", "--ros-args",
                           "--params-file", str(params)], capture_output=True, text=True,
                          timeout=60, env=os.environ.copy())
    lines = [line for line in (done.stdout + done.stderr).splitlines() if line.strip()]
    assert done.returncode == 2, lines
    assert len(lines) == 1 and "[FATAL]" in lines[0], lines
    assert "publish_rate_hzz" in lines[0] and "did you mean publish_rate_hz" in lines[0]
