"""Fitting preset parameters to start-ups: replays on Dask, a cache, scipy's least squares.

A *replay* runs one start-up with one parameter vector (:func:`simulate`, a Dask task,
about as long as ``drill_sim startup`` takes), its drive following the logged speed
low-passed at the string's cut-off (:func:`replayed_speed`: the sensor's jitter, replayed,
would stiffen the wall). An *evaluation* of a parameter vector averages the compared values
(:mod:`fit.objective`) of ``REPLAYS_PER_POINT`` replays of each start-up, each following
the logged speed with white noise of the speed's own size added (then low-passed), seeded
0, 1, ... at every vector (common random numbers): a replay's first slip moves with the
smallest change of the speed it follows, and the average over the same draws makes the
misfit a smoother function of the parameters, which the optimiser's differences can follow
(with 4 replays the misfit along the static coefficient of field_8p5in_deviated was rough
on the scale of the Jacobian's step, 1.5 % of it, lowest 4 % below the truth; with
12 it falls steadily to the truth, measured 2026-12-06, benchmarks/fit_replay_bias.py).
With ``follow="setpoint"`` a replay follows the log's setpoint through the preset's own
speed loop instead (:func:`simulate`): no sensor noise to add and no sensitivity replays
in the weights (the intervals' replays draw the setpoint's timing instead,
:meth:`Evaluator.measure_timing`); ``SETPOINT_REPLAYS`` replays a point, each following
the setpoint shifted in time by a seeded draw within half a sample
(:func:`shifted_setpoint`; seed 0 unshifted); and after the first least-squares pass,
every step (the Jacobian's, the bracket's, the profile's) ``SETPOINT_STEP_SHARE`` times
its size below. Both answer to how sharp and rough that
misfit is (the wind-up's weights carry no speed noise; measured on the tangent's two-speed
logs, 2026-12-07, docs/fit.md): one replay a point left it rough on a scale of a fraction
of a % of the parameters (the wall's junctions let go at thresholds: along a segment from
a joint fit to the truth it rose by 0.17 in all on the way down 0.21, against 0.09 on the
way down 0.62 with four shifted replays, benchmarks/fit_setpoint_roughness.py), and least
squares stopped in its shoulders. With the four, the Jacobian's 1 % of the range (5 % of
the tangent's static coefficient, whose basin is under 1 % wide) still stopped a fit at
+6.9 % of the damping scoring 1.46 where the truth scores 0.95; a fifth of it everywhere
reached the truth's basin there, but stopped another fit from 15 % below at +27 % (misfit
2.37 against 0.84) which the full step had brought to +2.7 %. So the first pass takes the
full step (into the basin), the rest a fifth (down it).
The misfit is the weighted residuals of that average. The fit works
in the parameters scaled to their bounds (u = (x - low) / (high - low), in [0, 1]):

1. a global start: the preset's values and ``STARTS_PER_PARAMETER`` x n points of a
   seeded Latin hypercube over the bounds (scipy.stats.qmc), evaluated in parallel; at the
   preset's values and at the best, the replay's sensitivity to the speed's noise is
   measured (:meth:`Evaluator.measure_sensitivity`, fit.objective) and joins the weights;
2. ``scipy.optimize.least_squares`` (trust-region reflective, within the bounds) from each
   of the ``LOCAL_STARTS`` best, its Jacobian forward differences of ``JACOBIAN_STEP`` in
   u, evaluated in parallel; the sensitivity measured again at the best optimum (it
   depends on the parameters: the weights keep the largest scatter seen), and least
   squares again from the best point so far under those weights (``PASSES`` in all);
3. a rescue, only when the search is lost (its misfit above ``MISFIT_LOST``, twice the
   log's noise where the truth scores about 1): least squares again, its Jacobian's step
   ``RESCUE_STEP`` in u, from the given values and then the global start's best points
   (``RESCUE_STARTS`` in all) until one is no longer lost. Following a setpoint, log 45
   of the tangent's two-speed study went from the given values (15 % below) at the full
   step into the valley where more viscous loss stands in for less wall friction (misfit
   16.1, damping +69.5 %); from there at a fifth of the step it stayed (16.1), from the
   given values at a fifth it reached the truth's basin (0.98, each within 1.6 %;
   measured 2026-12-07, docs/fit.md);
4. a bracket: the points ``BRACKET_STEPS`` on either side of the optimum along each
   parameter (2 and 4 % of its range; 3.3 and 6.6 % of field_8p5in_deviated's static
   coefficient), the others following along the misfit's valley (fit.intervals'
   profile directions; for one parameter, its axis), and least squares again from the
   best of them if it is better, up to ``BRACKET_ROUNDS`` times: the misfit, an average
   of replays whose slips move with the smallest change, is rough on the scale of the
   Jacobian's differences, and least squares stopped in a shoulder of it 5 % below the
   static coefficient's truth, where the misfit at the truth was lower (measured
   2026-12-06, docs/fit.md);
5. the 95 % intervals from the misfit's profile along each parameter (fit.intervals:
   where it first rises, at points 1 to 4 % of the range on either side, by the F
   threshold times the residuals' noise level plus the misfit's own noise over the draws
   of its replays, widened by how far the sensitivity replays' scatter would move the
   optimum); the correlations from the Jacobian at the optimum. ``FitResult.stages``
   books the replays and the seconds of each stage.

Every replay is appended to a cache file as it finishes (JSON lines keyed by a hash of the
preset, the start-up's samples and the parameter vector); a fit started again with the same
inputs reads them back instead of recomputing (the optimiser's path is deterministic), so
an interrupted fit resumes where it stopped.
"""

