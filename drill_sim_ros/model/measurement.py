"""What a rig measures at the surface: the drive's signals as its sensors give them.

A rig has, at the surface, the drive's speed (encoder), its motor torque (the drive's own
estimate from the motor current), where a torque sub is fitted, the string torque at the
quill, and the hook load (the deadline load cell; the driller's applied-WOB estimate is the
off-bottom hook load less the measured one, ``model.telemetry``). The bit's speed, depth of
cut, WOB and TOB are downhole truth that only the simulator knows. :class:`RigSensors`
turns the true surface signals of each sample (SI, one column per signal of
:data:`SIGNALS`) into measured ones, per signal and off by default:

* Gaussian noise of standard deviation ``noise_std`` (seeded: the same samples give the same
  measurements, run after run and whatever the blocks they come in);
* quantisation to multiples of ``quantum`` (round to nearest), applied to the noisy value as
  an ADC does;
* a delay of ``delay_periods`` whole samples (the first measurements repeat the first value).

Each sample costs the same whatever the settings and the block it comes in (issue 35): one
compiled pass over the block (:func:`sense_rows`) adds noise drawn ahead in blocks of
:data:`NOISE_BLOCK_SAMPLES` (per signal, the same stream as drawing it sample by sample),
rounds, and swaps the value through a preallocated ring buffer of the delay. Nothing is
allocated per sample or per call but the refills of the noise blocks.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from numba import njit

from drill_sim_ros.model.errors import ParameterError

SIGNALS = ("drive_speed_rad_s", "motor_torque_nm", "string_torque_nm", "hook_load_n")
MAX_DELAY_PERIODS = 10_000
NOISE_BLOCK_SAMPLES = 4096      # noise drawn ahead per signal, samples
_ALL_COLUMNS = np.arange(len(SIGNALS), dtype=np.int64)


@dataclass(frozen=True)
class SignalSpec:
    """One sensor: noise_std and quantum in the signal's unit (0: none), delay in samples."""

    noise_std: float = 0.0
    quantum: float = 0.0
    delay_periods: int = 0

    def __post_init__(self) -> None:
        for name in ("noise_std", "quantum"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value >= 0.0):
                raise ParameterError(f"parameter '{name}' = {value!r} must be finite and >= 0")
        if not (isinstance(self.delay_periods, int) and
                0 <= self.delay_periods <= MAX_DELAY_PERIODS):
            raise ParameterError(f"parameter 'delay_periods' = {self.delay_periods!r} must be "
                                 f"an integer in [0, {MAX_DELAY_PERIODS}]")


@njit(cache=True)
def sense_rows(rows: np.ndarray, columns: np.ndarray, noise_std: np.ndarray,
               quantum: np.ndarray, delay_periods: np.ndarray, noise: np.ndarray,
               noise_at: int, lines: np.ndarray, seen: int) -> None:
    """Measure, in place, signal ``i`` of :data:`SIGNALS` in column ``columns[i]`` of each of
    ``rows`` (shape (samples, any), the true values in, the measured out; SI).

    Per signal: ``noise_std * noise[i, noise_at + r]`` added to row ``r`` (``noise`` holds
    standard normal draws), rounded to the nearest multiple of ``quantum`` (half to even,
    as numpy rounds), then swapped through the ring buffer ``lines[i, :delay_periods[i]]``;
    ``seen`` samples were measured before, and the first fills the buffer with its value.
    """
    for r in range(rows.shape[0]):
        count = seen + r
        for i in range(columns.size):
            y = rows[r, columns[i]]
            if noise_std[i] > 0.0:
                y = y + (0.0 + noise_std[i] * noise[i, noise_at + r])   # = normal(0, std)
            if quantum[i] > 0.0:
                y = np.rint(y / quantum[i]) * quantum[i]
            d = delay_periods[i]
            if d > 0:
                if count == 0:
                    lines[i, :d] = y
                slot = count % d
                y, lines[i, slot] = lines[i, slot], y
            rows[r, columns[i]] = y


@dataclass
class RigSensors:
    """Measured surface signals from true ones; ``specs`` maps a name of :data:`SIGNALS` to
    its :class:`SignalSpec` (missing: a perfect sensor); ``seed`` seeds the noise."""

    specs: dict[str, SignalSpec] = field(default_factory=dict)
    seed: int = 0

    def __post_init__(self) -> None:
        unknown = sorted(set(self.specs) - set(SIGNALS))
        if unknown:
            raise ParameterError(f"unknown signal(s) {unknown}; known: {list(SIGNALS)}")
        self._spec = [self.specs.get(name, SignalSpec()) for name in SIGNALS]
        self._noise_std = np.array([spec.noise_std for spec in self._spec])
        self._quantum = np.array([spec.quantum for spec in self._spec])
        self._delay = np.array([spec.delay_periods for spec in self._spec], dtype=np.int64)
        self._noisy = [i for i, spec in enumerate(self._spec) if spec.noise_std]
        self._lines = np.zeros((len(SIGNALS), max(1, int(self._delay.max()))))
        self.reset()

    @property
    def perfect(self) -> bool:
        """True when every sensor is perfect (the measurement is the truth)."""
        return all(spec == SignalSpec() for spec in self._spec)

    def reset(self) -> None:
        """Forget the delay lines and restart the noise sequence."""
        self._rng = [np.random.Generator(np.random.PCG64([self.seed, i]))
                     for i in range(len(SIGNALS))]
        self._noise = np.zeros((len(SIGNALS), NOISE_BLOCK_SAMPLES))
        self._noise_at = NOISE_BLOCK_SAMPLES      # drawn ahead: none yet
        self._seen = 0                            # samples measured since the reset

    def measure(self, truth: np.ndarray) -> np.ndarray:
        """Measured values of a block of samples: ``truth`` and the result have shape
        (rows, len(SIGNALS)), columns in :data:`SIGNALS` order, SI units."""
        truth = np.asarray(truth, dtype=float)
        if truth.ndim != 2 or truth.shape[1] != len(SIGNALS):
            raise ParameterError(f"truth must have shape (rows, {len(SIGNALS)}), got "
                                 f"{truth.shape}")
        out = np.array(truth, order="C")
        self.measure_into(out, _ALL_COLUMNS)
        return out

    def measure_into(self, rows: np.ndarray, columns: np.ndarray) -> None:
        """:meth:`measure` in place: signal ``i`` of :data:`SIGNALS` is column ``columns[i]``
        (int64) of the float64 array ``rows`` (samples, any), true in, measured out."""
        samples = rows.shape[0]
        if self._noise_at + samples > self._noise.shape[1]:
            self._draw_ahead(samples)
        sense_rows(rows, columns, self._noise_std, self._quantum, self._delay, self._noise,
                   self._noise_at, self._lines, self._seen)
        self._noise_at += samples
        self._seen += samples

    def _draw_ahead(self, samples: int) -> None:
        """Refill the noise blocks so that ``samples`` draws are ready: the undrawn tail
        first, then the next draws of each noisy signal's stream."""
        left = self._noise.shape[1] - self._noise_at
        if samples > self._noise.shape[1]:        # a block longer than any before
            noise = np.zeros((len(SIGNALS), samples))
        else:
            noise = self._noise
        noise[:, :left] = self._noise[:, self._noise_at:]
        for i in self._noisy:
            self._rng[i].standard_normal(out=noise[i, left:])
        self._noise, self._noise_at = noise, 0
