"""Convergence in dtau, the profile delay against the exact time-history delay, determinism."""

from __future__ import annotations

import math

import numpy as np
import pytest

from drill_sim_ros.model import analysis as an
from drill_sim_ros.model import kernel as k
from drill_sim_ros.model.simulator import SimConfig, Simulator
from tests.model.helpers import FIG8A, FIG8B, run


def _observed_order(values: list[float]) -> float:
    """Order p from three results at dtau, dtau/2, dtau/4 (Richardson)."""
    e1, e2 = abs(values[0] - values[1]), abs(values[1] - values[2])
    return math.log2(e1 / e2)


def test_convergence_in_dtau_of_the_trajectory(capsys: pytest.CaptureFixture[str]) -> None:
    """Symplectic Euler is first order: the state at a fixed time converges as dtau^1."""
    omega_at_end = []
    for dtau in (4e-4, 2e-4, 1e-4):
        sim, _ = run(FIG8A, 8.0, dtau=dtau, perturb_v=1e-3, method="exact")
        omega_at_end.append(float(sim.state[k.S_OMEGA]))
    order = _observed_order(omega_at_end)
    with capsys.disabled():
        print(f"\n[convergence] observed order in dtau (trajectory, exact delay): {order:.3f}")
    assert 0.8 < order < 1.3


def test_convergence_in_dtau_of_limit_cycle_average(
        capsys: pytest.CaptureFixture[str]) -> None:
    """Limit-cycle averages converge at least at first order (kappa, bounded Fig. 8b cycle)."""
    kappas = []
    for dtau in (4e-4, 2e-4, 1e-4):
        sim, _ = run(FIG8B, 400.0, dtau=dtau, tau_avg=200.0, perturb_v=0.01)
        kappas.append(an.cycle_averages(FIG8B, sim.accumulators).kappa)
    order = _observed_order(kappas)
    with capsys.disabled():
        print(f"\n[convergence] observed order in dtau (kappa, Fig. 8b): {order:.3f}")
    assert order > 0.7


def test_profile_delay_agrees_with_exact_delay() -> None:
    """Second-order convergence in the node count towards the exact time-history delay."""
    def omega(method: str, nodes: int) -> np.ndarray:
        _, rows = run(FIG8A, 80.0, every=100, perturb_v=0.01, method=method, n_nodes=nodes)
        return rows[:, k.C_OMEGA]
    exact = omega("exact", 2048)
    err = {n: float(np.max(np.abs(omega("profile", n) - exact))) for n in (512, 2048)}
    print(f"max |omega_profile - omega_exact| over tau <= 80 (stick included): {err}")
    assert err[2048] < 1e-3 * FIG8A.omega0
    assert err[512] / err[2048] > 8.0          # (2048/512)^2 = 16 for second order


def test_snapshot_restore_is_bit_identical() -> None:
    sim = Simulator(FIG8A, SimConfig(dtau=1e-4), perturb_v=0.01)
    sim.advance(sim.steps_for(70.0))
    snap = sim.snapshot()
    first = sim.advance(50_000, every=10).data.copy()
    sim.restore(snap)
    second = sim.advance(50_000, every=10).data
    assert first.tobytes() == second.tobytes()


def test_runs_are_deterministic_and_chunking_invariant() -> None:
    one = Simulator(FIG8A, SimConfig(dtau=1e-4), perturb_v=0.01)
    whole = one.advance(400_000, every=1000).data
    two = Simulator(FIG8A, SimConfig(dtau=1e-4), perturb_v=0.01)
    parts = np.concatenate([two.advance(n, every=1000).data for n in (1, 999, 123_457, 275_543)])
    assert whole.tobytes() == parts.tobytes()


def test_memory_is_bounded() -> None:
    """The profile method keeps n_nodes floats whatever the run length; 'exact' forgets
    history older than one blade sector."""
    sim = Simulator(FIG8A, SimConfig(dtau=1e-4, n_nodes=1024), perturb_v=0.01)
    sim.advance(sim.steps_for(200.0))
    assert sim.profile.shape == (1024,)
    ex = Simulator(FIG8A, SimConfig(dtau=1e-4, method="exact", history_capacity=1 << 16),
                   perturb_v=0.01)
    ex.advance(ex.steps_for(200.0))          # would overflow if history were never forgotten
    assert ex.fault is None


def test_rebasing_keeps_large_depths_exact() -> None:
    """Depth and angle are rebased past 1e4 units; the trajectory must not notice."""
    p = FIG8B.with_(omega0=5.0)
    a = Simulator(p, SimConfig(dtau=2e-4), perturb_v=0.01)
    rows_a = np.concatenate([a.advance(100_000, every=100).data for _ in range(300)])
    assert a.snapshot().depth_offset > 0.0          # rebasing happened
    b = Simulator(p, SimConfig(dtau=2e-4), perturb_v=0.01)
    rows_b = b.advance(30_000_000, every=100).data  # never rebases (only before a run)
    # a missed shift would jump the depth of cut by n * shift ~ 1e4; rounding drifts ~1e-6
    for col in (k.C_DOC, k.C_OMEGA, k.C_V, k.C_WOB):
        spread = np.ptp(rows_b[:, col])
        assert np.max(np.abs(rows_a[:, col] - rows_b[:, col])) < 1e-3 * spread


@pytest.mark.parametrize("bad", [{"dtau": 0.0}, {"dtau": float("nan")}, {"n_nodes": 3},
                                 {"method": "rk4"}, {"omega_rate": -1.0}])
def test_bad_config_names_the_parameter(bad: dict) -> None:
    from drill_sim_ros.model.errors import ParameterError
    with pytest.raises(ParameterError, match=next(iter(bad))):
        SimConfig(**bad)