from __future__ import annotations

import hashlib
import json
import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from drill_sim_ros.fit.intervals import jackknife_sd, profile_directions, profile_intervals
from drill_sim_ros.fit.log import SurfaceLog
from drill_sim_ros.fit.objective import Target, noise_std
from drill_sim_ros.fit.params import FitParameter, with_values
from drill_sim_ros.model.analysis import lowpass
from drill_sim_ros.model.errors import DrillSimError
from drill_sim_ros.model.params import RPM_PER_RAD_S
from drill_sim_ros.model.presets import preset_from_dict
from drill_sim_ros.model.replay import FOLLOW, replay_speed

STARTS_PER_PARAMETER = 16
JACOBIAN_STEP = 0.01          # in u (a share of each parameter's bounds)
MAX_ITERATIONS = 40           # least squares' evaluations of the residuals (not the Jacobian's)
TOLERANCE = 1e-4              # least squares' ftol and xtol
PENALTY = 1e3                 # each residual of a vector the preset refuses (dynamic > static)
SENSITIVITY_REPLAYS = 8       # replays with fresh speed noise (Evaluator.measure_sensitivity)
SENSITIVITY_SEED = 1000       # their seeds from here (the averaged replays' from 0)
SETPOINT_REPLAYS = 4          # replays a point that follow the setpoint (shifted_setpoint)
REPLAYS_PER_POINT = 12        # replays averaged per parameter vector (common seeds; 4 left
#                               the misfit too rough for the differences: module doc)
PASSES = 2                    # least-squares passes, the weights measured anew after each
LOCAL_STARTS = 3              # the first pass starts from the best this many points
BRACKET_STEPS = (0.02, 0.04)  # in u: the points tried on either side of the optimum
SETPOINT_STEP_SHARE = 0.2     # following a setpoint, every step above after the first pass
#                               (and the profile's) times this: a sharper misfit (module doc)
BRACKET_ROUNDS = 3            # at most this many restarts from a better one of them
CORRELATED = 0.95             # |correlation| above this: the log cannot tell the two apart
MISFIT_LOST = 2.0             # the misfit at the fit above this: it missed the log (_warnings)
RESCUE_STARTS = 3             # a lost search's least squares again from this many points ...
RESCUE_STEP = 0.002           # ... its Jacobian's step this (in u; module doc, step 3)
VISCOUS_PATH = "string.torsional_damping_per_s"   # a loss torque that grows with speed ...
COULOMB_PATHS = ("well.side_friction.dynamic",)   # ... and friction torques that do not
SPEED_SPREAD = 3.0            # start-ups' speeds at least this far apart tell the two apart
#                               (the tangent: one at 3x told them apart, 2x hardly; fit.md)


def require_follow(follow: str, logs: Sequence[SurfaceLog]) -> None:
    """DrillSimError, in one line, unless the replays can follow ``follow`` in every log."""
    if follow not in FOLLOW:
        raise DrillSimError(f"--follow {follow!r}: must be one of {', '.join(FOLLOW)}")
    missing = [log.source for log in logs if log.setpoint_rad_s is None]
    if follow == "setpoint" and missing:
        raise DrillSimError(f"--follow setpoint: {missing[0]} has no setpoint column "
                            "(setpoint_rpm or setpoint_rad_s)")


def followed_series(log: SurfaceLog, follow: str) -> np.ndarray:
    """What a replay's drive follows in ``log``: its speed, or its setpoint (rad/s)."""
    return log.setpoint_rad_s if follow == "setpoint" else log.speed_rad_s


