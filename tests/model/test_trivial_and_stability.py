"""Trivial solution (eq. 34) and linear stability (Appendix B) against the simulation."""

from __future__ import annotations

import numpy as np
import pytest

from drill_sim_ros.model import analysis as an
from drill_sim_ros.model import kernel as k
from drill_sim_ros.model.params import DimensionlessParams
from tests.model.helpers import FIG8A, run

# tau_n0 = 2 pi / (n omega0) = 0.209 < tau_nc = pi / sqrt(2 n psi) = 0.406 for psi = 5
STABLE = DimensionlessParams(n=6, psi=5.0, beta=0.3, lam=5.0, w0=7.0, omega0=5.0)


def _deviation(rows: np.ndarray, p: DimensionlessParams) -> float:
    triv = an.trivial_solution(p)
    return max(float(np.max(np.abs(rows[:, k.C_V] - triv.v))),
               float(np.max(np.abs(rows[:, k.C_OMEGA] - p.omega0))),
               float(np.max(np.abs(rows[:, k.C_WOB] - p.w0))),
               float(np.max(np.abs(rows[:, k.C_TOB] - triv.torque))),
               float(np.max(np.abs(rows[:, k.C_DOC] - triv.depth_of_cut))))


def test_trivial_solution_eq34() -> None:
    p = FIG8A
    triv = an.trivial_solution(p)
    assert triv.v == pytest.approx(p.omega0 / (2 * np.pi) * (p.w0 - p.lam))
    assert triv.torque == pytest.approx(p.w0 + p.lam * (p.beta - 1.0))
    assert triv.depth_of_cut == pytest.approx(2 * np.pi * triv.v / p.omega0)   # eq. 26


def test_no_drilling_when_weight_below_contact_capacity() -> None:
    p = FIG8A.with_(w0=3.0)                   # W0 <= lam: V0 = 0, T0 = beta W0 (eq. 18)
    triv = an.trivial_solution(p)
    assert (triv.v, triv.torque) == (0.0, pytest.approx(p.beta * p.w0))


def test_below_critical_delay_stays_on_trivial_solution() -> None:
    assert an.trivial_delay(STABLE) < an.critical_delay(STABLE)
    _, rows = run(STABLE, 60.0, every=10)
    assert _deviation(rows, STABLE) < 1e-9


def test_above_critical_delay_rounding_noise_grows() -> None:
    """Zero perturbation: only rounding noise, which the unstable trivial solution amplifies."""
    assert an.trivial_delay(FIG8A) > an.critical_delay(FIG8A)
    _, early = run(FIG8A, 1.0, every=10)
    _, rows = run(FIG8A, 30.0, every=10)
    assert _deviation(early, FIG8A) < 1e-9          # starts on the trivial solution ...
    assert _deviation(rows, FIG8A) > 1e-3           # ... and leaves it by itself


def test_critical_delay_is_where_the_root_crosses() -> None:
    p = FIG8A
    tau_c = an.critical_delay(p)
    below = an.rightmost_root(p, tau=0.95 * tau_c)
    above = an.rightmost_root(p, tau=1.05 * tau_c)
    at = an.rightmost_root(p, tau=tau_c)
    assert below.real < 0.0 < above.real
    assert abs(at.real) < 1e-6 and at.imag == pytest.approx(np.sqrt(2 * p.n * p.psi))  # B.7


def _growth_and_frequency(tau: np.ndarray, x: np.ndarray, after: float) -> tuple[float, float]:
    """Exponential growth rate and angular frequency from the peaks of |x|."""
    ax = np.abs(x)
    peaks = np.flatnonzero((ax[1:-1] > ax[:-2]) & (ax[1:-1] >= ax[2:])) + 1
    peaks = peaks[tau[peaks] > after]
    rate = np.polyfit(tau[peaks], np.log(ax[peaks]), 1)[0]
    return float(rate), float(np.pi / np.mean(np.diff(tau[peaks])))


@pytest.mark.parametrize("method", ["profile", "exact"])
def test_growth_of_small_perturbation_matches_rightmost_root(method: str) -> None:
    p = FIG8A
    root = an.rightmost_root(p)
    _, rows = run(p, 6.0, dtau=1e-5, every=5, perturb_v=1e-9, method=method)
    v_dev = rows[:, k.C_V] - an.trivial_solution(p).v
    assert np.max(np.abs(v_dev)) < 0.2 * an.trivial_solution(p).v   # still linear: no lift-off
    rate, freq = _growth_and_frequency(rows[:, k.C_TAU], v_dev, after=2.0)
    print(f"growth rate {rate:.4f} vs root {root.real:.4f}; frequency {freq:.4f} vs "
          f"{root.imag:.4f}")
    assert rate == pytest.approx(root.real, rel=0.02)
    assert freq == pytest.approx(root.imag, rel=0.02)


@pytest.mark.parametrize("omega0", [0.05, 0.01, 1e-4])
def test_rightmost_root_of_a_long_delay_lies_between_its_asymptotic_bounds(omega0) -> None:
    """omega0 -> 0 makes tau_n0 = 2 pi / (n omega0) long; exp(-s tau) once overflowed.

    For tau >> 1 the unstable roots sit near s = i w, w = sqrt(n psi), s = i w + sigma + i d:
    (B.2) gives |2 i w (sigma + i d)| ~ n psi exp(-sigma tau). With d = 0 that is the upper
    bound sigma_hi exp(sigma_hi tau) = w / 2; the roots are 2 pi / tau apart along Im s, so
    the rightmost has |d| <= pi / tau, whence the lower bound.
    """
    p = DimensionlessParams(n=6, psi=50.0, beta=0.3, lam=5.0, w0=7.0, omega0=omega0)
    tau, npsi = an.trivial_delay(p), p.n * p.psi
    w = np.sqrt(npsi)
    root = an.rightmost_root(p)
    assert abs(root**2 + npsi * (1 - np.exp(-root * tau))) < 1e-6 * npsi
    sigmas = np.linspace(1e-9, 5.0 / tau * np.log(tau), 200_001)
    modulus = npsi * np.exp(-sigmas * tau)
    sigma_hi = sigmas[np.argmin(np.abs(2 * w * sigmas - modulus))]
    sigma_lo = sigmas[np.argmin(np.abs(2 * w * np.hypot(sigmas, np.pi / tau) - modulus))]
    assert sigma_lo <= root.real <= sigma_hi * (1 + 1e-6)
    assert abs(root.imag - w) < 2 * np.pi / tau


def test_rightmost_root_is_undefined_without_rotation() -> None:
    p = DimensionlessParams(n=6, psi=50.0, beta=0.3, lam=5.0, w0=7.0, omega0=0.0)
    assert np.isnan(an.rightmost_root(p).real)
