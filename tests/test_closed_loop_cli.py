"""drill_sim closed-loop as a user runs it: JSON, the table, the picture, a user's
controller by module:Class, and one-line errors."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from drill_sim_ros.closed_loop_cli import LABELS
from drill_sim_ros.control.bench import run_in_process
from drill_sim_ros.control.scenario import Scenario
from drill_sim_ros.control.scorecard import SCORE_FIELDS
from drill_sim_ros.model.telemetry import TELEMETRY_INDEX

ROOT = Path(__file__).resolve().parents[1]
F = TELEMETRY_INDEX


def drill_sim(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "drill_sim_ros.cli", "closed-loop", *args],
        capture_output=True,
        text=True,
        timeout=300,
        cwd=ROOT,
    )


def test_json_table_and_plot(tmp_path: Path) -> None:
    png = tmp_path / "cl.png"
    result = drill_sim(
        "--params",
        "field_8p5in_shale_lumped",
        "--controller",
        "z_torque",
        "--mode",
        "torque",
        "--t-end",
        "60",
        "--enable-at",
        "20",
        "--json",
        "--plot",
        str(png),
    )
    assert result.returncode == 0, result.stderr
    out = json.loads(result.stdout)
    assert out["periods"] == 6000 and out["scenario"]["mode"] == "torque"
    assert out["score"]["stick_fraction"] < out["baseline"]["stick_fraction"]
    assert list(out["score"]) == list(SCORE_FIELDS) == list(LABELS)
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and png.stat().st_size > 20_000
    table = drill_sim("--controller", "stiff", "--t-end", "30", "--enable-at", "10")
    assert table.returncode == 0, table.stderr
    assert "SSI after (mean)" in table.stdout and "no control" in table.stdout
    assert all(LABELS[key] in table.stdout for key in SCORE_FIELDS)


def test_user_controller_by_module_and_class(tmp_path: Path) -> None:
    result = drill_sim(
        "--controller",
        "tests.control.user_controller:TorqueDamper",
        "--t-end",
        "40",
        "--enable-at",
        "10",
        "--json",
        "--no-baseline",
    )
    assert result.returncode == 0, result.stderr
    assert json.loads(result.stdout)["scenario"]["controller"].endswith(":TorqueDamper")
    # the bare protocol: its commands reach the drive (75 rpm from the first command on)
    rows = run_in_process(
        Scenario(
            preset="field_8p5in_shale_lumped",
            controller="tests.control.user_controller:ConstantSpeed",
            duration_s=2.0,
            enable_at_s=0.0,
            params={"rpm": 75.0},
        )
    ).rows
    np.testing.assert_allclose(rows[1:, F["speed_setpoint_rpm"]], 75.0, rtol=1e-12)


@pytest.mark.parametrize(
    ("args", "names"),
    [
        (("--controller", "bogus"), "bogus"),
        (("--controller", "nowhere.module:Class"), "nowhere.module"),
        (("--controller", "none", "--mode", "torque"), "none"),
        (("--params", "fig5_8a"), "fig5_8a"),
        (("--t-end", "10", "--enable-at", "20"), "enable_at_s"),
        (("--set", "impedance_factor=x"), "impedance_factor"),
        (("--controller", "soft_torque", "--set", "gain=1"), "gain"),
    ],
)
def test_bad_input_is_one_line(args: tuple[str, ...], names: str) -> None:
    result = drill_sim(*args, "--t-end", "1") if "--t-end" not in args else drill_sim(*args)
    assert result.returncode == 2
    assert result.stderr.count("\n") == 1 and names in result.stderr, result.stderr
    assert "Traceback" not in result.stderr
