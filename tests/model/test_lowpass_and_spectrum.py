"""model.analysis's low-pass and spectrum against analytic cases: sines through the known
gain |H(f)|^2 = 1 / (1 + (f/fc)^8), a step that must not wrap round, a sine's amplitude and
frequency read off the spectrum."""

from __future__ import annotations

import numpy as np
import pytest

from drill_sim_ros.model import analysis

PERIOD_S = 0.01
CUTOFF_HZ = 2.5


def _amplitude(t: np.ndarray, x: np.ndarray, freq_hz: float) -> float:
    """Least-squares amplitude of the sine of ``freq_hz`` in ``x`` (with a constant)."""
    w = 2 * np.pi * freq_hz * t
    basis = np.column_stack((np.sin(w), np.cos(w), np.ones_like(t)))
    coef = np.linalg.lstsq(basis, x, rcond=None)[0]
    return float(np.hypot(coef[0], coef[1]))


def test_a_sine_either_side_of_the_cutoff_through_its_gain() -> None:
    t = np.arange(0.0, 60.0, PERIOD_S)
    low_hz, high_hz = 0.2 * CUTOFF_HZ, 2.0 * CUTOFF_HZ
    x = 50.0 + 30.0 * np.sin(2 * np.pi * low_hz * t) + 10.0 * np.sin(2 * np.pi * high_hz * t
                                                                     + 0.3)
    y = analysis.lowpass(x, PERIOD_S, CUTOFF_HZ)
    inner = slice(1000, -1000)                  # 10 s, 25 / fc, from either end
    ti, yi = t[inner], y[inner]
    assert _amplitude(ti, yi, low_hz) == pytest.approx(30.0, rel=1e-3)
    assert _amplitude(ti, yi, high_hz) == pytest.approx(10.0 / (1.0 + 2.0**8), rel=1e-3)
    assert yi.mean() == pytest.approx(50.0, rel=1e-3)            # the mean restored


def test_a_step_does_not_wrap_and_stays_symmetric() -> None:
    """0 then 100: no phase shift, so the step's response is odd about the step (passes
    50 halfway between its two samples); padding by reflection, so the ends keep their
    levels (a circular filter would bleed one end into the other, towards 50)."""
    x = np.where(np.arange(4000) < 2000, 0.0, 100.0)
    y = analysis.lowpass(x, PERIOD_S, CUTOFF_HZ)
    np.testing.assert_allclose(y[:2000] + y[:1999:-1], 100.0, atol=1e-9)
    assert abs(y[0]) < 1e-9 and abs(y[-1] - 100.0) < 1e-9
    assert y[1999] < 50.0 < y[2000]


def test_an_infinite_cutoff_passes_everything() -> None:
    x = np.random.default_rng(0).normal(size=500)
    np.testing.assert_allclose(analysis.lowpass(x, PERIOD_S, np.inf), x, atol=1e-12)
    with pytest.raises(ValueError, match="positive"):
        analysis.lowpass(x, PERIOD_S, 0.0)


def test_a_sine_reads_its_amplitude_and_frequency_off_the_spectrum() -> None:
    duration_s = 40.0
    t = np.arange(0.0, duration_s, PERIOD_S)
    x = 7.0 + 3.0 * np.sin(2 * np.pi * 0.7 * t) + 1.0 * np.sin(2 * np.pi * 16.3 * t)
    freq_hz, amplitude = analysis.amplitude_spectrum(x, PERIOD_S)
    assert amplitude.max() == pytest.approx(3.0, rel=0.01)        # the Hann scalloping
    assert freq_hz[-1] == pytest.approx(0.5 / PERIOD_S)           # up to Nyquist
    bin_hz = 1.0 / duration_s
    assert analysis.spectral_peak(x, PERIOD_S) == pytest.approx((0.7, 3.0), abs=bin_hz)
    high_hz, high = analysis.spectral_peak(x, PERIOD_S, low_hz=5.0)
    assert high_hz == pytest.approx(16.3, abs=bin_hz) and high == pytest.approx(1.0, rel=0.01)
    assert analysis.spectral_peak(np.full(100, 7.0), PERIOD_S) is None
