"""Closed-form and post-processing analysis of the RGD07 model.

* :func:`trivial_solution` - steady drilling, eq. (34) (and eq. 18 when W0 <= lambda);
* :func:`critical_delay`, :func:`rightmost_root` - linear stability, Appendix B (B.2, B.7);
* :func:`cycle_averages` - kappa (42), eta (43), the identities (44)-(47), E and S (48);
* :func:`kappa_from_depth` - kappa from the mean depth of cut (45a);
* :func:`severity` - stick-slip severity index and under-torque ratio of bit rpm;
* :func:`lowpass`, :func:`amplitude_spectrum`, :func:`spectral_peak` - a zero-phase
  low-pass and the spectrum of a uniformly sampled record (numpy only).
"""

from __future__ import annotations

import cmath
import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from drill_sim_ros.model import kernel as k
from drill_sim_ros.model.params import DimensionlessParams


@dataclass(frozen=True)
class TrivialSolution:
    """Steady drilling (eq. 34): rate of penetration v0, depth of cut delta0, torque T0, and
    the wearflat force W_f = min(W0, lam) it carries."""

    v: float
    depth_of_cut: float
    torque: float
    wob: float
    omega: float
    wearflat: float


def trivial_solution(p: DimensionlessParams) -> TrivialSolution:
    """Eq. (34): v0 = omega0 (W0 - lam) / 2 pi, T0 = W0 + lam (beta - 1) when W0 > lam.

    When W0 <= lam the bit slides without cutting (text after eq. 18): v0 = 0, T0 = beta W0.
    """
    doc = max(p.w0 - p.lam, 0.0)
    v = p.omega0 * doc / (2.0 * math.pi)
    wearflat = min(p.w0, p.lam)
    return TrivialSolution(v=v, depth_of_cut=doc, torque=doc + p.beta * wearflat, wob=p.w0,
                           omega=p.omega0, wearflat=wearflat)


def trivial_delay(p: DimensionlessParams) -> float:
    """tau_n0 = 2 pi / (n omega0) (eq. 16, scaled)."""
    return 2.0 * math.pi / (p.n * p.omega0) if p.omega0 > 0 else math.inf


def critical_delay(p: DimensionlessParams) -> float:
    """tau_nc = pi / sqrt(2 n psi) (Appendix B, eq. B.7 with k = 0)."""
    return math.pi / math.sqrt(2.0 * p.n * p.psi)


# Largest -Re(s) tau for which exp(-s tau) is evaluated: exp(709.8) is the largest float.
_EXP_ARG_LIMIT = 700.0


def _char_axial(s: complex, npsi: float, tau: float) -> tuple[complex, complex] | None:
    """P(s) = s^2 + n psi (1 - exp(-s tau)) (B.2) and dP/ds; None where exp overflows.

    At a root |exp(-s tau)| = |1 + s^2 / (n psi)|, so -Re(s) tau <= ln(1 + |s|^2 / (n psi)):
    a point with -Re(s) tau > 700 is no root, nor near one of modulus below sqrt(n psi) e^350.
    """
    if -s.real * tau > _EXP_ARG_LIMIT:
        return None
    e = cmath.exp(-s * tau)
    return s * s + npsi * (1.0 - e), 2.0 * s + npsi * tau * e


def _newton(s: complex, npsi: float, tau: float, iters: int = 60) -> complex | None:
    for _ in range(iters):
        value = _char_axial(s, npsi, tau)
        if value is None or value[1] == 0:
            return None                       # wandered far left, or a stationary point
        f, df = value
        step = f / df
        s -= step
        if abs(step) < 1e-13 * max(1.0, abs(s)):
            return s
    return None


def rightmost_root(p: DimensionlessParams, tau: float | None = None) -> complex:
    """The non-zero root of s^2 + n psi (1 - e^{-s tau}) = 0 (B.2) with the largest real part.

    tau defaults to tau_n0. Newton's method from a grid of starting points covering
    |s| <= 3 sqrt(2 n psi) (all roots with Re s > 0 lie within sqrt(2 n psi), App. B).
    Returns s = growth rate + i * angular frequency (Im s >= 0); NaN + NaN i when the delay
    is infinite (omega0 = 0: the bit does not turn, B.2 has no finite delay).
    """
    tau = trivial_delay(p) if tau is None else tau
    if not math.isfinite(tau):
        return complex(math.nan, math.nan)
    npsi = p.n * p.psi
    radius = math.sqrt(2.0 * npsi)
    best: complex | None = None
    for x in np.linspace(-radius, radius, 9):
        for y in np.linspace(0.05 * radius, 3.0 * radius, 31):
            root = _newton(complex(x, y), npsi, tau)
            if root is None or abs(root) < 1e-8 * radius:
                continue                      # diverged, or the root at the origin (B.3)
            if abs(_char_axial(root, npsi, tau)[0]) > 1e-6 * npsi:
                continue                      # converged onto no root
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


def kappa_from_depth(mean_depth: float, delta0: float, lam: float) -> float:
    """kappa from the mean depth of cut, eq. (45a) solved: (<delta> - delta0) / lam.

    Beside kappa = 1 - <W_f>/lam (eq. 42) it checks the wearflat accounting: the two agree
    over whole cycles because <W> = W0 (eq. 44) and W = delta + W_f (eq. 29) hold in every
    mode, stick included. nan when lam = 0.
    """
    return (mean_depth - delta0) / lam if lam > 0 else math.nan


def efficiency(p: DimensionlessParams, kappa: float) -> float:
    """Drilling efficiency eta = <T_c>/<T> in terms of kappa (eq. 43)."""
    contact = p.lam * (1.0 - kappa)
    return (p.w0 - contact) / (p.w0 - contact * (1.0 - p.beta))


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


