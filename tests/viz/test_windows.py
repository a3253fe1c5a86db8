"""Sliding-window statistics against brute force and analysis.severity."""

from __future__ import annotations

import numpy as np
import pytest

from drill_sim_ros.model.analysis import severity
from drill_sim_ros.viz.windows import SlidingWindow, window_max


def brute_windows(t: np.ndarray, length: float) -> list[np.ndarray]:
    return [np.flatnonzero((t > ti - length) & (t <= ti)) for ti in t]


def test_window_max_equals_brute_force() -> None:
    rng = np.random.default_rng(1)
    x = rng.normal(size=500)
    starts = rng.integers(0, 400, size=200)
    ends = starts + rng.integers(1, 100, size=200)
    got = window_max(x, starts, ends)
    want = [x[s:e].max() for s, e in zip(starts, ends, strict=True)]
    np.testing.assert_array_equal(got, want)


@pytest.mark.parametrize("batch", [1, 7, 25, 1000])
def test_batches_give_the_same_windows_as_one_pass(batch: int) -> None:
    rng = np.random.default_rng(2)
    t = np.cumsum(rng.uniform(0.005, 0.015, size=600))
    x = rng.normal(size=(600, 2))
    window = SlidingWindow(0.5, 2)
    means, maxima = [], []
    for i in range(0, len(t), batch):
        w = window.extend(t[i:i + batch], x[i:i + batch])
        means.append(w.mean(0))
        maxima.append(w.maximum(1))
    for i, rows in enumerate(brute_windows(t, 0.5)):
        assert np.concatenate(means)[i] == pytest.approx(x[rows, 0].mean(), rel=1e-12, abs=1e-12)
        assert np.concatenate(maxima)[i] == x[rows, 1].max()


def test_ssi_of_a_window_matches_analysis_severity() -> None:
    rng = np.random.default_rng(3)
    t = np.arange(400) * 0.01
    rpm = np.maximum(0.0, 60 + 50 * np.sin(t * 3) + rng.normal(size=400))
    w = SlidingWindow(1.0, 1).extend(t, rpm[:, None])
    ssi = (w.maximum(0) - w.minimum(0)) / (2 * w.mean(0))
    for i, rows in enumerate(brute_windows(t, 1.0)):
        assert ssi[i] == pytest.approx(severity(rpm[rows], 60.0).ssi, rel=1e-12)


def test_window_length_must_be_positive() -> None:
    with pytest.raises(ValueError, match="window"):
        SlidingWindow(0.0, 1)
