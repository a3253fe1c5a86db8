"""The 95 % intervals of fitted parameters from the misfit's profile (``drill_sim fit``).

The misfit is S(u) = sum of the weighted residuals squared, u the parameters scaled to their
bounds. For parameter i the profile is S along the line through the optimum u* on which the
other parameters follow their conditional optimum under the Jacobian's quadratic model,
u* + t d_i with d_i = C0[:, i] / C0[i, i] and C0 = (J^T J)^-1 (for a misfit quadratic in u
this is the exact profile; for the replays' misfit the others are not re-optimised at each
point). The profile is evaluated at ``PROFILE_STEPS`` on either side (in u; farther while
the interval reaches past the points evaluated) and a parabola a t^2 + b t + c is fitted to
it by least squares (:func:`vertex`), which follows the misfit over the scale of those
points rather than the slope of its roughness at the optimum (the misfit is an average of
replays whose slips move with the smallest change: along field_8p5in_deviated's static
coefficient it jumped by 21 % between points 0.12 % apart, docs/fit.md). Then:

1. **the profile interval**: the t where the parabola rises above its minimum by
   Delta = s^2 F(0.95; 1, dof), s^2 = S(u*) / dof the noise level estimated from the
   residuals (dof = residuals - parameters): t0 +- h, t0 = -b / 2a, h = sqrt(Delta / a).
   For residuals linear in u with independent noise of one size this is the exact
   (Student's t) interval of least squares.
2. **the replays' noise**: the residuals of one log are not independent; a replay's slips
   move many samples together, and the log is one such realisation. The sensitivity replays
   (fresh noise on the speed they follow, fit.engine) measure it: each one's deviation dr_k
   from their mean would move the optimum along the profile by dt_k = -g . dr_k / g . g,
   g the residuals' rate of change along the profile (their least-squares slope over the
   profile's points); the log's realisation and the mean of the R replays averaged at a
   point (their own scatter over R) add the variance (1 + 1/R) var(dt_k), with Student's t
   of the sensitivity replays' degrees of freedom;
3. **the misfit's roughness**: where a replay's slip jumps from one point to the next, the
   averaged misfit scatters about the parabola; the standard error of its vertex t0 from
   that scatter (Student's t of the points' degrees of freedom) adds its variance too.

The half-width is sqrt(h^2 + the variances of 2 and 3 times their t quantiles squared),
about t0; the fitted value is always inside.

The correlations between parameters are reported from the Jacobian at the optimum:
C0 s^2 plus the covariance of the shifts J^+ dr_k, scaled as above.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

PROFILE_STEPS = (0.01, 0.02, 0.03, 0.04)  # in u: the profile's points on either side
PROFILE_EXTENSIONS = 3         # at most this many doublings of the farthest step
LEVEL = 0.95


@dataclass(frozen=True)
class Intervals:
    """The intervals in u (``low``, ``high``), the correlation matrix and the profile's
    half-widths from the misfit alone and from the replays' noise alone (u)."""

    low: np.ndarray
    high: np.ndarray
    correlation: np.ndarray
    profile_half: np.ndarray
    replay_half: np.ndarray
    points: int                  # parameter vectors evaluated for the profiles


def noise_level(residuals: np.ndarray, parameters: int) -> tuple[float, int]:
    """s^2 = S / dof and dof = residuals - parameters (at least 1)."""
    dof = max(1, residuals.size - parameters)
    return float(np.sum(residuals**2)) / dof, dof


def jacobian_covariance(jacobian: np.ndarray, residuals: np.ndarray, scatter: np.ndarray,
                        replays: int) -> np.ndarray:
    """The parameters' covariance in u from the Jacobian (module doc, last paragraph)."""
    s2, _ = noise_level(residuals, jacobian.shape[1])
    cov = s2 * np.linalg.pinv(jacobian.T @ jacobian)
    if scatter.shape[0] >= 2:
        shifts = scatter @ np.linalg.pinv(jacobian).T
        n = jacobian.shape[1]
        cov = cov + (1.0 + 1.0 / replays) * np.cov(shifts, rowvar=False, ddof=1).reshape(n, n)
    return cov


