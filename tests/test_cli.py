"""The offline CLI answers for the Fig. 8 cases (subprocess, as a user runs it)."""

from __future__ import annotations

import csv
import json
import math
import subprocess
import sys
from pathlib import Path

import pytest

from drill_sim_ros.model.presets import preset_path
from drill_sim_ros.model.validate_input import read_preset_file
from tests.model.helpers import SMALL_DEVIATED
from tests.robust.helpers import one_error_line, run_cli

REQUIRED = ("first_stick_tau", "bounce_tau", "stick_fraction", "kappa", "kappa_from_depth",
            "mean_torque", "mean_depth_of_cut", "mean_wob", "omega_min", "omega_max",
            "trivial_torque", "trivial_depth_of_cut", "critical_delay", "growth_rate", "steps",
            "kernel_seconds")


def drill_sim(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "drill_sim_ros.cli", *args],
                          capture_output=True, text=True, timeout=240)


@pytest.mark.parametrize(("beta", "sticks"), [("0.3", True), ("1.3", False)])
def test_run_json_fig8(beta: str, sticks: bool, tmp_path: Path) -> None:
    trace = tmp_path / "trace.csv"
    result = drill_sim("run", "--n", "6", "--psi", "50", "--beta", beta, "--lam", "5",
                       "--w0", "7", "--omega0", "5", "--tau-end", "300", "--dtau", "1e-4",
                       "--average-from", "150", "--json", "--trace", str(trace),
                       "--trace-every", "1000")
    assert result.returncode == 0, result.stderr
    out = json.loads(result.stdout)
    assert set(REQUIRED) <= set(out)
    assert out["steps"] == 3_000_000
    assert (out["first_stick_tau"] is not None) == sticks
    assert out["trivial_torque"] == pytest.approx(7 + 5 * (float(beta) - 1))     # eq. 34
    with trace.open() as stream:
        rows = list(csv.DictReader(stream))
    assert list(rows[0]) == ["tau", "omega", "v", "wob", "tob", "depth_of_cut",
                             "surface_torque", "mode"]
    assert len(rows) == 3000
    assert float(rows[1]["tau"]) == pytest.approx(0.1)


def test_physical_preset_reports_si(tmp_path: Path) -> None:
    result = drill_sim("run", "--params", "field_8p5in_shale_lumped", "--t-end", "5", "--json")
    assert result.returncode == 0, result.stderr
    si = json.loads(result.stdout)["si"]
    assert si["t_star_s"] > 0 and si["mean_wob_n"] > 0


def test_bad_argument_is_named_with_nonzero_exit() -> None:
    result = drill_sim("run", "--psi", "-3", "--tau-end", "1")
    assert result.returncode == 2
    assert "'psi'" in result.stderr


def test_readable_summary() -> None:
    result = drill_sim("run", "--tau-end", "20")
    assert result.returncode == 0, result.stderr
    assert "kappa" in result.stdout and "first stick" in result.stdout


def test_sweep_prints_one_json_line_per_value() -> None:
    result = drill_sim("sweep", "--params", "fig11", "--vary", "omega0", "--values", "3,6",
                       "--tau-end", "20")
    assert result.returncode == 0, result.stderr
    lines = [json.loads(line) for line in result.stdout.splitlines()]
    assert [d["params"]["omega0"] for d in lines] == [3.0, 6.0]
    assert all(d["params"]["psi"] == 63.0 for d in lines)      # the rest from the preset


def test_info_and_presets() -> None:
    info = drill_sim("info", "fig5_8a")
    assert info.returncode == 0 and "critical delay" in info.stdout
    listing = drill_sim("presets")
    assert "field_8p5in_shale_lumped" in listing.stdout and "fig10" in listing.stdout


def test_top_drive_options_and_the_field_preset_drive() -> None:
    field = json.loads(drill_sim("run", "--params", "field_8p5in_shale_lumped", "--t-end", "2",
                                 "--json").stdout)
    assert field["top_drive"]["mode"] == "speed"               # the field preset's default
    paper = json.loads(drill_sim("run", "--params", "fig5_8a", "--tau-end", "2",
                                 "--json").stdout)
    assert paper["top_drive"]["mode"] == "kinematic"           # the paper's presets
    result = drill_sim("run", "--params", "fig5_8a", "--tau-end", "2", "--json",
                       "--top-drive", "torque", "--drive-inertia-ratio", "3",
                       "--motor-torque", "4", "--drive-max-torque-nm", "10")
    assert result.returncode == 0, result.stderr
    drive = json.loads(result.stdout)["top_drive"]
    assert drive == {"mode": "torque", "inertia_ratio": 3.0, "kp": drive["kp"],
                     "ki": drive["ki"], "max_torque": 10.0}
    bad = drill_sim("run", "--tau-end", "1", "--drive-inertia-ratio", "-1")
    assert bad.returncode == 2
    assert "'top_drive.inertia_ratio'" in bad.stderr and "Traceback" not in bad.stderr