def simulate(data: dict[str, Any], values: dict[str, float], t_s: np.ndarray,
             speed_rad_s: np.ndarray, speed_noise: tuple[int, float] | None = None,
             cutoff_hz: float = math.inf, follow: str = "speed"
             ) -> tuple[np.ndarray, np.ndarray] | str:
    """One replay (a Dask task): the string torque at the top N m and the bit speed rad/s at
    the log's times, or the one-line reason the preset with ``values`` is refused.
    ``speed_noise`` (seed, std rad/s): white noise added to the speed it follows; the speed
    is then low-passed at ``cutoff_hz`` (:func:`replayed_speed`). ``follow="setpoint"``:
    ``speed_rad_s`` is the drive's logged setpoint, followed as it is through the preset's
    speed loop (model/replay.py; no noise, no low-pass: a command has neither)."""
    if follow == "setpoint" and speed_noise is not None and t_s.size >= 2:
        speed_rad_s = shifted_setpoint(t_s, speed_rad_s, speed_noise[0])
    if follow == "speed":
        if speed_noise is not None:
            seed, std = speed_noise
            speed_rad_s = speed_rad_s + std * np.random.default_rng(seed).standard_normal(
                speed_rad_s.size)
        speed_rad_s = replayed_speed(t_s, speed_rad_s, cutoff_hz)
    try:
        preset = preset_from_dict("fit", with_values(data, values))
        run = replay_speed(preset, t_s, speed_rad_s, follow=follow)
    except DrillSimError as exc:
        return str(exc)
    return run.surface_torque_nm, run.bit_rpm / RPM_PER_RAD_S


def shifted_setpoint(t_s: np.ndarray, setpoint_rad_s: np.ndarray, seed: int) -> np.ndarray:
    """The setpoint a replay seeded ``seed`` follows: the logged one shifted in time by a
    draw uniform within half a sample either way (linear between samples, held at the
    ends; seed 0: unshifted). The log says when each sample was taken, not where within its
    interval the rig's drive began to turn; and the start-up's wall lets go junction by
    junction at thresholds, so a replay's misfit is rough on a scale of a fraction of a %
    of the parameters (fit.engine's module doc): averaged over these shifts, it is
    smoother."""
    if seed == 0:
        return setpoint_rad_s
    sample_s = float(np.median(np.diff(t_s)))
    shift_s = (np.random.default_rng(seed).uniform() - 0.5) * sample_s
    return np.interp(t_s - shift_s, t_s, setpoint_rad_s)


def replayed_speed(t_s: np.ndarray, speed_rad_s: np.ndarray, cutoff_hz: float) -> np.ndarray:
    """The drive speed a replay follows: the logged one low-passed at ``cutoff_hz`` (the
    string's cut-off, zero-phase). The drive's own speed carries nothing above it that the
    string's stick-slip answers to, but the speed sensor's white noise does, and a
    kinematic drive would pass that jitter into the string: the wall's stick band (Karnopp,
    a one-step memory of each junction's speed) holds a junction whose speed the jitter
    dips into the band, so a jittered replay winds up stiffer than the rig did (measured
    2026-12-06, benchmarks/fit_replay_bias.py: the true speed with the sensor's 0.02 rad/s
    of noise replayed on field_8p5in_deviated slips later and higher, every time)."""
    if not math.isfinite(cutoff_hz) or t_s.size < 2:
        return speed_rad_s
    return lowpass(speed_rad_s, float(np.median(np.diff(t_s))), cutoff_hz)


@dataclass(frozen=True)
class Evaluation:
    """A parameter vector's residuals over all start-ups (``refused``: why the preset refused
    it, the residuals then ``PENALTY``)."""

    x: np.ndarray
    residuals: np.ndarray
    refused: str | None = None

    @property
    def misfit(self) -> float:
        """The residuals' root mean square."""
        return float(np.sqrt(np.mean(self.residuals**2)))


