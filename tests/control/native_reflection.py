"""The field drive's own speed loop through the closed-loop bench, measured once for the
suite: tests/model/test_string.py (|r| against the formula on the log-spaced band) and
tests/control/test_stability.py (the complex r on a few frequencies) read the same two
90 s runs (control.reflection.complex_reflection_with: 30 s settle, 60 s measured, with
and without the pulse), which cost about 30 s on the 2-core CI machine.

Each frequency's ratio is a Fourier sum of its own over the same records
(string_instruments.complex_spectral_ratio), so measuring at the union of the frequencies
gives each test the very numbers a run of its own would."""

from __future__ import annotations

import functools

import numpy as np

from drill_sim_ros.control.reflection import complex_reflection_with
from drill_sim_ros.model import string_instruments as si

FIELD = "field_8p5in_shale"
SECONDS = 60.0
STABILITY_F_HZ = np.array([0.05, 0.2, 1.0, 3.0])     # test_stability's phase check


@functools.cache
def _measured() -> tuple[np.ndarray, np.ndarray]:
    f_hz = np.union1d(si.reflection_frequencies(), STABILITY_F_HZ)
    return f_hz, complex_reflection_with(FIELD, "none", f_hz, seconds=SECONDS)


def native_reflection(f_hz: np.ndarray) -> np.ndarray:
    """r(f) (complex) at ``f_hz``, each one of the frequencies measured here."""
    measured_f, ratio = _measured()
    index = np.searchsorted(measured_f, f_hz)
    assert np.array_equal(measured_f[np.minimum(index, measured_f.size - 1)], f_hz), f_hz
    return ratio[index]