def profile_intervals(evaluate: Callable[[Sequence[np.ndarray]], list[np.ndarray]],
                      u_best: np.ndarray, residuals: np.ndarray, jacobian: np.ndarray,
                      scatter: np.ndarray, replays: int) -> Intervals:
    """The intervals of each parameter (module doc). ``evaluate``: the weighted residual
    vectors of points in u (within [0, 1]); ``residuals`` and ``jacobian`` at ``u_best``;
    ``scatter`` (sensitivity replays, residuals): their weighted deviations from their
    mean (none: zero rows); ``replays`` averaged a point."""
    from scipy.stats import f as fisher
    from scipy.stats import t as student
    n = u_best.size
    s2, dof = noise_level(residuals, n)
    delta = s2 * float(fisher.ppf(LEVEL, 1, dof))
    c0 = np.linalg.pinv(jacobian.T @ jacobian)
    cov = jacobian_covariance(jacobian, residuals, scatter, replays)
    sd = np.sqrt(np.maximum(np.diag(cov), 0.0))
    with np.errstate(invalid="ignore", divide="ignore"):
        correlation = cov / np.outer(sd, sd)
    low, high = np.zeros(n), np.ones(n)
    profile_half, replay_half = np.full(n, np.inf), np.zeros(n)
    points = 0
    q_replays = float(student.ppf(0.5 + LEVEL / 2, max(1, scatter.shape[0] - 1)))
    for i in range(n):
        if c0[i, i] <= 0.0:
            continue                                  # not constrained: the bounds
        direction = c0[:, i] / c0[i, i]
        ts, rs = _profile(evaluate, u_best, residuals, direction, i, delta)
        points += ts.size - 1
        if ts.size < 4:
            continue                                  # too few points: the bounds
        top = vertex(ts, np.array([float(r @ r) for r in rs]))
        if top is None:
            continue                                  # no minimum: the bounds
        t0, se_t0, a = top
        h = float(np.sqrt(delta / a))
        replay_var = (float(student.ppf(0.5 + LEVEL / 2, ts.size - 3)) * se_t0)**2
        if scatter.shape[0] >= 2:
            g = np.polyfit(ts, np.array(rs), 1)[0]    # d residuals / dt, over the profile
            shifts = -(scatter @ g) / float(g @ g)
            replay_var += q_replays**2 * (1.0 + 1.0 / replays) * np.var(shifts, ddof=1)
        replay_half[i] = float(np.sqrt(replay_var))
        half = float(np.hypot(h, replay_half[i]))
        profile_half[i] = h
        low[i] = max(0.0, u_best[i] + min(0.0, t0 - half))
        high[i] = min(1.0, u_best[i] + max(0.0, t0 + half))
    return Intervals(low, high, correlation, profile_half, replay_half, points)


def vertex(ts: np.ndarray, misfits: np.ndarray) -> tuple[float, float, float] | None:
    """The least-squares parabola a t^2 + b t + c through (``ts``, ``misfits``): its vertex
    t0 = -b / 2a, t0's standard error from the misfits' scatter about it (the delta
    method; 0 when it passes through them all) and a; None when a <= 0 (no minimum)."""
    design = np.column_stack((ts**2, ts, np.ones_like(ts)))
    coef, *_ = np.linalg.lstsq(design, misfits, rcond=None)
    a, b = float(coef[0]), float(coef[1])
    if a <= 0.0:
        return None
    t0 = -b / (2.0 * a)
    spread = misfits - design @ coef
    dof = ts.size - 3
    if dof < 1:
        return t0, 0.0, a
    cov = float(spread @ spread) / dof * np.linalg.pinv(design.T @ design)
    grad = np.array([b / (2.0 * a * a), -1.0 / (2.0 * a), 0.0])    # d t0 / d (a, b, c)
    return t0, float(np.sqrt(max(0.0, grad @ cov @ grad))), a


def _profile(evaluate: Callable[[Sequence[np.ndarray]], list[np.ndarray]],
             u_best: np.ndarray, residuals: np.ndarray, direction: np.ndarray, i: int,
             delta: float) -> tuple[np.ndarray, list[np.ndarray]]:
    """The profile's points t (the step along parameter i) and their residuals: the
    optimum, ``PROFILE_STEPS`` on either side, then the farthest step doubled while the
    parabola's rise by ``delta`` lies beyond the points (at most ``PROFILE_EXTENSIONS``)."""
    ts, rs = [0.0], [residuals]

    def add(steps: Sequence[float]) -> None:
        wanted = []
        for t in steps:
            u = u_best + t * direction
            if np.all((u >= 0.0) & (u <= 1.0)):
                wanted.append((t, u))
        ts.extend(t for t, _ in wanted)
        rs.extend(evaluate([u for _, u in wanted]))
    add([s * side for s in PROFILE_STEPS for side in (1.0, -1.0)])
    step = max(PROFILE_STEPS)
    for _ in range(PROFILE_EXTENSIONS):
        if len(ts) >= 4:
            top = vertex(np.array(ts), np.array([float(r @ r) for r in rs]))
            reach = abs(top[0]) + np.sqrt(delta / top[2]) if top else np.inf
            if reach <= max(abs(t) for t in ts):
                break
        step *= 2.0
        add([step, -step])
    return np.array(ts), rs
