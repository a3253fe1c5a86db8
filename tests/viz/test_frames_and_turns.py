"""Frames of the 2D views and the revolution cutter, on made-up data with known answers."""

from __future__ import annotations

import math

import numpy as np
import pytest

from drill_sim_ros.viz.frames import (
    Extents,
    box_frame,
    es_frame,
    es_reference,
    nice_step,
    polar_frame,
)
from drill_sim_ros.viz.paper_units import PaperUnits
from drill_sim_ros.viz.turns import TurnTracker


@pytest.mark.parametrize("span", [0.013, 0.9, 1.66, 7.3, 9.8, 420.0])
def test_nice_steps_are_1_2_5_and_give_about_five_ticks(span: float) -> None:
    step = nice_step(span)
    mantissa = step / 10.0 ** math.floor(math.log10(step))
    assert round(mantissa, 9) in (1.0, 2.0, 5.0)
    assert 2 <= span / step <= 5.0 + 1e-9


def test_a_box_frame_holds_its_data_on_whole_ticks_with_the_asked_shape() -> None:
    frame = box_frame(-0.3, 9.8, 0.0, 2.33, aspect=4.0 / 3.0)
    (x_lo, x_hi), (y_lo, y_hi) = frame.x_range, frame.y_range
    assert x_lo <= -0.3 and x_hi >= 9.8 and y_lo <= 0.0 and y_hi >= 2.33
    for value, step in ((x_lo, frame.x_step), (x_hi, frame.x_step), (y_hi, frame.y_step)):
        assert value / step == pytest.approx(round(value / step))
    width = (x_hi - x_lo) * frame.x_scale
    assert width / frame.height == pytest.approx(4.0 / 3.0)
    stored = frame.stored(np.array([9.8]), np.array([2.33]))[0]
    (bx_lo, bx_hi), (by_lo, by_hi) = frame.bounds()
    assert bx_lo <= stored[0] <= bx_hi and by_lo <= stored[1] <= by_hi


@pytest.mark.parametrize("r_max", [2.0, 2.7, 9.0, 51.0])
def test_the_polar_frame_holds_the_radius_with_equal_scales(r_max: float) -> None:
    frame = polar_frame(r_max)
    assert frame.x_range[1] >= r_max and frame.x_range == frame.y_range
    assert frame.x_scale == frame.y_scale
    assert frame.x_range[1] / max(1.0, frame.x_step) <= 8     # a handful of circles


def test_es_frame_keeps_the_reference_points_and_the_data_but_not_outliers() -> None:
    units = PaperUnits.load("field_8p5in_shale_lumped")
    extents = Extents()
    extents.add(np.array([1.0]), np.array([1.0]), np.array([1.0]),
                s=np.array([1.4, 2.2, np.nan, 1e6]), e=np.array([1.1, 1.4, np.nan, 1e6]))
    frame = es_frame(units, extents)
    ref = es_reference(units)
    for s, e in [*ref, (1.4, 1.1), (2.2, 1.4)]:
        assert frame.x_range[0] < s < frame.x_range[1]
        assert frame.y_range[0] < e < frame.y_range[1]
    assert frame.x_range[1] < 10.0 * ref[:, 0].max()           # the 1e6 outlier is cut


def _spiral(n: int) -> tuple[np.ndarray, np.ndarray]:
    t = np.arange(n) * 0.01
    angle = 2.0 * np.pi * 0.7 * t + 0.3 * np.sin(3.0 * t) ** 2     # never backwards
    return t, angle


def test_turns_are_whole_revolutions_closed_by_the_next_sample() -> None:
    t, angle = _spiral(2000)
    turns = TurnTracker().add(t, angle, np.cos(angle), np.sin(angle), np.zeros_like(t))
    index = np.floor(angle / (2.0 * np.pi))
    assert len(turns) == int(index[-1])                    # the unfinished last one is held
    for turn in turns:
        rows = np.searchsorted(t, turn.t)
        assert len(set(index[rows[:-1]])) == 1             # one revolution...
        assert index[rows[-1]] == index[rows[0]] + 1       # ...closed by the next sample


def test_turns_do_not_depend_on_how_the_samples_are_batched() -> None:
    t, angle = _spiral(2000)
    args = (t, angle, np.cos(angle), np.sin(angle), np.zeros_like(t))
    whole = TurnTracker().add(*args)
    tracker, parts = TurnTracker(), []
    for a in range(0, 2000, 137):
        parts += tracker.add(*(x[a:a + 137] for x in args))
    assert len(parts) == len(whole)
    for p, w in zip(parts, whole, strict=True):
        np.testing.assert_array_equal(p.t, w.t)
        np.testing.assert_array_equal(p.x, w.x)