def stick_slip_index(lo: ArrayLike, hi: ArrayLike, mean: ArrayLike) -> np.ndarray:
    """SSI = (max - min) / (2 mean) of the bit speed, elementwise; nan where mean <= 0
    (a bit that never turns has no severity)."""
    lo, hi, mean = np.asarray(lo, float), np.asarray(hi, float), np.asarray(mean, float)
    out = np.full(np.broadcast(lo, hi, mean).shape, np.nan)
    np.divide(hi - lo, 2.0 * mean, out=out, where=mean > 0.0)
    return out


def severity_of(lo: float, hi: float, mean: float, omega0: float) -> Severity:
    """:func:`severity` from the min, max and mean of the bit speed."""
    ssi = float(stick_slip_index(lo, hi, mean))
    utr = (omega0 - lo) / omega0 if omega0 > 0 else math.nan
    return Severity(ssi, utr, lo, hi, mean)


def first_event_tau(acc: np.ndarray) -> tuple[float | None, float | None]:
    """(first stick tau, first off-bottom tau), None when it did not happen."""
    def _opt(x: float) -> float | None:
        return None if math.isnan(x) else float(x)
    return _opt(acc[k.A_FIRST_STICK]), _opt(acc[k.A_FIRST_BOUNCE])


# ---- signals: one low-pass, one spectrum ---------------------------------------------------
LOWPASS_ORDER = 4          # the Butterworth order whose forward-backward magnitude is used
SPECTRUM_ZERO_PAD = 8      # zero padding of the spectrum: 8x the record's length


def lowpass(signal: ArrayLike, sample_period_s: float, cutoff_hz: float) -> np.ndarray:
    """``signal`` (uniform samples, shape (n,)) low-passed at ``cutoff_hz``, zero-phase.

    Applied in the frequency domain with the magnitude of a 4th-order Butterworth run
    forward and backward, |H(f)|^2 = 1 / (1 + (f / fc)^8): 1/2 at fc, no phase shift, so
    a stick phase stays where it was. The mean is removed first and restored; the record is
    padded by reflection at both ends (n - 1 samples each, mirrored about the end sample) so
    that the circular convolution of the FFT does not wrap its end onto its start; within
    about 1 / fc of an end, the mirror's kink in slope shows (a record that ends at rest,
    e.g. a stuck bit, is exact there). An infinite ``cutoff_hz`` passes everything."""
    x = np.asarray(signal, dtype=float)
    if not cutoff_hz > 0.0:
        raise ValueError(f"cutoff_hz = {cutoff_hz!r} must be positive")
    if x.size < 2:
        return x.copy()
    mean = float(x.mean())
    pad = x.size - 1
    padded = np.pad(x - mean, pad, mode="reflect")
    freq_hz = np.fft.rfftfreq(padded.size, sample_period_s)
    gain = 1.0 / (1.0 + (freq_hz / cutoff_hz) ** (2 * LOWPASS_ORDER))
    out = np.fft.irfft(np.fft.rfft(padded) * gain, n=padded.size)
    return out[pad:pad + x.size] + mean


def amplitude_spectrum(signal: ArrayLike, sample_period_s: float
                       ) -> tuple[np.ndarray, np.ndarray]:
    """(frequency Hz, amplitude) of ``signal`` (uniform samples), mean removed, through a
    Hann window, zero-padded to ``SPECTRUM_ZERO_PAD`` times its length; scaled so that a
    sine of amplitude A reads A at its peak (within the window's scalloping, under 1 %
    with this padding). Its resolution is still 1 / (the record's duration)."""
    x = np.asarray(signal, dtype=float)
    window = np.hanning(x.size)
    n_fft = SPECTRUM_ZERO_PAD * max(x.size, 1)
    spectrum = np.fft.rfft((x - x.mean()) * window, n_fft) if x.size else np.zeros(1)
    scale = 2.0 / window.sum() if window.sum() > 0 else 0.0
    return np.fft.rfftfreq(n_fft, sample_period_s), np.abs(spectrum) * scale


def spectral_peak(signal: ArrayLike, sample_period_s: float,
                  low_hz: float = 0.0) -> tuple[float, float] | None:
    """(frequency Hz, amplitude) of the peak of :func:`amplitude_spectrum` above
    ``low_hz``; None when there is no spectrum above it or it is zero (a constant record)."""
    freq_hz, amplitude = amplitude_spectrum(signal, sample_period_s)
    above = freq_hz > low_hz
    if not above.any() or not np.any(amplitude[above] > 0.0):
        return None
    peak = int(np.argmax(amplitude[above]))
    return float(freq_hz[above][peak]), float(amplitude[above][peak])


MODE_COUNT = 3          # torsional modes that set the stick-slip cut-off
CUTOFF_PER_MODE = 2.0   # the cut-off, in units of the highest of them


def cutoff_of(modes_hz: tuple[float, ...]) -> float:
    """The cut-off between the string's stick-slip and the collars' ringing (Hz): twice
    the highest of the first MODE_COUNT torsional modes (inf when fewer were found).

    Stick-slip has its fundamental at 1/(1 to 2.5 T1), T1 the first mode's period, and
    needs about a dozen harmonics to keep the shape of its stick phases, which reach past
    the third mode; the collars ring (high-frequency torsional oscillation) an order of
    magnitude higher, 16 Hz on the field preset. Twice f3 lies between the two. The one
    cut-off of the scorecard, its picture and the start-up's scores."""
    if len(modes_hz) < MODE_COUNT:
        return math.inf
    return CUTOFF_PER_MODE * modes_hz[MODE_COUNT - 1]