class Evaluator:
    """Evaluations of parameter vectors over start-ups, cached and run on a Dask client
    (None: in this process)."""

    def __init__(self, data: dict[str, Any], params: Sequence[FitParameter],
                 targets: Sequence[Target], client: Any = None, cache: Path | None = None,
                 progress: Callable[[str], None] | None = None,
                 replays: int | None = None, follow: str = "speed") -> None:
        self.data, self.params, self.targets = data, list(params), list(targets)
        self.follow = follow                   # what the replays' drive follows
        require_follow(follow, [t.log for t in self.targets])
        # a replay of a setpoint has no noise to average over, but shifts of its timing
        default = SETPOINT_REPLAYS if follow == "setpoint" else REPLAYS_PER_POINT
        self.replays = default if replays is None else replays
        self.client, self.cache, self.progress = client, cache, progress
        self.done: dict[str, list[float] | str] = {}
        self.computed = self.reused = 0
        self.best = math.inf
        self.started = time.perf_counter()
        self._keys = [f"{s}#{self._segment_key(t)}" for s, t in enumerate(self.targets)]
        self.sigma = [t.noise_sigma for t in self.targets]
        self.speed_noise = [noise_std(t.log.speed_rad_s) for t in self.targets]
        self.sensitivity: list[np.ndarray | None] = [None] * len(self.targets)
        if cache is not None and cache.exists():
            self._load(cache)

    # ---- cache ----------------------------------------------------------------------
    def _segment_key(self, target: Target) -> str:
        """The cache's key of a start-up: the preset, the log, the fitted paths and the
        cut-off the replayed speed is low-passed at."""
        log = target.log
        h = hashlib.sha256(json.dumps(self.data, sort_keys=True, default=str).encode())
        for array in (log.t_s, log.speed_rad_s, log.torque_nm):
            h.update(np.ascontiguousarray(array, dtype=np.float64).tobytes())
        h.update(",".join(p.path for p in self.params).encode())
        h.update(f"lowpass {target.cutoff_hz!r}".encode())
        if self.follow != "speed":
            h.update(f"follow {self.follow}".encode())
        return h.hexdigest()[:24]

    def _key(self, segment: int, x: np.ndarray) -> str:
        return f"{self._keys[segment]}:{','.join(repr(float(v)) for v in x)}"

    def _load(self, path: Path) -> None:
        for line in path.read_text().splitlines():
            try:
                row = json.loads(line)
                self.done[row["key"]] = row["value"]
            except (ValueError, KeyError, TypeError):
                continue             # a line cut by an interruption

    def _store(self, key: str, value: list[float] | str) -> None:
        self.done[key] = value
        if self.cache is not None:
            with self.cache.open("a") as f:
                f.write(json.dumps({"key": key, "value": value}) + "\n")

    # ---- evaluating -----------------------------------------------------------------
    def values_of(self, x: np.ndarray) -> dict[str, float]:
        return {p.path: float(v) for p, v in zip(self.params, x, strict=True)}

    def evaluate(self, xs: Sequence[np.ndarray]) -> list[Evaluation]:
        """The evaluations of the vectors ``xs`` (parameter values), in parallel."""
        wanted = [(i, s, r) for i in range(len(xs)) for s in range(len(self.targets))
                  for r in range(self.replays)]
        jobs = [job for job in wanted if self._job_key(xs, job) not in self.done]
        self.reused += len(wanted) - len(jobs)
        keys = [self._job_key(xs, job) for job in jobs]
        self._map([self._args(xs, j) for j in jobs],
                  lambda i, result: self._take(keys[i], jobs[i][1], result))
        return [self._evaluation(x) for x in xs]

    def _job_key(self, xs: Sequence[np.ndarray], job: tuple[int, int, int]) -> str:
        return f"{self._key(job[1], xs[job[0]])}:r{job[2]}"

    def _args(self, xs: Sequence[np.ndarray], job: tuple[int, int, int],
              seed_offset: int = 0) -> tuple[Any, ...]:
        """:func:`simulate`'s arguments: start-up ``job[1]`` at ``xs[job[0]]``, the logged
        speed with noise of its own size seeded ``job[2] + seed_offset``."""
        target = self.targets[job[1]]
        return (self.data, self.values_of(xs[job[0]]), target.log.t_s, self._series(target),
                (job[2] + seed_offset, self.speed_noise[job[1]]), target.cutoff_hz,
                self.follow)

    def _series(self, target: Target) -> np.ndarray:
        return followed_series(target.log, self.follow)

    def _take(self, key: str, segment: int, result: tuple[np.ndarray, np.ndarray] | str
              ) -> None:
        value = result if isinstance(result, str) else \
            self.targets[segment].raw(*result).tolist()
        self.computed += 1
        self._store(key, value)
        if self.progress is not None:
            self.progress(f"fit: {self.computed} replays ({self.reused} from the cache), "
                          f"{time.perf_counter() - self.started:6.1f} s, best misfit "
                          f"{self.best:.4g}")

    def _evaluation(self, x: np.ndarray) -> Evaluation:
        parts, refused = [], None
        for s, target in enumerate(self.targets):
            raws = self._raws(s, x)
            bad = [r for r in raws if isinstance(r, str)]
            if bad:
                refused = bad[0]
                parts.append(np.full(_size(target), PENALTY))
            else:
                parts.append(self._residuals(s, np.mean(np.array(raws), axis=0)))
        evaluation = Evaluation(np.asarray(x, dtype=float), np.concatenate(parts), refused)
        self.best = min(self.best, evaluation.misfit)
        return evaluation

    def _residuals(self, segment: int, raw: np.ndarray) -> np.ndarray:
        target = self.targets[segment]
        return (np.asarray(raw) - target.logged) / self.sigma[segment]

    def _raws(self, segment: int, x: np.ndarray) -> list[np.ndarray | str]:
        """What each replay averaged at an evaluated ``x`` gave for start-up ``segment``:
        its compared values, or why it was refused."""
        return [self.done[f"{self._key(segment, x)}:r{r}"] for r in range(self.replays)]

    def _replays_at(self, segment: int, x: np.ndarray) -> np.ndarray | None:
        """The compared values of each replay averaged at an evaluated ``x`` for start-up
        ``segment``, shape (replays, values); None when one was refused."""
        raws = self._raws(segment, x)
        return None if any(isinstance(r, str) for r in raws) else np.array(raws)

    def replayed_cycles(self, x: np.ndarray) -> list[np.ndarray | None]:
        """Per start-up, the torque's cycle (period s, mean and standard deviation N m;
        :meth:`Target.cycle_of`) in each of the replays averaged at the evaluated ``x``,
        shape (replays, 3); None where the cycle is not compared or a replay was refused.
        Their spread, not one replay, is what the model says of the log's cycle: in the
        deviated presets the cycle after the first slip jumps between branches with the
        smallest change of the speed replayed, and of the parameters (docs/fit.md)."""
        cycles: list[np.ndarray | None] = []
        for s, target in enumerate(self.targets):
            raws = self._replays_at(s, x)
            rows = [None] if raws is None else [target.cycle_of(r) for r in raws]
            cycles.append(None if any(r is None for r in rows) else np.array(rows))
        return cycles

    def measure_sensitivity(self, x: np.ndarray) -> None:
        """Add to each compared value's uncertainty the scatter of ``SENSITIVITY_REPLAYS``
        replays at ``x`` that follow the logged speed with fresh noise of its own size
        (fit.objective's module doc); measured at several points, the largest holds (the
        scatter depends on the parameters). Not when the replays follow a setpoint: they
        carry no speed noise to be sensitive to (:meth:`measure_timing` instead)."""
        if self.follow == "setpoint":
            return
        for s, raws in enumerate(self._sensitivity_replays(x)):
            if raws is not None:
                self.sensitivity[s] = raws
                scatter = np.std(raws, axis=0, ddof=1)
                self.sigma[s] = np.sqrt(np.maximum(self.sigma[s]**2,
                                                   self.targets[s].noise_sigma**2 + scatter**2))

    def measure_timing(self, x: np.ndarray) -> None:
        """Following a setpoint: ``SENSITIVITY_REPLAYS`` replays at ``x``, each following the
        setpoint shifted by a draw of its own (:func:`shifted_setpoint`, seeds from
        ``SENSITIVITY_SEED``), draws of what the log cannot tell, the true drive's timing
        between its samples: the intervals' scatter (:meth:`sensitivity_scatter`,
        fit.intervals item 3). They do not join the weights, which stay the log's noise
        (the shifts move a compared value by 0.1-0.3 of it, RMS, on the tangent's log,
        tests/fit/test_fit.py). Not when the replays follow the logged speed."""
        if self.follow != "setpoint":
            return
        self.sensitivity = self._sensitivity_replays(x)

    def _sensitivity_replays(self, x: np.ndarray) -> list[np.ndarray | None]:
        """Per start-up, the compared values of ``SENSITIVITY_REPLAYS`` replays at ``x``
        seeded from ``SENSITIVITY_SEED`` (run where not cached), shape (replays, values);
        None where fewer than two were not refused."""
        jobs = [(0, s, r) for s in range(len(self.targets)) for r in range(SENSITIVITY_REPLAYS)]
        keys = [f"{self._key(s, x)}:sensitivity{r}" for _, s, r in jobs]
        todo = [(key, job) for key, job in zip(keys, jobs, strict=True) if key not in self.done]
        self._map([self._args([x], job, SENSITIVITY_SEED) for _, job in todo],
                  lambda i, result: self._take(todo[i][0], todo[i][1][1], result))
        replays = []
        for s in range(len(self.targets)):
            raws = [self.done[key] for key, job in zip(keys, jobs, strict=True) if job[1] == s]
            raws = [r for r in raws if not isinstance(r, str)]
            replays.append(np.array(raws) if len(raws) >= 2 else None)
        return replays

    def misfit_sd(self, x: np.ndarray) -> float:
        """The standard deviation of the misfit (the sum of the squared residuals) at an
        evaluated ``x`` over the draws of its averaged replays (the jackknife over them,
        fit.intervals): the misfit's roughness from averaging a finite number."""
        variance = 0.0
        for s, target in enumerate(self.targets):
            raws = self._replays_at(s, x)
            if raws is None:
                return 0.0
            logged, sigma = target.logged, self.sigma[s]
            variance += jackknife_sd(
                lambda mean, logged=logged, sigma=sigma: float(np.sum(((mean - logged) /
                                                                      sigma)**2)),
                raws)**2
        return math.sqrt(variance)

    def sensitivity_scatter(self) -> np.ndarray:
        """The sensitivity replays' deviations from their mean over the weights, each row a
        replay, the start-ups' residuals side by side: how far the compared values of one
        log stray from the replays' expectation (empty when not measured). Following a
        setpoint, the replays of :meth:`measure_timing`."""
        if any(raws is None for raws in self.sensitivity):
            return np.zeros((0, 0))
        return np.hstack([(raws - raws.mean(axis=0)) / sigma
                          for raws, sigma in zip(self.sensitivity, self.sigma, strict=True)])

    def map_runs(self, values: dict[str, float]) -> list[tuple[np.ndarray, np.ndarray]]:
        """Each start-up replayed with ``values``: (string torque N m, bit speed rad/s)."""
        runs = self._map([(self.data, values, t.log.t_s, self._series(t), None,
                           t.cutoff_hz, self.follow) for t in self.targets])
        for run in runs:
            if isinstance(run, str):
                raise DrillSimError(f"the fitted values are refused: {run}")
        return runs

    def _map(self, arguments: list[tuple[Any, ...]],
             on_result: Callable[[int, Any], None] | None = None) -> list[Any]:
        """:func:`simulate` over ``arguments``, in parallel on the client (None: here);
        ``on_result(index, result)`` as each finishes (what the cache is written from)."""
        results: list[Any] = [None] * len(arguments)

        def take(index: int, result: Any) -> None:
            results[index] = result
            if on_result is not None:
                on_result(index, result)
        if self.client is None:
            for i, a in enumerate(arguments):
                take(i, simulate(*a))
            return results
        from distributed import as_completed
        futures = {self.client.submit(simulate, *a, pure=False): i
                   for i, a in enumerate(arguments)}
        for future in as_completed(futures):
            take(futures[future], future.result())
        return results


