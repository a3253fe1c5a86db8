"""Per point, a map gives the figures of `drill_sim run`; the regime classifier on the
paper's cases; the torsional period of a known signal."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from drill_sim_ros.model import analysis
from drill_sim_ros.study import regime, store
from drill_sim_ros.study.grid import Numerics
from drill_sim_ros.study.point import COLUMN, evaluate_point, torsional_period
from tests.robust.helpers import run_cli
from tests.study.helpers import FIG8A, drill_sim, small_spec

# map variable -> `drill_sim run --json` key
SAME_AS_RUN = {"kappa": "kappa", "eta": "eta", "mean_depth_of_cut": "mean_depth_of_cut",
               "mean_torque": "mean_torque", "mean_wob": "mean_wob", "ssi": "ssi",
               "utr": "utr", "stick_fraction": "stick_fraction",
               "first_stick_tau": "first_stick_tau", "bounce_tau": "bounce_tau",
               "omega_min": "omega_min", "omega_max": "omega_max",
               "specific_energy": "specific_energy",
               "drilling_strength": "drilling_strength"}


def test_map_points_equal_drill_sim_run(tmp_path: Path,
                                       capsys: pytest.CaptureFixture[str]) -> None:
    """`drill_sim map` (a local cluster, 2 workers) against `drill_sim run --json` per
    point: the same numbers, exactly (both are deterministic runs of the same model). The
    map runs as a user runs it (its own process and workers); the six runs run in this
    process (cli.main: its argv and its stdout), which spares six interpreter and kernel
    start-ups; tests/test_cli.py runs `drill_sim run` as a process."""
    spec = small_spec()
    out = tmp_path / "map.nc"
    result = drill_sim("map", "--n", "6", "--psi", "50", "--beta", "0.3", "--lam", "5",
                       "--w0", "7", "--omega0", "5", "--tau-end", "60", "--average-from",
                       "30", "--dtau", "1e-4", "--vary", "beta=0.3,1.3",
                       "--vary", "w0_ratio=1.2,1.4,1.8", "--out", str(out), "--workers", "2")
    assert result.returncode == 0, result.stderr
    ds = store.load(out)
    assert int(ds["done"].sum()) == spec.size
    assert ds.attrs["package_version"] and ds["kappa"].attrs["units"] == "1"
    for flat in range(spec.size):
        p = spec.point(flat)
        rc, stdout, stderr = run_cli(
            capsys, "run", "--n", str(p.n), "--psi", repr(p.psi), "--beta", repr(p.beta),
            "--lam", repr(p.lam), "--w0", repr(p.w0), "--omega0", repr(p.omega0),
            "--tau-end", "60", "--average-from", "30", "--dtau", "1e-4", "--json")
        assert rc == 0, stderr
        expected = json.loads(stdout)
        where = np.unravel_index(flat, spec.shape)
        for var, key in SAME_AS_RUN.items():
            got = float(ds[var].values[where])
            want = math.nan if expected[key] is None else expected[key]
            assert got == want or (math.isnan(got) and math.isnan(want)), (flat, var)
        delta0 = expected["trivial_depth_of_cut"]
        assert float(ds["kappa_from_depth"].values[where]) == pytest.approx(
            (expected["mean_depth_of_cut"] - delta0) / p.lam, rel=1e-12)


LIMIT = Numerics(tau_end=600.0, average_from=300.0, dtau=1e-4)


def _regime(params, num=LIMIT) -> tuple[int, np.ndarray]:
    out = evaluate_point(params, num)
    return int(out[COLUMN["regime"]]), out


def test_fig8a_is_stick_slip() -> None:
    code, _ = _regime(FIG8A)                       # RGD07 Fig. 8a: beta < 1 sticks
    assert code == regime.STICK_SLIP


def test_fig8b_has_no_stick() -> None:
    code, out = _regime(FIG8A.with_(beta=1.3))     # Fig. 8b: bounded, no stick
    assert code == regime.AXIAL
    assert out[COLUMN["stick_fraction"]] == 0.0


def test_large_weight_small_speed_bounces() -> None:
    """Fig. 14 case (n = 6, lambda = 4.2, beta = 0.43, psi = 100) at W0' = 3, omega0 = 2:
    inside the bouncing region the paper draws (large W0', small omega0)."""
    params = FIG8A.with_(psi=100.0, beta=0.43, lam=4.2, w0=3.0 * 4.2, omega0=2.0)
    code, out = _regime(params, Numerics(tau_end=300.0, average_from=150.0, dtau=5e-5))
    assert code == regime.BOUNCING
    assert out[COLUMN["bounce_tau"]] > 0.0


def test_below_critical_delay_stays_trivial() -> None:
    """tau_n0 = 2 pi/(n omega0) < tau_nc = pi/sqrt(2 n psi) (App. B): the perturbation
    decays and nothing sticks, bounces or loses contact."""
    params = FIG8A.with_(omega0=10.0)
    assert analysis.trivial_delay(params) < analysis.critical_delay(params)
    code, out = _regime(params)
    assert code == regime.TRIVIAL
    assert out[COLUMN["kappa"]] == pytest.approx(0.0, abs=1e-9)
    assert out[COLUMN["axial_amplitude"]] < 0.01


def test_sliding_without_cutting_is_trivial() -> None:
    """W0 < lambda: no cutting, the bit slides on its wearflats (text after eq. 18),
    W_f = W0, so kappa = 1 - W0/lambda without any vibration."""
    params = FIG8A.with_(w0=4.0)
    code, out = _regime(params)
    assert out[COLUMN["kappa"]] == pytest.approx(1 - 4.0 / 5.0, abs=1e-6)
    assert code == regime.TRIVIAL


def test_classify_order() -> None:
    assert regime.classify(0.1, 5.0, 0.2, 3.0, 0.01) == regime.BOUNCING
    assert regime.classify(0.1, math.nan, 0.2, 3.0, 0.01) == regime.STICK_SLIP
    assert regime.classify(0.0, math.nan, 0.2, 3.0, 0.01) == regime.AXIAL
    assert regime.classify(0.0, math.nan, 0.0, 0.02, 0.01) == regime.AXIAL   # it grew
    assert regime.classify(0.0, math.nan, 0.0, 0.005, 0.01) == regime.TRIVIAL


def test_torsional_period_of_known_signals() -> None:
    tau = np.arange(0.0, 100.0, 0.01)
    assert torsional_period(tau, 5 + np.sin(2 * np.pi * tau / 6.5)) == pytest.approx(
        6.5, rel=1e-3)
    # stick-slip shape: zero most of the time, a short slip every 7.25
    slip = np.where(np.mod(tau, 7.25) < 1.5, 10 * np.sin(np.pi * np.mod(tau, 7.25) / 1.5), 0)
    assert torsional_period(tau, slip) == pytest.approx(7.25, rel=1e-3)
    assert math.isnan(torsional_period(tau, np.full_like(tau, 5.0)))
