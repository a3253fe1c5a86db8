"""The 95 % intervals of fitted parameters from the misfit's profile (``drill_sim fit``).

The misfit is S(u) = sum of the weighted residuals squared, u the parameters scaled to their
bounds. For parameter i the profile is S along the line through the optimum u* on which the
other parameters follow their conditional optimum under the Jacobian's quadratic model,
u* + t d_i with d_i = C0[:, i] / C0[i, i] and C0 = (J^T J)^-1 (for a misfit quadratic in u
this is the exact profile; for the replays' misfit the others are not re-optimised at each
point). The profile is evaluated at ``PROFILE_STEPS`` on either side of the optimum (in u;
farther, doubling, while a side does not rise enough). Each side's bound is where the
profile first rises above the optimum's misfit (or the level its near neighbours on the
profile put there, where higher: :func:`base_level`) by

    rise = s^2 F(0.95; 1, dof) + z(0.95) sqrt(2) sd_S

(:func:`crossing`: between the last point below and the first above, interpolated as a
parabola through the optimum would), then widened:

1. **the profile**: s^2 = S(u*) / dof is the noise level estimated from the residuals
   (dof = residuals - parameters). For residuals linear in u with independent noise of one
   size, the first term alone gives least squares' exact (Student's t) interval.
2. **the misfit's own noise**: S is an average over R replays whose slips move with the
   smallest change (along field_8p5in_deviated's static coefficient it jumped by 21 %
   between points 0.12 % apart, docs/fit.md). sd_S is its standard deviation over the
   draws of those replays at the optimum (:func:`jackknife_sd`); a point whose misfit lies
   within the one-sided 95 % quantile of the difference of two such draws above the
   optimum's cannot be told from it.
3. **the replays' shifts**: the residuals of one log are not independent; a replay's slips
   move many samples together, and the log is one such realisation. The sensitivity
   replays (fresh noise on the speed they follow; following a setpoint, a shift of their
   own of its timing: fit.engine) measure it: each one's
   deviation dr_k from their mean would move the optimum along the profile by
   dt_k = -g . dr_k / g . g, g the residuals' least-squares slope over the profile's
   points; the log's realisation and the mean of the R replays averaged at a point add the
   variance (1 + 1/R) var(dt_k), with Student's t of the sensitivity replays' degrees of
   freedom, in quadrature with each side's crossing.

The correlations between parameters are reported from the Jacobian at the optimum:
C0 s^2 plus the covariance of the shifts J^+ dr_k, scaled as above.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

PROFILE_STEPS = (0.01, 0.02, 0.03, 0.04)  # in u: the profile's points on either side
NEAR_RISES = 4.0              # base_level fits the points within this many rises of the optimum
PROFILE_EXTENSIONS = 3         # at most this many doublings of the farthest step
LEVEL = 0.95


@dataclass(frozen=True)
class Intervals:
    """The intervals in u (``low``, ``high``), the correlation matrix, the misfit's rise
    that bounds the profile and the half-width added for the replays' shifts (u)."""

    low: np.ndarray
    high: np.ndarray
    correlation: np.ndarray
    rise: np.ndarray
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
    cov = s2 * unscaled_covariance(jacobian)
    if scatter.shape[0] >= 2:
        shifts = scatter @ np.linalg.pinv(jacobian).T
        n = jacobian.shape[1]
        cov = cov + (1.0 + 1.0 / replays) * np.cov(shifts, rowvar=False, ddof=1).reshape(n, n)
    return cov