@pytest.mark.parametrize("omega0", ["0.05", "0"])
def test_run_and_info_at_the_low_end_of_omega0(omega0: str, tmp_path: Path) -> None:
    """A long (or infinite) delay once raised OverflowError after the whole run."""
    run = drill_sim("run", "--omega0", omega0, "--tau-end", "2", "--json")
    assert run.returncode == 0, run.stderr
    assert "Traceback" not in run.stderr
    result = json.loads(run.stdout)
    assert result["steps"] > 0 and result["params"]["omega0"] == float(omega0)
    assert (result["growth_rate"] is None) == (omega0 == "0")
    preset = tmp_path / "slow.yaml"
    preset.write_text("description: slow top drive\n"
                      f"dimensionless: {{n: 6, psi: 50.0, beta: 0.3, lam: 5.0, w0: 7.0, "
                      f"omega0: {omega0}}}\n")
    info = drill_sim("info", str(preset))
    assert info.returncode == 0 and "Traceback" not in info.stderr, info.stderr


def test_modes_reports_damping_ratios(tmp_path: Path) -> None:
    """``drill_sim modes`` on a damped string (one rate per kind): the table has the two
    damping columns, and the JSON line gives per kind the analytic ratios rate / (2 omega_k)
    of its analytic frequencies and identified ones within 10 % of them."""
    rates = {"torsional": 0.9, "axial": 1.2}
    preset = tmp_path / "damped.yaml"
    preset.write_text(
        "description: 1200 m of 5-in pipe on 150 m of collars, damped\n"
        "physical: {density_kg_m3: 7850.0, shear_modulus_pa: 79.3e9,\n"
        "  youngs_modulus_pa: 206.0e9, bit_radius_m: 0.108, n_blades: 6,\n"
        "  intrinsic_specific_energy_pa: 230.0e6,\n"
        "  zeta: 0.729, mu_gamma: 0.48, contact_stress_times_wearflat_n_per_m: 3.0e5,\n"
        "  applied_wob_n: 60000.0, surface_rpm: 60.0}\n"
        "string:\n"
        "  model: distributed\n"
        "  sections:\n"
        "    - {outer_radius_m: 0.0635, inner_radius_m: 0.0543, length_m: 1200.0}\n"
        "    - {outer_radius_m: 0.0857, inner_radius_m: 0.0357, length_m: 150.0}\n"
        f"  torsional_damping_per_s: {rates['torsional']}\n"
        f"  axial_damping_per_s: {rates['axial']}\n"
        "top_drive: {mode: speed, inertia_kg_m2: 2900.0, kp_nm_s: 23200.0, ki_nm: 46400.0,\n"
        "  max_torque_nm: 50000.0}\n")
    result = drill_sim("modes", "--params", str(preset), "--count", "2")
    assert result.returncode == 0, result.stderr
    lines = result.stdout.splitlines()
    assert "identified zeta" in lines[0] and "analytic zeta" in lines[0]
    assert len(lines) == 1 + 4 + 1
    out = json.loads(lines[-1])
    for kind, rate in rates.items():
        d = out[kind]
        assert set(d) == {"identified_hz", "analytic_hz", "identified_damping_ratio",
                          "analytic_damping_ratio"}
        expected = [rate / (4 * math.pi * f) for f in d["analytic_hz"]]
        assert d["analytic_damping_ratio"] == pytest.approx(expected, abs=2e-6)
        assert d["identified_damping_ratio"] == pytest.approx(expected, rel=0.10)


def test_modes_on_a_walled_preset_names_no_peak_after_the_wrong_mode() -> None:
    """``drill_sim modes`` on the deviated preset: the wall's note, and per kind one
    identified frequency a mode (null where none was found), each within 10 % of its own
    analytic mode: a listing of the lowest peaks found would name mode 2's peak mode 1."""
    result = drill_sim("modes", "--params", "field_8p5in_deviated")
    assert result.returncode == 0, result.stderr
    assert "note: the string rings in its well, on the wall" in result.stdout
    out = json.loads(result.stdout.splitlines()[-1])
    for kind in ("torsional", "axial"):
        found, analytic = out[kind]["identified_hz"], out[kind]["analytic_hz"]
        assert len(found) == len(analytic) == 3, out[kind]
        for hz, mode_hz in zip(found, analytic, strict=True):
            assert hz is None or abs(hz / mode_hz - 1.0) < 0.1, out[kind]
    assert None not in out["torsional"]["identified_hz"]    # the wall damps axial motion


