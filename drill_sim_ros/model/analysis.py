"""Closed-form and post-processing analysis of the RGD07 model.

* :func:`trivial_solution` - steady drilling, eq. (34) (and eq. 18 when W0 <= lambda);
* :func:`critical_delay`, :func:`rightmost_root` - linear stability, Appendix B (B.2, B.7);
* :func:`cycle_averages` - kappa (42), eta (43), the identities (44)-(47), E and S (48);
* :func:`severity` - stick-slip severity index and under-torque ratio of bit rpm.
"""

from __future__ import annotations

import cmath
import math
from dataclasses import dataclass

import numpy as np

from drill_sim_ros.model import kernel as k
from drill_sim_ros.model.params import DimensionlessParams


@dataclass(frozen=True)
class TrivialSolution:
    """Steady drilling (eq. 34): rate of penetration v0, depth of cut delta0, torque T0."""

    v: float
    depth_of_cut: float
    torque: float
    wob: float
    omega: float


def trivial_solution(p: DimensionlessParams) -> TrivialSolution:
    """Eq. (34): v0 = omega0 (W0 - lam) / 2 pi, T0 = W0 + lam (beta - 1) when W0 > lam.

    When W0 <= lam the bit slides without cutting (text after eq. 18): v0 = 0, T0 = beta W0.
    """
    doc = max(p.w0 - p.lam, 0.0)
    v = p.omega0 * doc / (2.0 * math.pi)
    torque = doc + p.beta * min(p.w0, p.lam)
    return TrivialSolution(v=v, depth_of_cut=doc, torque=torque, wob=p.w0, omega=p.omega0)


def trivial_delay(p: DimensionlessParams) -> float:
    """tau_n0 = 2 pi / (n omega0) (eq. 16, scaled)."""
    return 2.0 * math.pi / (p.n * p.omega0) if p.omega0 > 0 else math.inf


def critical_delay(p: DimensionlessParams) -> float:
    """tau_nc = pi / sqrt(2 n psi) (Appendix B, eq. B.7 with k = 0)."""
    return math.pi / math.sqrt(2.0 * p.n * p.psi)


def _char_axial(s: complex, npsi: float, tau: float) -> tuple[complex, complex]:
    """P(s) = s^2 + n psi (1 - exp(-s tau)) (B.2) and dP/ds."""
    e = cmath.exp(-s * tau)
    return s * s + npsi * (1.0 - e), 2.0 * s + npsi * tau * e


def _newton(s: complex, npsi: float, tau: float, iters: int = 60) -> complex | None:
    for _ in range(iters):
        f, df = _char_axial(s, npsi, tau)
        if df == 0:
            return None
        step = f / df
        s -= step
        if abs(step) < 1e-13 * max(1.0, abs(s)):
            return s
    return None


def rightmost_root(p: DimensionlessParams, tau: float | None = None) -> complex:
    """The non-zero root of s^2 + n psi (1 - e^{-s tau}) = 0 (B.2) with the largest real part.

    tau defaults to tau_n0. Newton's method from a grid of starting points covering
    |s| <= 3 sqrt(2 n psi) (all roots with Re s > 0 lie within sqrt(2 n psi), App. B).
    Returns s = growth rate + i * angular frequency (Im s >= 0).
    """
    tau = trivial_delay(p) if tau is None else tau
    npsi = p.n * p.psi
    radius = math.sqrt(2.0 * npsi)
    best: complex | None = None
    for x in np.linspace(-radius, radius, 9):
        for y in np.linspace(0.05 * radius, 3.0 * radius, 31):
            root = _newton(complex(x, y), npsi, tau)
            if root is None or abs(root) < 1e-8 * radius:
                continue                      # diverged, or the root at the origin (B.3)
            if abs(_char_axial(root, npsi, tau)[0]) > 1e-6 * npsi:
                continue
            root = complex(root.real, abs(root.imag))
            if best is None or root.real > best.real + 1e-12:
                best = root
    if best is None:
        raise ArithmeticError("no characteristic root found")
    return best


@dataclass(frozen=True)
class CycleAverages:
    """Time averages over the statistics window (stick phases included)."""

    kappa: float          # eq. (42): 1 - <W_f>/lam
    eta: float            # eq. (43) evaluated with kappa
    mean_wf: float
    mean_torque: float    # <T>
    mean_depth_of_cut: float  # <delta>
    mean_wob: float       # <W>
    mean_omega: float
    mean_pipe_torque: float   # <PHI_S - PHI> = T0 - <phi>
    mean_rop: float
    specific_energy: float    # E = <T> / <delta> (eq. 48)
    drilling_strength: float  # S = <W> / <delta> (eq. 48)
    omega_min: float
    omega_max: float
    stick_fraction: float
    window_steps: int