def profile_intervals(evaluate: Callable[[Sequence[np.ndarray]], list[np.ndarray]],
                      u_best: np.ndarray, residuals: np.ndarray, jacobian: np.ndarray,
                      scatter: np.ndarray, replays: int, misfit_sd: float = 0.0,
                      step_share: float = 1.0) -> Intervals:
    """The intervals of each parameter (module doc). ``evaluate``: the weighted residual
    vectors of points in u (within [0, 1]); ``residuals`` and ``jacobian`` at ``u_best``;
    ``scatter`` (sensitivity replays, residuals): their weighted deviations from their
    mean (none: zero rows); ``replays`` averaged a point; ``misfit_sd``: the standard
    deviation of the misfit at the optimum over the draws of those replays
    (:func:`jackknife_sd`); ``step_share``: the profile's steps are ``PROFILE_STEPS`` times
    this (fit.engine: smaller for the sharper misfit of replays that follow a setpoint)."""
    from scipy.stats import f as fisher
    from scipy.stats import norm
    from scipy.stats import t as student
    n = u_best.size
    s2, dof = noise_level(residuals, n)
    rise = s2 * float(fisher.ppf(LEVEL, 1, dof)) + \
        float(norm.ppf(LEVEL)) * np.sqrt(2.0) * misfit_sd
    c0 = unscaled_covariance(jacobian)
    cov = jacobian_covariance(jacobian, residuals, scatter, replays)
    sd = np.sqrt(np.maximum(np.diag(cov), 0.0))
    with np.errstate(invalid="ignore", divide="ignore"):
        correlation = cov / np.outer(sd, sd)
    low, high = np.zeros(n), np.ones(n)
    replay_half = np.zeros(n)
    points = 0
    q_replays = float(student.ppf(0.5 + LEVEL / 2, max(1, scatter.shape[0] - 1)))
    directions = profile_directions(jacobian)
    for i in range(n):
        if c0[i, i] <= 0.0:
            continue                                  # not constrained: the bounds
        direction = directions[:, i]
        ts, rs = _profile(evaluate, u_best, residuals, i, direction, rise, step_share)
        points += ts.size - 1
        misfits = np.array([float(r @ r) for r in rs])
        if scatter.shape[0] >= 2:
            g = np.polyfit(ts, np.array(rs), 1)[0]    # d residuals / dt, over the profile
            shifts = -(scatter @ g) / float(g @ g)
            replay_half[i] = q_replays * float(np.sqrt((1.0 + 1.0 / replays) *
                                                       np.var(shifts, ddof=1)))
        down, up = crossing(ts, misfits, rise, -1.0), crossing(ts, misfits, rise, 1.0)
        if down is not None:
            low[i] = max(0.0, u_best[i] - np.hypot(down, replay_half[i]))
        if up is not None:
            high[i] = min(1.0, u_best[i] + np.hypot(up, replay_half[i]))
    return Intervals(low, high, correlation, np.full(n, rise), replay_half, points)


def unscaled_covariance(jacobian: np.ndarray) -> np.ndarray:
    """C0 = (J^T J)^-1 (pseudo-inverse: a parameter the misfit ignores gets a zero row)."""
    return np.linalg.pinv(jacobian.T @ jacobian)


def profile_directions(jacobian: np.ndarray) -> np.ndarray:
    """Column i: d_i = C0[:, i] / C0[i, i], C0 = (J^T J)^-1 (module doc): the direction in u
    along which parameter i moves by one and the others follow their least-squares optimum
    under the Jacobian's linear model. Along a pair the log can hardly tell apart (the
    damping and the dynamic coefficient at one speed) the misfit's valley runs diagonally,
    and a step along one axis climbs its side (fit.engine's bracket steps along these). A
    parameter the misfit does not move with keeps its axis."""
    c0 = unscaled_covariance(jacobian)
    out = np.eye(jacobian.shape[1])
    for i in range(out.shape[1]):
        if c0[i, i] > 0.0:
            out[:, i] = c0[:, i] / c0[i, i]
    return out


def base_level(ts: np.ndarray, misfits: np.ndarray, rise: float) -> float:
    """The misfit the profile's rise is counted from: the optimum's own (t = 0), or, where
    higher, the level c at t = 0 of the least-squares fit c + a_low t^2 (t < 0),
    c + a_high t^2 (t > 0) to the profile's near points, those within ``NEAR_RISES`` rises
    of the optimum (for a parabola, twice the interval's half-width; at least four, else
    the optimum's own). The optimum's misfit is the lowest of the many the optimiser drew,
    so its share of the misfit's noise is biased low; its neighbours on the profile were not
    chosen for being low. Points farther up say nothing of the level at the optimum: where
    the misfit has a cliff within the profile's steps (a start-up whose break-away moves by
    a sample), a parabola through them put the level 55 to 168 times the optimum's own and
    the interval read +22 % (the independent solver's log, docs/fit.md)."""
    own = float(misfits[ts == 0.0][0])
    near = (ts != 0.0) & (misfits <= own + NEAR_RISES * rise)
    if np.count_nonzero(near) < 4:
        return own
    t = ts[near]
    design = np.column_stack((np.ones_like(t), np.where(t < 0.0, t**2, 0.0),
                              np.where(t > 0.0, t**2, 0.0)))
    coef, *_ = np.linalg.lstsq(design, misfits[near], rcond=None)
    return max(own, float(coef[0]))