STARTUP_KEYS = {"breakaway_s", "breakaway_turns", "breakaway_torque_nm", "first_slip_s",
                "peak_motor_torque_nm", "stick_slip", "period_s", "stick_fraction",
                "bit_rpm_max", "motor_torque_nm", "twist_turns", "cutoff_hz"}


@pytest.mark.parametrize(("args", "names"), [
    (("--rpm", "0"), ("--rpm = 0.0", "(0, 300]")),
    (("--rpm", "301"), ("--rpm = 301.0", "(0, 300]")),
    (("--ramp-s", "-1"), ("--ramp-s = -1.0", "[0, 3600]")),
    (("--seconds", "0"), ("--seconds = 0.0", "(0, 3600]")),
    (("--params", "field_8p5in_shale_lumped"), ("field_8p5in_shale_lumped", "lumped",
                                                "distributed")),
    (("--params", "fig8b"), ("fig8b", "dimensionless")),
    (("--params", "no_such_preset"), ("no_such_preset", "not found")),
])
def test_startup_refuses_bad_input_in_one_line(capsys: pytest.CaptureFixture[str],
                                               args: tuple[str, ...],
                                               names: tuple[str, ...]) -> None:
    rc, out, err = run_cli(capsys, "startup", "--seconds", "5", *args)
    one_error_line(rc, err, *names)
    assert out == ""


def test_startup_in_a_small_deviated_well(capsys: pytest.CaptureFixture[str],
                                          tmp_path: Path) -> None:
    """A real run of 10 s: --json is one line with every key, the bit breaks away; without
    --json the summary comes first and the same JSON line last, and --plot writes a PNG."""
    preset = tmp_path / "deviated.yaml"
    preset.write_text(SMALL_DEVIATED)
    args = ("startup", "--params", str(preset), "--rpm", "60", "--ramp-s", "5", "--seconds",
            "10")
    rc, out, err = run_cli(capsys, *args, "--json")
    assert rc == 0, err
    assert len(out.splitlines()) == 1
    scores = json.loads(out)
    assert set(scores) == STARTUP_KEYS
    assert scores["breakaway_s"] > 0.0
    assert set(scores["motor_torque_nm"]) == set(scores["twist_turns"]) == {"mean", "min",
                                                                            "max"}
    plot = tmp_path / "startup.png"
    rc, out, err = run_cli(capsys, *args, "--plot", str(plot))
    assert rc == 0, err
    lines = out.splitlines()
    assert "break-away" in out and "stick-slip" in out
    assert json.loads(lines[-1]) == scores
    assert plot.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    # --plot as closed-loop's (plot_file): an existing picture is kept and named in one line,
    # before the run; --overwrite replaces it; no partial file is left beside it
    plot.write_bytes(b"keep")
    rc, out, err = run_cli(capsys, *args, "--plot", str(plot))
    one_error_line(rc, err, str(plot), "--overwrite")
    assert plot.read_bytes() == b"keep" and out == ""
    rc, out, err = run_cli(capsys, *args, "--plot", str(plot), "--overwrite", "--json")
    assert rc == 0, err
    assert plot.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["deviated.yaml", "startup.png"]


def test_run_drills_with_the_presets_bit_law(tmp_path: Path) -> None:
    """`drill_sim run --params field_8p5in_shale` runs the preset's weakening law: its
    trivial torque is the law's at the drive's speed, eq. 34's times f(omega0) =
    0.5 + 0.5 exp(-omega0 / 7 rad/s) (docs/model.md), and the same preset with floor ratio 1
    (RGD07's law) reports eq. 34's own torque."""
    data = read_preset_file(preset_path("field_8p5in_shale"))
    weak = data["physical"]["friction_weakening"]
    rgd07 = tmp_path / "rgd07.yaml"
    rgd07.write_text(json.dumps({**data, "physical": {
        **data["physical"], "friction_weakening": {**weak, "floor_ratio": 1.0}}}))
    outs = []
    for params in ("field_8p5in_shale", str(rgd07)):
        done = drill_sim("run", "--params", params, "--t-end", "2", "--json")
        assert done.returncode == 0, done.stderr
        outs.append(json.loads(done.stdout.strip().splitlines()[-1]))
    omega0_rad_s = 35.0 * 2.0 * math.pi / 60.0
    factor = 0.5 + 0.5 * math.exp(-omega0_rad_s / 7.0)
    assert outs[0]["trivial_torque"] == pytest.approx(factor * outs[1]["trivial_torque"],
                                                      rel=1e-9)
