"""drill_sim closed-loop as a user runs it: JSON, the table, the picture, a user's
controller by module:Class, and one-line errors."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from drill_sim_ros.closed_loop_cli import LABELS, _table
from drill_sim_ros.control.bench import run_in_process
from drill_sim_ros.control.registry import display_name
from drill_sim_ros.control.rig import rig_physics
from drill_sim_ros.control.scenario import Scenario, seeded
from drill_sim_ros.control.scorecard import SCORE_FIELDS, score
from drill_sim_ros.model.telemetry import TELEMETRY_FIELDS, TELEMETRY_INDEX

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


def test_a_column_is_named_by_the_controllers_name_and_never_glued() -> None:
    """The table's column is the controller's ``name`` (what its errors say), its class name
    when it keeps the base's; a name longer than the column keeps a space before it."""
    assert display_name("tests.control.user_controller:TorqueDamper") == "torque_damper"
    assert display_name("tests.control.user_controller:ConstantSpeed") == "ConstantSpeed"
    assert display_name("soft_torque") == "soft_torque"
    long_name = "impedance_matching_with_a_long_name (speed)"
    card = dict.fromkeys(SCORE_FIELDS, 1.0)
    header = _table({"no control": card, long_name: card}).splitlines()[0]
    assert header.split() == ["no", "control", *long_name.split()]
    assert "control" + long_name[0] not in header


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
        (("--t-end", "30", "--enable-at", "30"), "--enable-at"),
        (("--ensemble", "0"), "--ensemble"),
        (("--ensemble", "65"), "--ensemble"),
        (("--ensemble", "2", "--ros"), "--ensemble"),
        (("--record", "run.mcap"), "--record"),
        (("--ros", "--record", "run.rrd"), "--record"),
        (("--save-traces", "traces.csv"), "--save-traces"),
    ],
)
def test_bad_input_is_one_line(args: tuple[str, ...], names: str) -> None:
    result = drill_sim(*args, "--t-end", "1") if "--t-end" not in args else drill_sim(*args)
    assert result.returncode == 2
    assert result.stderr.count("\n") == 1 and names in result.stderr, result.stderr
    assert "Traceback" not in result.stderr


def test_an_ensemble_scores_its_members_as_the_bench_does() -> None:
    """--ensemble 3: member 0 is the run printed as ``score``, and member 2, run by the
    command, is the bench's own run of the scenario with the bit's sigma l x (1 + 2e-12);
    the uncontrolled column has its members too."""
    result = drill_sim("--controller", "soft_torque", "--t-end", "60", "--ensemble", "3",
                       "--json")
    assert result.returncode == 0, result.stderr
    doc = json.loads(result.stdout.splitlines()[-1])
    members, baseline = doc["ensemble"]["score"], doc["ensemble"]["baseline"]
    assert len(members) == len(baseline) == 3 and doc["ensemble"]["step"] == 1e-12
    assert members[0] == doc["score"] and baseline[0] == doc["baseline"]
    scenario = seeded(Scenario(controller="soft_torque", duration_s=60.0, enable_at_s=20.0), 2)
    preset = scenario.load_preset()
    card = score(run_in_process(scenario).rows, scenario.enable_at_s,
                 scenario.setpoints(preset), rig_physics(preset), scenario.period_s)
    for key in ("ssi_mean", "stick_fraction", "rop_m_h", "saturation_fraction", "ring_rms_rpm"):
        assert members[2][key] == pytest.approx(card[key], rel=1e-12), key
    table = drill_sim("--controller", "soft_torque", "--t-end", "30", "--ensemble", "2")
    assert table.returncode == 0, table.stderr
    assert "the ensemble of 2 members" in table.stdout
    assert "stick-slip / ok / stalled / other" in table.stdout


def test_save_traces_holds_both_runs_as_the_bench_runs_them(tmp_path: Path) -> None:
    """--save-traces: every telemetry column of the controller's run and of the uncontrolled
    one, equal to the bench's own runs of the same scenario; the throughput line counts
    both runs (2 x 2000 periods)."""
    npz = tmp_path / "traces.npz"
    result = drill_sim("--controller", "soft_torque", "--t-end", "20", "--save-traces",
                       str(npz))
    assert result.returncode == 0, result.stderr
    assert "4,000 periods of 10 ms in 2 runs (in process)" in result.stdout
    scenario = Scenario(controller="soft_torque", duration_s=20.0, enable_at_s=20.0 / 3.0)
    with np.load(npz) as saved:
        assert tuple(saved["fields"]) == TELEMETRY_FIELDS
        assert json.loads(str(saved["meta"]))["controlled"] == "soft_torque (speed)"
        np.testing.assert_array_equal(saved["controlled"], run_in_process(scenario).rows)
        np.testing.assert_array_equal(
            saved["baseline"], run_in_process(scenario.with_(controller="none")).rows)
    again = drill_sim("--controller", "soft_torque", "--t-end", "1", "--save-traces", str(npz))
    assert again.returncode == 2 and "exists" in again.stderr


@pytest.mark.ros
def test_record_keeps_the_recording_it_scored(tmp_path: Path) -> None:
    """--ros --record FILE.mcap: the command says where the recording is, and its telemetry
    is the run the command saved (--save-traces)."""
    from drill_sim_ros.ros.closed_loop import read_telemetry
    mcap, npz = tmp_path / "run.mcap", tmp_path / "traces.npz"
    result = drill_sim("--controller", "soft_torque", "--t-end", "10", "--no-baseline", "--ros",
                       "--record", str(mcap), "--save-traces", str(npz))
    assert result.returncode == 0, result.stderr
    assert f"recording: {mcap}" in result.stdout
    with np.load(npz) as saved:
        np.testing.assert_array_equal(read_telemetry(mcap), saved["controlled"])