def crossing(ts: np.ndarray, misfits: np.ndarray, rise: float, side: float) -> float | None:
    """How far from the optimum (t = 0) on ``side`` (+1 or -1) the profile first rises by
    ``rise`` above :func:`base_level`: between the last point below and the first above,
    interpolated as a parabola through the optimum would (linear in the square root of the
    rise: exact for a misfit quadratic about the optimum); None: no point rises so far."""
    base = base_level(ts, misfits, rise)
    order = np.argsort(np.abs(ts))
    last_t, last_rise = 0.0, 0.0
    for k in order:
        if ts[k] * side <= 0.0:
            continue
        up = float(misfits[k]) - base
        if up > rise:
            share = (np.sqrt(rise) - np.sqrt(last_rise)) / (np.sqrt(up) - np.sqrt(last_rise))
            return last_t + (abs(float(ts[k])) - last_t) * float(share)
        last_t, last_rise = abs(float(ts[k])), max(0.0, up)
    return None


def jackknife_sd(statistic: Callable[[np.ndarray], float], samples: np.ndarray) -> float:
    """The jackknife standard deviation of ``statistic`` of the mean of ``samples`` (rows:
    independent draws): how much the statistic of an average of that many draws moves
    from one set of draws to another."""
    count = samples.shape[0]
    if count < 2:
        return 0.0
    total = samples.sum(axis=0)
    left_out = np.array([statistic((total - row) / (count - 1)) for row in samples])
    return float(np.sqrt((count - 1) / count * np.sum((left_out - left_out.mean())**2)))


def _profile(evaluate: Callable[[Sequence[np.ndarray]], list[np.ndarray]],
             u_best: np.ndarray, residuals: np.ndarray, index: int, direction: np.ndarray,
             rise: float, step_share: float = 1.0) -> tuple[np.ndarray, list[np.ndarray]]:
    """The profile's points t (the step along the parameter) and their residuals: the
    optimum, ``PROFILE_STEPS`` on either side, then the farthest step doubled while a side
    does not rise by ``rise`` (at most ``PROFILE_EXTENSIONS`` times). A point keeps
    parameter ``index`` (``direction``'s entry 1) within its bounds; the others follow
    ``direction`` up to their bounds and stay there (for two parameters and a misfit
    quadratic in u, exactly their conditional optimum under the bounds; with more, near
    it). Points whose others left the bounds used to be skipped: where the correlated line
    left the box before the misfit rose, the interval read the parameter's bound (the
    dynamic coefficient fitted with the damping on the tangent: "+669 %", docs/fit.md)."""
    ts, rs = [0.0], [residuals]

    def add(steps: Sequence[float]) -> None:
        wanted = []
        for t in steps:
            if 0.0 <= u_best[index] + t <= 1.0:
                wanted.append((t, np.clip(u_best + t * direction, 0.0, 1.0)))
        ts.extend(t for t, _ in wanted)
        rs.extend(evaluate([u for _, u in wanted]))
    add([step_share * s * side for s in PROFILE_STEPS for side in (1.0, -1.0)])
    step = step_share * max(PROFILE_STEPS)
    for _ in range(PROFILE_EXTENSIONS):
        t_now, misfits = np.array(ts), np.array([float(r @ r) for r in rs])
        missing = [side for side in (1.0, -1.0)
                   if crossing(t_now, misfits, rise, side) is None]
        if not missing:
            break
        step *= 2.0
        add([side * step for side in missing])
    return np.array(ts), rs