def cycle_averages(p: DimensionlessParams, acc: np.ndarray) -> CycleAverages:
    """Averages from the kernel accumulators (``kernel.A_*``) for parameters ``p``."""
    count = acc[k.A_COUNT]
    if count <= 0:
        nan = math.nan
        return CycleAverages(nan, nan, nan, nan, nan, nan, nan, nan, nan, nan, nan, nan, nan,
                             nan, 0)
    mean = {name: acc[idx] / count for name, idx in (
        ("wf", k.A_WF), ("tob", k.A_TOB), ("doc", k.A_DOC), ("wob", k.A_WOB),
        ("omega", k.A_OMEGA), ("tp", k.A_T_PIPE), ("v", k.A_V))}
    kappa = 1.0 - mean["wf"] / p.lam if p.lam > 0 else math.nan
    return CycleAverages(
        kappa=kappa,
        eta=efficiency(p, kappa),
        mean_wf=mean["wf"],
        mean_torque=mean["tob"],
        mean_depth_of_cut=mean["doc"],
        mean_wob=mean["wob"],
        mean_omega=mean["omega"],
        mean_pipe_torque=mean["tp"],
        mean_rop=mean["v"],
        specific_energy=mean["tob"] / mean["doc"],
        drilling_strength=mean["wob"] / mean["doc"],
        omega_min=float(acc[k.A_OMEGA_MIN]),
        omega_max=float(acc[k.A_OMEGA_MAX]),
        stick_fraction=acc[k.A_STUCK] / count,
        window_steps=int(count),
    )


def efficiency(p: DimensionlessParams, kappa: float) -> float:
    """Drilling efficiency eta = <T_c>/<T> in terms of kappa (eq. 43)."""
    contact = p.lam * (1.0 - kappa)
    return (p.w0 - contact) / (p.w0 - contact * (1.0 - p.beta))


def kappa_from_depth(mean_depth: float, delta0: float, lam: float) -> float:
    """kappa from the mean depth of cut, eq. (45a): kappa = (<delta> - delta0) / lam."""
    return (mean_depth - delta0) / lam if lam > 0 else math.nan


def predicted_from_kappa(p: DimensionlessParams, kappa: float) -> dict[str, float]:
    """The mean response implied by kappa alone: eqs. (45), (47), (50)."""
    triv = trivial_solution(p)
    doc = triv.depth_of_cut + kappa * p.lam                     # eq. (45a)
    torque = triv.torque + (1.0 - p.beta) * kappa * p.lam        # eq. (47)
    strength = p.w0 / doc
    return {
        "mean_depth_of_cut": doc,
        "mean_torque": torque,
        "mean_torque_45b": doc + (1.0 - kappa) * p.beta * p.lam,  # eq. (45b)
        "mean_phi": -(1.0 - p.beta) * kappa * p.lam,              # eq. (45c)
        "specific_energy_50": (1.0 - p.beta) + p.beta * strength,  # eq. (50)
    }


@dataclass(frozen=True)
class Severity:
    """Stick-slip severity of a bit-speed record."""

    ssi: float    # (max - min) / (2 mean)
    utr: float    # (omega0 - min) / omega0
    omega_min: float
    omega_max: float
    omega_mean: float


def severity(omega: np.ndarray, omega0: float) -> Severity:
    """SSI = (max - min) / (2 mean) and UTR = (omega0 - min) / omega0 of bit speeds."""
    if omega.size == 0:
        return Severity(math.nan, math.nan, math.nan, math.nan, math.nan)
    return severity_of(float(omega.min()), float(omega.max()), float(omega.mean()), omega0)


def severity_of(lo: float, hi: float, mean: float, omega0: float) -> Severity:
    """:func:`severity` from the min, max and mean of the bit speed."""
    ssi = (hi - lo) / (2.0 * mean) if mean > 0 else math.inf
    utr = (omega0 - lo) / omega0 if omega0 > 0 else math.nan
    return Severity(ssi, utr, lo, hi, mean)


def first_event_tau(acc: np.ndarray) -> tuple[float | None, float | None]:
    """(first stick tau, first off-bottom tau), None when it did not happen."""
    def _opt(x: float) -> float | None:
        return None if math.isnan(x) else float(x)
    return _opt(acc[k.A_FIRST_STICK]), _opt(acc[k.A_FIRST_BOUNCE])
