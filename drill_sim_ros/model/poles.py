"""Damped complex exponentials in a ring-down record: their poles s = -sigma + i omega_d.

ROS-free, numpy only. The free response of a linear system is a sum of damped exponentials
c z^n with z = exp(s dt). The matrix pencil (Hua & Sarkar 1990, IEEE Trans. ASSP 38(5))
finds the poles from the record itself, so it copes with heavy damping (a mode with
zeta = 0.4 rings for a couple of cycles), where spectral peaks and envelope fits fail.

Before the fit the record is differenced (a constant offset drops out), low-passed by a
short FIR filter and decimated. A linear filter changes the amplitude of each exponential,
never its pole, once the filter's own length has passed; a short filter keeps its stop band
for the strongly damped poles too (evaluated off the unit circle, an FIR of length T loses
up to exp(sigma T) of its attenuation).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

BLACKMAN_TRANSITION = 5.5      # width of a Blackman-windowed sinc's transition, x rate / taps
STOP_OVER_KEEP = 4.0           # the stop band starts at this multiple of the highest kept mode
GROWING_LIMIT = 1.01           # |z| above this: a spurious growing pole, dropped


@dataclass(frozen=True)
class Decimation:
    """A low-pass FIR (``taps`` long, cut-off ``cutoff_hz``) then every ``every``-th sample."""

    taps: int
    cutoff_hz: float
    every: int

    def rate_hz(self, sample_hz: float) -> float:
        return sample_hz / self.every


def plan_decimation(sample_hz: float, keep_hz: float, max_filter_s: float) -> Decimation:
    """A decimation that keeps the modes up to ``keep_hz``: the filter's transition runs
    from 1.5 x to STOP_OVER_KEEP x ``keep_hz`` if a filter of ``max_filter_s`` allows it
    (else it is wider, the pass band kept to at least 1.2 x ``keep_hz``), and the decimated
    Nyquist frequency is where the stop band starts."""
    wanted_s = BLACKMAN_TRANSITION / ((STOP_OVER_KEEP - 1.5) * keep_hz)
    taps = max(5, int(min(wanted_s, max_filter_s) * sample_hz)) | 1
    half_width_hz = 0.5 * BLACKMAN_TRANSITION * sample_hz / taps
    cutoff_hz = max(STOP_OVER_KEEP * keep_hz - half_width_hz, 1.2 * keep_hz)
    every = max(1, int(sample_hz / (2.0 * (cutoff_hz + half_width_hz))))
    return Decimation(taps, cutoff_hz, every)


def lowpass_taps(cutoff_hz: float, sample_hz: float, taps: int) -> np.ndarray:
    """A Blackman-windowed sinc low-pass of ``taps`` (odd) coefficients, unit gain at 0 Hz."""
    n = np.arange(taps) - 0.5 * (taps - 1)
    h = np.sinc(2.0 * cutoff_hz / sample_hz * n) * np.blackman(taps)
    return h / h.sum()


def decimate(signal: np.ndarray, plan: Decimation, sample_hz: float) -> np.ndarray:
    """``signal`` (1-D, at ``sample_hz``) differenced, filtered (only the samples after the
    filter's transient) and decimated by ``plan``."""
    h = lowpass_taps(plan.cutoff_hz, sample_hz, plan.taps)
    return np.convolve(np.diff(signal), h, mode="valid")[::plan.every]


@dataclass(frozen=True)
class PoleFit:
    """One model order's poles s (1/s, complex) and the magnitude of their amplitudes."""

    poles_per_s: np.ndarray
    amplitudes: np.ndarray


def matrix_pencil(record: np.ndarray, dt_s: float, orders: list[int]) -> list[PoleFit]:
    """The poles of ``record`` (1-D, step ``dt_s``) for each model order in ``orders``: the
    right singular vectors V of its Hankel matrix (pencil parameter N / 3), truncated to
    the order, give the poles as the eigenvalues of pinv(V[:-1]) V[1:]; the amplitudes are
    the least-squares fit of the exponentials to the record."""
    y = record / np.max(np.abs(record))
    pencil = y.size // 3
    _, _, vh = np.linalg.svd(np.lib.stride_tricks.sliding_window_view(y, pencil + 1),
                             full_matrices=False)
    fits = []
    for order in orders:
        v = vh[:min(order, pencil - 1)].conj().T
        z = np.linalg.eigvals(np.linalg.pinv(v[:-1]) @ v[1:])
        z = z[(np.abs(z) < GROWING_LIMIT) & (z != 0.0)]
        powers = np.vander(z, y.size, increasing=True).T
        amps = np.linalg.lstsq(powers, y.astype(complex), rcond=None)[0]
        fits.append(PoleFit(np.log(z) / dt_s, np.abs(amps)))
    return fits


MODE_WINDOW = 0.1   # a pole or peak names a mode within +-10 % of its frequency


def damping_ratio_near(fits: list[PoleFit], omega_rad_s: float, window: float = MODE_WINDOW,
                       floor: float = 0.01, present: float = 1e-3) -> float | None:
    """The damping ratio sigma / |s| of the pole nearest ``omega`` in |s| among those within
    +-``window`` of it whose amplitude is at least ``floor`` of the largest there and
    ``present`` of the largest of the fit, as the median over the model orders of ``fits``
    (a stable pole is found at every order, a spurious one moves); None if no order has a
    pole there."""
    found = []
    for fit in fits:
        s, amps = fit.poles_per_s, fit.amplitudes
        near = ((s.imag > 0.0) & (np.abs(np.abs(s) / omega_rad_s - 1.0) < window)
                & (amps >= present * amps.max()))
        if not near.any():
            continue
        strong = np.flatnonzero(near & (amps >= floor * amps[near].max()))
        best = s[strong[np.argmin(np.abs(np.abs(s[strong]) - omega_rad_s))]]
        found.append(-best.real / abs(best))
    return float(np.median(found)) if found else None


def damping_ratios(record: np.ndarray, sample_hz: float, plan: Decimation,
                   modes_hz: list[float], modes_in_band: int) -> list[float | None]:
    """The damping ratio of each mode at ``modes_hz`` in a ring-down ``record`` at
    ``sample_hz``, decimated by ``plan`` and fitted with 2 x ``modes_in_band`` (the modes
    below the decimated Nyquist frequency) plus 0, 4, 8 and 12 poles."""
    y = decimate(record, plan, sample_hz)
    fits = matrix_pencil(y, 1.0 / plan.rate_hz(sample_hz),
                         [2 * modes_in_band + extra for extra in (0, 4, 8, 12)])
    return [damping_ratio_near(fits, 2.0 * math.pi * f) for f in modes_hz]
