"""The misfit between a start-up as logged and as replayed: what ``drill_sim fit`` minimises.

Both torques are compared low-passed at the string's cut-off (twice its third torsional
mode, zero-phase, :func:`analysis.lowpass`: the stick-slip and its harmonics, not the
collars' ringing, whose phase no model keeps), each torque the kind the log holds: the
torque sub's string torque as simulated, or the motor torque as the string torque plus the
drive's inertia times the logged speed's (low-passed) rate of change. The residual vector
of a start-up has two parts, each residual divided by its own uncertainty:

1. **The transient, in time**: from the start to ``SLIP_GUARD_S`` before the first slip
   seen at the surface (the low-passed logged torque first falls more than ``DROP_SHARE``
   of its range below its running maximum, :func:`first_slip_index`), at the cut-off's
   Nyquist rate (every 1 / (2 f_c) s), divided by the logged torque's noise there,
   sigma sqrt(2 f_c dt) (sigma from the log's second differences: :func:`noise_std`): the
   winding up, sample by sample; then the break-away: the peak torque before the first
   slip (the torque's noise). The moment of the first slip itself is not compared: it
   moves by half a second between replays that differ only in the speed sensor's noise
   (measured 2026-12-06 on field_8p5in_deviated), a sensitivity of the model, not a
   property of the wall.
2. **The cycle, drift-free**, from ``SLIP_MARGIN_S`` after the first slip to the end: its
   period (the first peak of the torque's autocorrelation, :func:`period_s`), mean,
   standard deviation and the 10, 25, 50, 75 and 90 % quantiles of the low-passed torque:
   none of them moves when the cycle drifts in phase, which a stick-slip limit cycle does
   after a few periods (its slips are sensitive to the smallest difference). Each is
   divided by how much it scatters in the log: the feature over blocks of one period each,
   their standard deviation over the square root of their count (at least the noise's
   share; with fewer than two blocks, ``LONE_BLOCK_SHARE`` of the feature's scale).

The log's noise is not all the uncertainty: the replay follows the *logged* speed, noise
and all, and the wall's junctions let go at times that are sensitive to it, so a replay with
the true parameters still strays from the log by more than the torque's noise. The fit
(fit.engine) measures that: it replays the start-up a few times with fresh noise of the
speed's own size added to the speed, and adds the scatter of each compared value to its
uncertainty (in quadrature).

A downhole bit speed, where logged, adds its own transient (in time) and its cycle's mean
and standard deviation, the same way. The misfit reported is the root mean square of the
residuals (1: the model within the log's noise and scatter).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from drill_sim_ros.fit.log import SurfaceLog
from drill_sim_ros.model.analysis import MODE_COUNT, cutoff_of, lowpass
from drill_sim_ros.model.presets import Preset
from drill_sim_ros.model.string import analytic_modes_hz

DROP_SHARE = 0.2          # the first slip: the torque this share of its range below its peak
SLIP_GUARD_S = 1.0        # the transient in time stops this long before the first slip
SLIP_MARGIN_S = 1.0       # the transient runs this long after the first slip
QUANTILES = (0.10, 0.25, 0.50, 0.75, 0.90)
FEATURES = ("period_s", "mean_nm", "std_nm", *tuple(f"q{round(100 * q)}_nm" for q in QUANTILES))
LONE_BLOCK_SHARE = 0.05   # a feature's uncertainty when the log has under two cycles
MIN_CYCLE_S = 1.0         # a cycle window shorter than this is not compared


def noise_std(values: np.ndarray) -> float:
    """The white noise of a smooth signal sampled finely: the median absolute second
    difference / 0.6745 / sqrt(6) (a second difference of white noise has variance
    6 sigma^2; the median ignores the signal's own kinks)."""
    second = np.diff(np.asarray(values, dtype=float), 2)
    return float(np.median(np.abs(second - np.median(second))) / 0.6745 / math.sqrt(6.0))


def cutoff_hz(preset: Preset) -> float:
    """The stick-slip's cut-off of ``preset``'s string (twice its third torsional mode)."""
    return cutoff_of(tuple(analytic_modes_hz(preset.string, MODE_COUNT)))


def first_slip_index(torque_lp: np.ndarray) -> int | None:
    """The first sample where ``torque_lp`` lies more than ``DROP_SHARE`` of the record's
    range (max - first) below its running maximum: a slip, not one of the small drops of
    the winding up as the wall lets go of the string bit by bit; None: never."""
    peak = np.maximum.accumulate(torque_lp)
    drop = np.flatnonzero(torque_lp < peak - DROP_SHARE * (peak[-1] - torque_lp[0]))
    return int(drop[0]) if drop.size else None


def period_s(values: np.ndarray, sample_s: float) -> float:
    """The period of a cycling signal: the lag of the first local peak of its
    autocorrelation, after its first zero crossing and within the first half of the window,
    that reaches half the highest there (parabolic between samples; a later, higher peak is
    a multiple of it); the window's length when there is none (no cycle)."""
    x = np.asarray(values, dtype=float) - np.mean(values)
    n = x.size
    spectrum = np.fft.rfft(x, 2 * n)
    acf = np.fft.irfft(spectrum * np.conj(spectrum))[: n // 2 + 1]
    negative = np.flatnonzero(acf < 0.0)
    if acf[0] <= 0.0 or not negative.size or negative[0] >= acf.size - 2:
        return n * sample_s
    start = int(negative[0])
    inner = acf[start + 1:-1]
    peaks = start + 1 + np.flatnonzero((inner >= acf[start:-2]) & (inner > acf[start + 2:]))
    peaks = peaks[acf[peaks] >= 0.5 * np.max(acf[start:])] if peaks.size else peaks
    if not peaks.size or acf[peaks[0]] <= 0.0:
        return n * sample_s
    peak = int(peaks[0])
    a, b, c = acf[peak - 1], acf[peak], acf[peak + 1]
    shift = 0.5 * (a - c) / (a - 2.0 * b + c) if a - 2.0 * b + c < 0.0 else 0.0
    return (peak + shift) * sample_s


def cycle_features(values: np.ndarray, sample_s: float) -> np.ndarray:
    """:data:`FEATURES` of the low-passed torque over a cycle window."""
    return np.concatenate(([period_s(values, sample_s), np.mean(values), np.std(values)],
                           np.quantile(values, QUANTILES)))


@dataclass(frozen=True)
class Part:
    """How one signal of a start-up is compared: the transient's samples ``transient``
    (indices), their logged values and uncertainty; the cycle window ``cycle`` (a slice),
    its logged features, their uncertainties, and which features are used."""

    transient: np.ndarray
    logged_transient: np.ndarray
    transient_sigma: float
    cycle: slice
    features: np.ndarray
    feature_sigma: np.ndarray
    used: np.ndarray               # indices into FEATURES


@dataclass(frozen=True)
class Target:
    """A start-up's log prepared for comparison: its SI samples, the cut-off, the drive's
    inertia (for a motor torque), the torque's and the bit speed's :class:`Part`."""

    log: SurfaceLog
    cutoff_hz: float
    drive_inertia_kg_m2: float
    torque: Part
    bit: Part | None
    breakaway: np.ndarray          # the logged peak torque before the first slip, N m
    breakaway_sigma: np.ndarray
    first_slip_s: float | None     # the logged first slip, s from the start (None: none)

    def model_torque(self, string_torque_nm: np.ndarray) -> np.ndarray:
        """The simulated counterpart of the logged torque, low-passed (module doc)."""
        dt = self.log.sample_s
        torque = lowpass(string_torque_nm, dt, self.cutoff_hz)
        if self.log.torque_kind == "motor":
            speed = lowpass(self.log.speed_rad_s, dt, self.cutoff_hz)
            torque = torque + self.drive_inertia_kg_m2 * np.gradient(speed, dt)
        return torque

    def raw(self, string_torque_nm: np.ndarray,
            bit_speed_rad_s: np.ndarray | None = None) -> np.ndarray:
        """What a replay gives for the compared values (the transient's samples, the cycle's
        features; torque, then bit speed), unweighted, shape (n_residuals,)."""
        torque = self.model_torque(string_torque_nm)
        out = [_part_raw(self.torque, torque, self.log.sample_s),
               breakaway_features(torque, self.log.sample_s)]
        if self.bit is not None and bit_speed_rad_s is not None:
            out.append(_part_raw(self.bit, lowpass(bit_speed_rad_s, self.log.sample_s,
                                                    self.cutoff_hz), self.log.sample_s))
        return np.concatenate(out)

    def cycle_of(self, raw: np.ndarray) -> np.ndarray | None:
        """The torque's cycle (period s, mean and standard deviation N m) in a vector of
        :meth:`raw` (or :attr:`logged`); None when the cycle is not compared."""
        part = self.torque
        if not part.used.size:
            return None
        features = np.asarray(raw)[part.transient.size:part.transient.size + part.used.size]
        return np.array([features[list(part.used).index(FEATURES.index(name))]
                         for name in FEATURES[:3]])

    @property
    def logged(self) -> np.ndarray:
        """The logged counterpart of :meth:`raw`."""
        parts = [np.concatenate((p.logged_transient, p.features[p.used])) for p in self.parts]
        return np.concatenate([parts[0], self.breakaway, *parts[1:]])

    @property
    def noise_sigma(self) -> np.ndarray:
        """The log's own uncertainty of each compared value (module doc)."""
        parts = [np.concatenate((np.full(p.transient.size, p.transient_sigma),
                                 p.feature_sigma[p.used])) for p in self.parts]
        return np.concatenate([parts[0], self.breakaway_sigma, *parts[1:]])

    @property
    def parts(self) -> list[Part]:
        return [self.torque] if self.bit is None else [self.torque, self.bit]


def _part_raw(part: Part, model_lp: np.ndarray, sample_s: float) -> np.ndarray:
    if not part.used.size:
        return model_lp[part.transient]
    return np.concatenate((model_lp[part.transient],
                           cycle_features(model_lp[part.cycle], sample_s)[part.used]))


def make_target(log: SurfaceLog, preset: Preset) -> Target:
    """The comparison of a start-up's ``log`` with replays of ``preset`` (module doc)."""
    dt = log.sample_s
    fc = min(cutoff_hz(preset), 0.5 / dt)
    torque_lp = lowpass(log.torque_nm, dt, fc)
    n = log.t_s.size
    slip = first_slip_index(torque_lp)
    ends = (n, n) if slip is None else (max(1, slip - round(SLIP_GUARD_S / dt)),
                                        min(n, slip + round(SLIP_MARGIN_S / dt)))
    every = max(1, math.floor(0.5 / (fc * dt)))
    lp_share = min(1.0, math.sqrt(2.0 * fc * dt))
    torque = _part(log.torque_nm, torque_lp, ends, every, lp_share, dt, FEATURES)
    bit = None
    if log.bit_speed_rad_s is not None:
        bit = _part(log.bit_speed_rad_s, lowpass(log.bit_speed_rad_s, dt, fc), ends, every,
                    lp_share, dt, ("mean_nm", "std_nm"))
    return Target(log=log, cutoff_hz=fc, drive_inertia_kg_m2=preset.drive.inertia_kg_m2,
                  torque=torque, bit=bit, breakaway=breakaway_features(torque_lp, dt),
                  breakaway_sigma=np.array([torque.transient_sigma]),
                  first_slip_s=None if slip is None else slip * dt)


def breakaway_features(torque_lp: np.ndarray, sample_s: float) -> np.ndarray:
    """The peak torque before the first slip, N m (:func:`first_slip_index`; never: the
    record's maximum), shape (1,)."""
    slip = first_slip_index(torque_lp)
    end = torque_lp.size if slip is None else slip
    return np.array([float(np.max(torque_lp[:max(1, end)]))])


def _part(raw: np.ndarray, lp: np.ndarray, ends: tuple[int, int], every: int,
          lp_share: float, sample_s: float, names: tuple[str, ...]) -> Part:
    """The transient up to ``ends[0]``, the cycle from ``ends[1]`` (module doc)."""
    transient, end = np.arange(0, ends[0], every), ends[1]
    noise = max(noise_std(raw) * lp_share, 1e-9 * max(1.0, float(np.max(np.abs(lp)))))
    cycle = slice(end, lp.size)
    if (lp.size - end) * sample_s < MIN_CYCLE_S:
        empty = np.zeros(len(FEATURES))
        return Part(transient, lp[transient], noise, cycle, empty, empty + 1.0,
                    np.array([], dtype=int))
    window = lp[cycle]
    features = cycle_features(window, sample_s)
    sigma = _feature_sigma(window, sample_s, features, noise)
    used = np.array([FEATURES.index(name) for name in names], dtype=int)
    return Part(transient, lp[transient], noise, cycle, features, sigma, used)


def _feature_sigma(window: np.ndarray, sample_s: float, features: np.ndarray,
                   noise: float) -> np.ndarray:
    """Each feature's scatter over blocks of one period (module doc)."""
    period = features[0]
    size = max(2, round(period / sample_s))
    blocks = window.size // size
    scale = np.abs(features) + features[2]               # |feature| + the cycle's std
    if blocks < 2:
        return np.maximum(LONE_BLOCK_SHARE * scale, noise)
    per_block = np.array([cycle_features(window[i * size:(i + 1) * size], sample_s)
                          for i in range(blocks)])
    per_block[:, 0] = _crossing_periods(window, sample_s, blocks)
    sigma = np.std(per_block, axis=0, ddof=1) / math.sqrt(blocks)
    sigma[0] = max(sigma[0], sample_s)
    sigma[1:] = np.maximum(sigma[1:], noise)
    return sigma


def _crossing_periods(window: np.ndarray, sample_s: float, count: int) -> np.ndarray:
    """``count`` cycle lengths from the upward crossings of the window's mean (with a
    hysteresis of half its std), repeated or cut to ``count``; the window's period if it
    has fewer than two crossings."""
    x = window - np.mean(window)
    band = 0.5 * np.std(x)
    ups, armed = [], False
    for i, value in enumerate(x):
        if value < -band:
            armed = True
        elif armed and value > 0.0:
            ups.append(i)
            armed = False
    lengths = np.diff(ups) * sample_s
    if lengths.size < 2:
        return np.full(count, period_s(window, sample_s))
    return np.resize(lengths, count)
