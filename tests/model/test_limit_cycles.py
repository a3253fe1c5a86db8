"""Limit cycles: Fig. 8 (beta decides stick-slip), identities (44)-(47), (50), Fig. 11 trends."""

from __future__ import annotations

import numpy as np
import pytest

from drill_sim_ros.model import analysis as an
from drill_sim_ros.model.params import DimensionlessParams
from tests.model.helpers import FIG8A, FIG8B, run, whole_cycle_averages


def test_fig8a_beta_below_one_ends_in_stick_slip() -> None:
    sim, _ = run(FIG8A, 600.0, tau_avg=300.0, perturb_v=0.01)
    avg = an.cycle_averages(FIG8A, sim.accumulators)
    stick, _ = an.first_event_tau(sim.accumulators)
    assert stick is not None and stick < 300.0
    assert avg.stick_fraction > 0.0 and avg.omega_min == 0.0
    # "slipping phases where omega increases up to two times the imposed velocity" (Sec. 1)
    assert avg.omega_max / FIG8A.omega0 == pytest.approx(2.0, abs=0.15)


def test_fig8b_beta_above_one_stays_bounded_without_stick() -> None:
    sim, _ = run(FIG8B, 600.0, tau_avg=300.0, perturb_v=0.01)
    avg = an.cycle_averages(FIG8B, sim.accumulators)
    assert an.first_event_tau(sim.accumulators) == (None, None)
    assert avg.omega_min > 0.0 and avg.omega_max < 1.5 * FIG8B.omega0
    assert avg.kappa > 0.0                  # self-excited: intermittent loss of contact


def _identity_errors(p: DimensionlessParams, avg: an.CycleAverages) -> dict[str, float]:
    pred = an.predicted_from_kappa(p, avg.kappa)
    triv = an.trivial_solution(p)
    return {
        "44a W0 = <delta> + (1-kappa) lam": (avg.mean_depth_of_cut
                                            + (1 - avg.kappa) * p.lam - p.w0) / p.w0,
        "44b T0 = <T> + <phi>": (avg.mean_torque + (triv.torque - avg.mean_pipe_torque)
                                 - triv.torque) / triv.torque,
        "45b <T> = <delta> + (1-kappa) beta lam": (avg.mean_torque - pred["mean_torque_45b"])
        / avg.mean_torque,
        "47 <T> = T0 + (1-beta) kappa lam": (avg.mean_torque - pred["mean_torque"])
        / avg.mean_torque,
        "50 E = 1 - beta + beta S": (avg.specific_energy
                                     - (1 - p.beta + p.beta * avg.drilling_strength))
        / avg.specific_energy,
    }


def test_cycle_identities_without_stick_within_0p1_percent() -> None:
    sim, _ = run(FIG8B, 900.0, tau_avg=300.0, perturb_v=0.01)
    avg = an.cycle_averages(FIG8B, sim.accumulators)
    assert avg.stick_fraction == 0.0
    errors = _identity_errors(FIG8B, avg)
    print(errors)
    assert max(abs(e) for e in errors.values()) <= 1e-3, errors


def test_cycle_identities_with_stick_within_1_percent() -> None:
    avg = whole_cycle_averages(FIG8A, cycles=20)
    assert avg.stick_fraction > 0.0
    errors = _identity_errors(FIG8A, avg)
    print(errors)
    assert max(abs(e) for e in errors.values()) <= 1e-2, errors


def test_mean_weight_and_speed_equal_the_surface_inputs_over_whole_cycles() -> None:
    """<U''> = 0 gives <W> = W0; a bounded pipe twist gives <omega> = omega0 (Sec. 5.1)."""
    avg = whole_cycle_averages(FIG8A, cycles=20)
    assert avg.mean_wob == pytest.approx(FIG8A.w0, rel=1e-3)
    assert avg.mean_omega == pytest.approx(FIG8A.omega0, rel=1e-2)


FIG11 = DimensionlessParams(n=6, psi=63.0, beta=0.28, lam=8.0 / 1.7, w0=8.0, omega0=4.0)


def _kappa(p: DimensionlessParams) -> float:
    sim, _ = run(p, 400.0, tau_avg=200.0, perturb_v=0.01)
    return an.cycle_averages(p, sim.accumulators).kappa


@pytest.mark.parametrize(("name", "values", "rising"), [
    ("w0_over_lam", (1.4, 1.7, 2.0), True),
    ("psi", (30.0, 63.0, 120.0), True),
    ("omega0", (3.0, 4.0, 6.0), False),
])
def test_fig11_kappa_trends(name: str, values: tuple[float, ...], rising: bool) -> None:
    def params(value: float) -> DimensionlessParams:
        if name == "w0_over_lam":
            return FIG11.with_(lam=FIG11.w0 / value)
        return FIG11.with_(**{name: value})
    kappas = np.array([_kappa(params(v)) for v in values])
    print(name, values, kappas)
    steps = np.diff(kappas)
    assert np.all(steps > 0) if rising else np.all(steps < 0)