def _size(target: Target) -> int:
    """The number of residuals of ``target`` (what a refused vector fills)."""
    n = target.torque.transient.size + target.torque.used.size + target.breakaway.size
    if target.bit is not None:
        n += target.bit.transient.size + target.bit.used.size
    return n


# ---- the fit --------------------------------------------------------------------------
@dataclass(frozen=True)
class FitResult:
    """The fitted values, their 95 % intervals and correlations, the misfits before and
    after, the optimiser's counts, and warnings (one line each)."""

    params: tuple[FitParameter, ...]
    x: np.ndarray
    low95: np.ndarray
    high95: np.ndarray
    correlation: np.ndarray
    misfit_before: float
    misfit_after: float
    evaluations: int
    replays: int
    reused: int
    seconds: float
    warnings: tuple[str, ...]
    stages: dict[str, tuple[int, float]]   # replays run and seconds taken, by stage
    cycles: tuple[np.ndarray | None, ...] = ()   # per start-up: Evaluator.replayed_cycles


def fit(evaluator: Evaluator, seed: int = 0) -> FitResult:
    """Fit ``evaluator``'s parameters (module doc)."""
    from scipy.optimize import least_squares
    from scipy.stats import qmc
    params = evaluator.params
    low = np.array([p.low for p in params])
    span = np.array([p.high for p in params]) - low
    x0 = np.array([p.initial for p in params])
    share = SETPOINT_STEP_SHARE if evaluator.follow == "setpoint" else 1.0
    jacobian_step = [JACOBIAN_STEP]       # the first pass's; then ``share`` times it

    def x_of(u: np.ndarray) -> np.ndarray:
        return low + span * np.clip(u, 0.0, 1.0)

    stages: dict[str, tuple[int, float]] = {}
    mark = [evaluator.computed, time.perf_counter()]

    def stage(name: str) -> None:
        """Book the replays run and the time taken since the last stage under ``name``."""
        now = time.perf_counter()
        stages[name] = (evaluator.computed - mark[0], now - mark[1])
        mark[:] = [evaluator.computed, now]

    starts = qmc.LatinHypercube(d=len(params), seed=seed).random(
        STARTS_PER_PARAMETER * len(params))
    points = [x0, *[x_of(u) for u in starts]]
    evaluator.measure_sensitivity(x0)
    evaluator.measure_sensitivity(min(evaluator.evaluate(points), key=lambda e: e.misfit).x)
    global_points = list(points)
    count = [len(points)]
    stage("global")

    def fun(u: np.ndarray) -> np.ndarray:
        count[0] += 1
        return evaluator.evaluate([x_of(u)])[0].residuals

    def jac(u: np.ndarray) -> np.ndarray:
        steps = [_step(u, i, jacobian_step[0]) for i in range(u.size)]
        points = [x_of(u), *[x_of(u + h) for h in steps]]
        evals = evaluator.evaluate(points)
        count[0] += len(points) - 1
        columns = [(e.residuals - evals[0].residuals) / h.sum()
                   for e, h in zip(evals[1:], steps, strict=True)]
        return np.column_stack(columns)

    def descend(x_start: np.ndarray) -> np.ndarray:
        """Where least squares from ``x_start`` stops."""
        result = least_squares(fun, (x_start - low) / span, jac=jac, bounds=(0.0, 1.0),
                               method="trf", ftol=TOLERANCE, xtol=TOLERANCE,
                               max_nfev=MAX_ITERATIONS)
        return x_of(result.x)

    for pass_index, starts_now in enumerate((LOCAL_STARTS, *[1] * (PASSES - 1))):
        jacobian_step[0] = JACOBIAN_STEP * (1.0 if pass_index == 0 else share)
        tried = sorted(evaluator.evaluate(points), key=lambda e: e.misfit)  # weighted anew
        ends = []
        for start in tried[:starts_now]:
            ends.append(evaluator.evaluate([descend(start.x)])[0])
        best = min([*ends, tried[0]], key=lambda e: e.misfit)
        evaluator.measure_sensitivity(best.x)
        points += [e.x for e in ends]
    best = min(evaluator.evaluate(points), key=lambda e: e.misfit)
    stage("least squares")
    if best.misfit > MISFIT_LOST:         # lost: start again (module doc, step 3)
        jacobian_step[0] = RESCUE_STEP
        ranked = sorted(evaluator.evaluate(global_points), key=lambda e: e.misfit)
        for start in _rescue_starts(x0, ranked):
            points.append(descend(start))
            best = min(evaluator.evaluate(points), key=lambda e: e.misfit)
            if best.misfit <= MISFIT_LOST:
                break
        jacobian_step[0] = JACOBIAN_STEP * share
    stage("rescue")
    for _ in range(BRACKET_ROUNDS):
        u_now = (best.x - low) / span
        valleys = profile_directions(jac(u_now))
        nearby = evaluator.evaluate([x_of(u) for u in _bracket(u_now, valleys, share)])
        count[0] += len(nearby)
        points += [e.x for e in nearby]
        better = min(nearby, key=lambda e: e.misfit)
        if better.misfit >= best.misfit:
            break
        points.append(descend(better.x))
        best = min(evaluator.evaluate(points), key=lambda e: e.misfit)
    before = evaluator.evaluate([x0])[0]
    stage("bracket")
    u_best = (best.x - low) / span
    jacobian = jac(u_best)
    evaluator.measure_timing(best.x)
    bands = profile_intervals(
        lambda us: [e.residuals for e in evaluator.evaluate([x_of(u) for u in us])],
        u_best, best.residuals, jacobian, evaluator.sensitivity_scatter(), evaluator.replays,
        evaluator.misfit_sd(best.x), share)
    count[0] += bands.points
    stage("intervals")
    warnings = [*one_speed_warning(params, [t.log.speed_rad_s for t in evaluator.targets]),
                *_warnings(params, best, jacobian, bands.correlation)]
    return FitResult(tuple(params), best.x, x_of(bands.low), x_of(bands.high),
                     bands.correlation, before.misfit, best.misfit, count[0],
                     evaluator.computed, evaluator.reused,
                     time.perf_counter() - evaluator.started, tuple(warnings), stages,
                     tuple(evaluator.replayed_cycles(best.x)))


