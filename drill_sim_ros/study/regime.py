"""The regime of a run: trivial, axial vibration only, stick-slip or bit bouncing.

RGD07 Sec. 4: below the critical delay the trivial motion (eq. 34) is stable and a small
perturbation dies out; above it the axial vibration grows and, with beta < 1, ends in a
stick-slip limit cycle (Sec. 4.3); large W0' makes the bit bounce (delta < 0, Sec. 5.4).
The classification reads the statistics window (the limit cycle) for stick, and the whole
run for bouncing, which the paper treats as the end of a run.
"""

from __future__ import annotations

import math

TRIVIAL = 0
AXIAL = 1
STICK_SLIP = 2
BOUNCING = 3
REGIME_NAMES = ("trivial", "axial vibration only", "stick-slip", "bit bouncing")
REGIME_COLORS = ("#d9d9d9", "#80b1d3", "#fb8072", "#6a3d9a")
KAPPA_TRIVIAL = 1e-3      # below it the wearflat keeps (almost) permanent contact (eq. 42)


def trivial_kappa(w0: float, lam: float) -> float:
    """kappa of the trivial motion: 0 when W0 > lambda (full contact, eq. 34); when
    W0 <= lambda the bit slides on its wearflats with W_f = W0 (eq. 18), so 1 - W0/lambda."""
    return 1.0 - min(w0, lam) / lam if lam > 0 else 0.0


def classify(stick_fraction: float, bounce_tau: float, kappa: float,
             axial_amplitude: float, perturbation: float, kappa0: float = 0.0) -> int:
    """Regime code from a run's figures.

    bouncing: the bit left the rock at any time (bounce_tau not NaN);
    stick-slip: the bit stuck within the statistics window;
    axial vibration only: contact was lost (kappa above the trivial ``kappa0`` by more than
    KAPPA_TRIVIAL) or the axial velocity oscillates with more than the initial
    perturbation (it grew, RGD07 App. B);
    trivial: otherwise (the perturbation decayed or stayed put).
    """
    if not math.isnan(bounce_tau):
        return BOUNCING
    if stick_fraction > 0.0:
        return STICK_SLIP
    grown = axial_amplitude > max(abs(perturbation), 1e-12)
    if kappa - kappa0 > KAPPA_TRIVIAL or grown:
        return AXIAL
    return TRIVIAL
