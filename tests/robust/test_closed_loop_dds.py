"""closed-loop --ros: the controller node's failure is the same one line as in process
(exit 2), a huge finite command is clamped there too, and sim_node refuses a params file
that sets nothing real (one FATAL line)."""

from __future__ import annotations

import os
import subprocess
import sys

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
    assert done.returncode != 0
    assert len(lines) == 1 and "[FATAL]" in lines[0], lines
    assert "publish_rate_hzz" in lines[0] and "did you mean publish_rate_hz" in lines[0]