def _rescue_starts(x0: np.ndarray, ranked: Sequence[Evaluation]) -> list[np.ndarray]:
    """Where a lost search starts again (module doc, step 3): the given values, then the
    global start's best points, ``RESCUE_STARTS`` in all."""
    others = [e.x for e in ranked if not np.array_equal(e.x, x0)]
    return [x0, *others][:RESCUE_STARTS]


def _bracket(u: np.ndarray, directions: np.ndarray, share: float = 1.0) -> list[np.ndarray]:
    """The points ``BRACKET_STEPS`` times ``share`` (in u) on either side of ``u`` along
    each parameter's valley (``directions[:, i]``, its entry i one:
    fit.intervals.profile_directions), parameter i within its bounds, the others clipped
    to theirs (module doc, step 4)."""
    out = []
    for i in range(u.size):
        for h in (share * b for b in (*BRACKET_STEPS, *(-b for b in BRACKET_STEPS))):
            if 0.0 <= u[i] + h <= 1.0:
                out.append(np.clip(u + h * directions[:, i], 0.0, 1.0))
    return out


def _step(u: np.ndarray, i: int, size: float) -> np.ndarray:
    """The forward step of parameter ``i`` (backward at the upper bound)."""
    h = np.zeros_like(u)
    h[i] = size if u[i] + size <= 1.0 else -size
    return h


