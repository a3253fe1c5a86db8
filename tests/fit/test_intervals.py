"""The fit's profile intervals (fit.intervals) against least squares' statistics: on a
misfit quadratic in the parameters the profile interval is Student's t interval, and with
noise that moves many residuals together (as a replay's slips do) the intervals cover the
truth 95 % of the time, where the plain profile interval does not."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.stats import t as student

from drill_sim_ros.fit.intervals import jackknife_sd, profile_intervals

RESIDUALS = 60
REPLAYS = 12                  # averaged per point, as the fit does
SENSITIVITY = 8               # sensitivity replays, as the fit measures
TRIALS = 400


def _design(rng: np.random.Generator) -> np.ndarray:
    """Two correlated columns (correlation about 0.6), scaled so that one unit of noise
    moves the parameters by about 0.01 in u."""
    a = rng.standard_normal((RESIDUALS, 2))
    a[:, 1] = 0.6 * a[:, 0] + 0.8 * a[:, 1]
    return 12.0 * a


def test_on_a_quadratic_misfit_the_profile_interval_is_students() -> None:
    """Residuals linear in u with noise of sd 2 under weights that assume 1: the interval
    is u* +- t(0.975, m - n) s sqrt((A^T A)^-1_ii), s^2 the residuals' mean square over
    their degrees of freedom, for each of two correlated parameters."""
    rng = np.random.default_rng(5)
    a = _design(rng)
    y = a @ np.array([0.4, 0.6]) + 2.0 * rng.standard_normal(RESIDUALS)
    u_best = np.linalg.lstsq(a, y, rcond=None)[0]
    r_best = a @ u_best - y
    bands = profile_intervals(lambda us: [a @ u - y for u in us], u_best, r_best, a,
                              np.zeros((0, RESIDUALS)), REPLAYS)
    dof = RESIDUALS - 2
    s = np.sqrt(r_best @ r_best / dof)
    half = student.ppf(0.975, dof) * s * np.sqrt(np.diag(np.linalg.inv(a.T @ a)))
    assert s == pytest.approx(2.0, rel=0.25)            # the noise level is read, not set
    assert np.allclose(bands.low, u_best - half, rtol=0, atol=1e-9)
    assert np.allclose(bands.high, u_best + half, rtol=0, atol=1e-9)


def _coverage(with_scatter: bool) -> float:
    """The share of TRIALS logs whose intervals cover the truth (both parameters counted),
    each log's residuals carrying, besides independent noise of sd 1, a realisation z v
    (z ~ N(0, 1), one per run) that moves the optimum by three times the noise's standard
    error; the model's residuals average REPLAYS runs' realisations (the same at every u)."""
    rng = np.random.default_rng(11)
    a = _design(rng)
    c0 = np.linalg.inv(a.T @ a)
    pattern = a @ (3.0 * np.sqrt(np.diag(c0)) * np.array([1.0, -1.0]))
    truth = np.array([0.45, 0.55])
    covered = 0
    for _ in range(TRIALS):
        y = a @ truth + rng.standard_normal(RESIDUALS) + rng.standard_normal() * pattern
        replayed = rng.standard_normal(REPLAYS).mean() * pattern
        sensitivity = rng.standard_normal(SENSITIVITY)
        scatter = np.outer(sensitivity - sensitivity.mean(), pattern) if with_scatter \
            else np.zeros((0, RESIDUALS))

        def residuals(u: np.ndarray, y: np.ndarray = y, replayed: np.ndarray = replayed
                      ) -> np.ndarray:
            return a @ u + replayed - y
        u_best = np.linalg.lstsq(a, y - replayed, rcond=None)[0]
        bands = profile_intervals(lambda us, f=residuals: [f(u) for u in us], u_best,
                                  residuals(u_best), a, scatter, REPLAYS)
        covered += int(np.sum((bands.low <= truth) & (truth <= bands.high)))
    return covered / (2 * TRIALS)


def test_intervals_cover_the_truth_95_percent_with_correlated_replay_noise() -> None:
    """About 95 % (the binomial sd over 800 is 0.8 %; the sensitivity replays' Student's t
    makes them a little wider), where the profile alone covers about half the time."""
    assert 0.93 <= _coverage(True) <= 0.99
    assert _coverage(False) < 0.7


def _rough_fits() -> tuple[float, float, float]:
    """TRIALS fits of a misfit 1e5 (t - t*)^2 + 100 that every evaluation draws with noise of
    sd 10 (a replay average's roughness), each the lowest of 30 evaluations 0.02 either side
    of t*, its interval given that sd: the share of intervals covering t*, their median
    half-width and the fits' standard deviation about t*."""
    rng = np.random.default_rng(3)
    size, truth, sd = 200, 0.5, 10.0

    def residuals(u: np.ndarray) -> np.ndarray:
        misfit = 1e5 * (u[0] - truth)**2 + 100.0 + sd * rng.standard_normal()
        return np.full(size, np.sqrt(max(misfit, 0.0) / size))
    covered, halves, errors = 0, [], []
    for _ in range(TRIALS):
        tried = [np.array([truth + t]) for t in np.linspace(-0.02, 0.02, 30)]
        rs = [residuals(u) for u in tried]
        best = int(np.argmin([r @ r for r in rs]))
        bands = profile_intervals(lambda us: [residuals(u) for u in us], tried[best], rs[best],
                                  np.ones((size, 1)), np.zeros((0, size)), REPLAYS, sd)
        covered += int(bands.low[0] <= truth <= bands.high[0])
        halves.append(0.5 * (bands.high[0] - bands.low[0]))
        errors.append(tried[best][0] - truth)
    return covered / TRIALS, float(np.median(halves)), float(np.std(errors))


def test_intervals_cover_the_minimum_of_a_rough_misfit() -> None:
    """At least 95 % less the binomial spread (sd 1.1 % over 400), and not by being wide:
    the median half-width under 2.5 times the 1.96 sd of the fits about the minimum."""
    coverage, half, spread = _rough_fits()
    assert coverage >= 0.93
    assert half < 2.5 * 1.96 * spread


def test_the_jackknife_reads_the_spread_of_a_statistic_of_an_average() -> None:
    """The jackknife sd of the squared norm of the mean of 12 draws (each 40 values with
    sd 1 about 0.3) against its spread over 2000 independent sets of draws, on average
    over 200 sets: not below it (the jackknife's variance errs high, Efron and Stein 1981)
    and within 30 % of it."""
    rng = np.random.default_rng(4)

    def statistic(mean: np.ndarray) -> float:
        return float(mean @ mean)
    spread = np.std([statistic(rng.normal(0.3, 1.0, (12, 40)).mean(axis=0))
                     for _ in range(2000)])
    read = np.mean([jackknife_sd(statistic, rng.normal(0.3, 1.0, (12, 40)))
                    for _ in range(200)])
    assert spread <= read <= 1.3 * spread


def test_a_profile_that_meets_another_parameters_bound_rises_there() -> None:
    """Two nearly interchangeable parameters (columns correlated 0.995), the second's
    optimum 0.05 above its lower bound: along the first's profile the second falls about
    as fast as the first rises and meets its bound at t = 0.05, before the valley's misfit
    has risen. Held at its bound, the misfit rises; the interval's upper end is where the
    profile under the bound, computed here in closed form, has risen by the threshold
    (it read the first parameter's own bound, 1.0, when such points were skipped)."""
    from scipy.optimize import brentq
    from scipy.stats import f as fisher
    rng = np.random.default_rng(3)
    x, y = rng.standard_normal((2, RESIDUALS))
    a = 12.0 * np.column_stack((x, 0.995 * x + np.sqrt(1 - 0.995**2) * y))
    u_best = np.array([0.5, 0.05])
    noise = rng.standard_normal(RESIDUALS)
    noise -= a @ np.linalg.lstsq(a, noise, rcond=None)[0]     # the optimum stays u_best
    bands = profile_intervals(lambda us: [a @ (u - u_best) + noise for u in us], u_best,
                              noise, a, np.zeros((0, RESIDUALS)), REPLAYS)
    c0 = np.linalg.inv(a.T @ a)
    slope = c0[1, 0] / c0[0, 0]                    # the second's conditional optimum

    def risen(t: float) -> float:
        second = max(0.0, u_best[1] + slope * t)   # convex in it: the bound is its optimum
        r = a @ (np.array([u_best[0] + t, second]) - u_best) + noise
        return float(r @ r - noise @ noise)
    dof = RESIDUALS - 2
    rise = noise @ noise / dof * fisher.ppf(0.95, 1, dof)
    free = np.sqrt(rise * c0[0, 0])                # where the profile without bounds rises
    bounded = brentq(lambda t: risen(t) - rise, 0.0, 1.0 - u_best[0])
    assert -1.2 < slope < -0.8 and free > 0.08 > 0.05 / -slope   # the case is as described
    assert bounded < 0.08
    assert bands.high[0] - u_best[0] == pytest.approx(bounded, rel=0.15)


def test_a_profile_direction_moves_the_other_parameter_to_its_conditional_optimum() -> None:
    """For two parameters, the profile's (and the bracket's) direction of parameter i moves
    it by one and the other j by the least-squares optimum of |J_i + J_j d|^2 over d,
    d = -(J_i . J_j) / (J_j . J_j) (the projection, computed here without the inverse the
    code uses); the bracket's points lie on those lines, ``share`` times its steps out."""
    from drill_sim_ros.fit import engine
    from drill_sim_ros.fit.intervals import profile_directions
    a = _design(np.random.default_rng(7))
    directions = profile_directions(a)
    for i, j in ((0, 1), (1, 0)):
        assert directions[i, i] == pytest.approx(1.0)
        assert directions[j, i] == pytest.approx(-(a[:, i] @ a[:, j]) / (a[:, j] @ a[:, j]))
    assert abs(directions[1, 0]) > 0.3                # correlated: not the axis
    u = np.array([0.5, 0.5])
    points = engine._bracket(u, directions, 0.5)
    steps = [0.5 * h for h in engine.BRACKET_STEPS]
    expected = [u + s * side * directions[:, i] for i in (0, 1) for side in (1, -1)
                for s in steps]
    assert len(points) == len(expected)
    for p in points:
        assert min(np.max(np.abs(p - e)) for e in expected) < 1e-12


def _parabola_bands(plateau: float | None, misfit_sd: float = 5.0):
    """The interval of one parameter whose misfit is 100 + 1e5 (u - 0.5)^2, or below
    u = 0.485 (between the profile's first and second steps down) ``plateau``: a misfit that
    jumps there and stays, as when a replay's break-away moves by a sample."""
    size = 100

    def residuals(u: np.ndarray) -> np.ndarray:
        t = float(u[0]) - 0.5
        misfit = plateau if plateau is not None and t < -0.015 else 100.0 + 1e5 * t**2
        return np.full(size, np.sqrt(misfit / size))
    u_best = np.array([0.5])
    return profile_intervals(lambda us: [residuals(u) for u in us], u_best,
                             residuals(u_best), np.ones((size, 1)), np.zeros((0, size)),
                             REPLAYS, misfit_sd)


def test_a_cliff_on_one_side_does_not_move_the_other_sides_bound() -> None:
    """On a parabola the interval's half-width is sqrt(rise / 1e5), rise = s^2 F(0.95; 1,
    dof) + z(0.95) sqrt(2) sd. A cliff on one side (the misfit jumps to 50 times the
    optimum's beyond the first step) puts that side's bound between the step below and the
    cliff, and leaves the other side's as it is (a parabola fitted through the cliff's
    points lifted the level the rise is counted from: that bound moved five times as far)."""
    from scipy.stats import f as fisher
    from scipy.stats import norm
    dof = 100 - 1
    rise = 100.0 / dof * fisher.ppf(0.95, 1, dof) + norm.ppf(0.95) * np.sqrt(2.0) * 5.0
    half = np.sqrt(rise / 1e5)
    smooth, cliffed = _parabola_bands(None), _parabola_bands(5e3)
    assert smooth.low[0] == pytest.approx(0.5 - half, abs=1e-9)
    assert smooth.high[0] == pytest.approx(0.5 + half, abs=1e-9)
    assert cliffed.high[0] == pytest.approx(0.5 + half, abs=1e-9)
    assert 0.48 <= cliffed.low[0] <= 0.49
