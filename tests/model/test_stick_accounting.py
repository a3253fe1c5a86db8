"""Issue 13: the wearflat force while stuck comes from the axial balance (eq. 31 last line,
eq. 25 left), so kappa (42), eq. (44) and eq. (45a) agree in stick-slip, and nothing else
changes: the dynamics, checked against the plain reference path of tests/model/reference."""

from __future__ import annotations

import numpy as np
import pytest

from drill_sim_ros.model import analysis as an
from drill_sim_ros.model import kernel as k
from drill_sim_ros.model.params import DimensionlessParams
from drill_sim_ros.model.simulator import SimConfig, Simulator
from tests.model import reference
from tests.model.helpers import FIG8A, FIG8B, advance_to_stick_onset, whole_cycle_averages

# Fig. 11 base case: W0' = W0 / lam = 1.7, omega0 = 4, psi = 63, n = 6, beta = 0.28.
FIG11_BASE = DimensionlessParams(n=6, psi=63.0, beta=0.28, lam=5.0, w0=8.5, omega0=4.0)
NODES = 2048
EVERY = 7


def _run_both(p: DimensionlessParams, tau_end: float, tau_avg: float
              ) -> tuple[np.ndarray, an.CycleAverages, np.ndarray, an.CycleAverages]:
    """The production kernel and the reference path over the same run."""
    dtau = 1e-4
    sim = Simulator(p, SimConfig(dtau=dtau, n_nodes=NODES, tau_avg=tau_avg), perturb_v=0.01)
    n_steps = sim.steps_for(tau_end)
    rows = sim.advance(n_steps, every=EVERY).data
    state, profile = reference.initial_state(p, 0.01, 0.0, NODES)
    ref_rows, sums = reference.run_reference(state, profile, float(p.n), p.beta, p.lam, p.psi,
                                             p.w0, p.omega0, dtau, n_steps, EVERY, tau_avg)
    ref_acc = k.new_accumulators()
    ref_acc[:k.A_OMEGA_MIN] = sums[:k.A_OMEGA_MIN]
    ref_acc[k.A_STUCK] = sums[k.A_STUCK]
    ref_acc[k.A_OMEGA_MIN] = sim.accumulators[k.A_OMEGA_MIN]   # extremes: not in the sums
    ref_acc[k.A_OMEGA_MAX] = sim.accumulators[k.A_OMEGA_MAX]
    return (rows, an.cycle_averages(p, sim.accumulators), ref_rows,
            an.cycle_averages(p, ref_acc))


UNCHANGED = ("mean_torque", "mean_depth_of_cut", "mean_omega", "mean_pipe_torque", "mean_rop",
             "specific_energy", "stick_fraction", "window_steps")


@pytest.mark.parametrize("p", [FIG8A, FIG8B], ids=["fig8a", "fig8b"])
def test_fig8_unchanged_to_the_last_digit_but_the_stuck_wearflat(p: DimensionlessParams
                                                                  ) -> None:
    rows, avg, ref_rows, ref_avg = _run_both(p, 600.0, 300.0)
    assert rows.shape == ref_rows.shape
    stuck = rows[:, k.C_MODE] == k.MODE_STUCK
    assert np.array_equal(stuck, ref_rows[:, k.C_MODE] == k.MODE_STUCK)
    wf_cols = [k.C_WF, k.C_WOB]
    others = [c for c in range(k.N_COLS) if c not in wf_cols]
    assert np.array_equal(rows[:, others], ref_rows[:, others])        # every step, bit for bit
    assert np.array_equal(rows[~stuck][:, wf_cols], ref_rows[~stuck][:, wf_cols])
    for name in UNCHANGED:
        assert getattr(avg, name) == getattr(ref_avg, name), name
    if not stuck.any():                     # Fig. 8b: no stick, so everything is unchanged
        assert avg == ref_avg
    else:                                   # Fig. 8a: the stuck wearflat carries W0 - delta_k
        wearflat = np.clip(p.w0 - rows[stuck, k.C_DOC], 0.0, p.lam)
        assert np.array_equal(rows[stuck, k.C_WF], wearflat)
        assert np.array_equal(rows[stuck, k.C_WOB], rows[stuck, k.C_DOC] + wearflat)
        print(f"stuck samples with W0 - delta_k beyond [0, lam]: "
              f"{np.mean(wearflat != p.w0 - rows[stuck, k.C_DOC]):.3f}")
        assert avg.kappa > ref_avg.kappa    # less wearflat force than the full lam