def one_speed_warning(params: Sequence[FitParameter], speeds_rad_s: Sequence[np.ndarray]
                      ) -> list[str]:
    """A warning when the string's viscous loss is fitted with a Coulomb friction on
    start-ups that all turn at about one speed (their turning speeds, each the median of a
    start-up's second half, less than ``SPEED_SPREAD`` apart). The viscous loss is a torque
    rate x inertia x speed; the dynamic friction's does not depend on speed. At one speed a
    little more of one and a little less of the other give nearly the same torque: on the
    Well B-like tangent at 40 rpm the four fitted jointly put the damping 8.4 % high and the
    dynamic coefficient 0.9 % low (docs/fit.md), a point a start-up at 120 rpm rejects;
    fitted to both speeds, the damping's bias halved (+2.5 to +6.3 % on four logs)."""
    fitted = {p.path for p in params}
    if VISCOUS_PATH not in fitted or not fitted.intersection(COULOMB_PATHS):
        return []
    turning = [float(np.median(s[s.size // 2:])) for s in speeds_rad_s if s.size]
    if not turning or min(turning) <= 0.0 or max(turning) >= SPEED_SPREAD * min(turning):
        return []
    rpm = [v * RPM_PER_RAD_S for v in (min(turning), max(turning))]
    at = f"{rpm[0]:.0f} rpm" if rpm[1] - rpm[0] < 0.5 else f"{rpm[0]:.0f} to {rpm[1]:.0f} rpm"
    return [f"every start-up turns at {at}: at one speed the log can hardly tell "
            f"{VISCOUS_PATH} (a loss growing with speed) from "
            f"{' or '.join(fitted.intersection(COULOMB_PATHS))} (one that does not); add a "
            f"start-up at {SPEED_SPREAD:g} times the speed or more (docs/fit.md)"]


def _warnings(params: Sequence[FitParameter], best: Evaluation, jacobian: np.ndarray,
              correlation: np.ndarray) -> list[str]:
    """A parameter the misfit does not move with, a pair the log cannot tell apart (their
    |correlation| above ``CORRELATED``), fitted values the preset refused, and a fit that
    missed the log: the weights are the log's noise, so a model that reproduces it scores
    about 1 (the truth scored 0.50 to 1.31 in every study of docs/fit.md), and a misfit
    above ``MISFIT_LOST`` means residuals that many times the noise (one fit of 60 from
    15 % below stopped at 16.1, its damping +70 %, its intervals narrow around it, before
    the rescue of step 3 of the module doc: a fit still lost after it is warned)."""
    warnings = []
    if best.misfit > MISFIT_LOST:
        warnings.append(f"the fit missed the log: its misfit is {best.misfit:.3g} times the "
                        f"log's noise (about 1 where the model reproduces the log), so its "
                        "values and intervals are not to be trusted; start from other values "
                        "(the preset's), narrow the bounds, or fit fewer parameters")
    for i, p in enumerate(params):
        if not np.any(jacobian[:, i]):
            warnings.append(f"the log does not constrain {p.path} (the misfit does not move "
                            "with it)")
        for j in range(i + 1, len(params)):
            if abs(correlation[i, j]) > CORRELATED:
                warnings.append(f"the log cannot tell {p.path} and {params[j].path} apart "
                                f"(correlation {correlation[i, j]:+.3f}): fix one, or add a "
                                "log that moves them differently")
    if best.refused:
        warnings.append(f"the preset refused the fitted values: {best.refused}")
    return warnings