def test_every_stuck_sample_balances_w_equals_delta_plus_wf() -> None:
    """W = delta + W_f (eq. 29) and 0 <= W_f <= lam in every stuck sample; W = W0 when the
    wearflat can carry W0 - delta_k, at its bounds otherwise (applied weight changed)."""
    p = FIG11_BASE.with_(omega0=3.0)
    sim = Simulator(p, SimConfig(dtau=1e-4), perturb_v=0.01)
    rows = [sim.advance(sim.steps_for(200.0), every=3).data]
    for w_app in (p.w0 + 3.0 * p.lam, 0.0, p.w0):  # over lam / below delta_k / the balance
        assert advance_to_stick_onset(sim, sim.tau + 50.0)
        sim.advance(10)
        sim.set_inputs(w_app=w_app)
        rows.append(sim.advance(200, every=1).data[1:])
        sim.set_inputs(w_app=p.w0)
    data = np.concatenate(rows)
    stuck = data[data[:, k.C_MODE] == k.MODE_STUCK]
    assert len(stuck) > 1000
    doc, wf, wob, w_app = (stuck[:, c] for c in (k.C_DOC, k.C_WF, k.C_WOB, k.C_W_APP))
    assert np.all(wob == doc + wf)
    assert np.all((wf >= 0.0) & (wf <= p.lam))
    inside = (w_app - doc >= 0.0) & (w_app - doc <= p.lam)
    assert np.all(wob[inside] == w_app[inside])
    assert np.any(wf == p.lam) and np.any(wf == 0.0) and np.any(inside)


@pytest.mark.parametrize("omega0", [3.0, 4.0])
def test_fig11_kappa_eq44_and_eq45a_agree_in_stick_slip(omega0: float) -> None:
    p = FIG11_BASE.with_(omega0=omega0)
    avg = whole_cycle_averages(p, cycles=20)
    assert avg.stick_fraction > 0.15
    delta0 = an.trivial_solution(p).depth_of_cut
    errors = {
        "44a W0 = <delta> + (1 - kappa) lam":
            (avg.mean_depth_of_cut + (1.0 - avg.kappa) * p.lam - p.w0) / p.w0,
        "45a <delta> = delta0 + kappa lam":
            (avg.mean_depth_of_cut - (delta0 + avg.kappa * p.lam)) / avg.mean_depth_of_cut,
        "kappa = (<delta> - delta0) / lam":
            an.kappa_from_depth(avg.mean_depth_of_cut, delta0, p.lam) / avg.kappa - 1.0,
        "<W> = W0": avg.mean_wob / p.w0 - 1.0,
    }
    pred = an.predicted_from_kappa(p, avg.kappa)
    misses = {"45b": avg.mean_torque / pred["mean_torque_45b"] - 1.0,
              "47": avg.mean_torque / pred["mean_torque"] - 1.0}
    print(f"omega0={omega0} stick={avg.stick_fraction:.3f} kappa={avg.kappa:.5f}", errors,
          "eq. 30-based, not valid in stick:", misses)
    assert max(abs(e) for e in errors.values()) <= 3e-3, errors


def test_kappa_from_depth_is_eq45a_solved() -> None:
    p = FIG11_BASE
    delta0 = an.trivial_solution(p).depth_of_cut
    kappa = 0.2
    assert an.kappa_from_depth(delta0 + kappa * p.lam, delta0, p.lam) == pytest.approx(kappa)
    assert np.isnan(an.kappa_from_depth(1.0, 0.0, 0.0))
