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
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from drill_sim_ros.model.errors import ParameterError

SIGNALS = ("drive_speed_rad_s", "motor_torque_nm", "string_torque_nm", "hook_load_n")
MAX_DELAY_PERIODS = 10_000


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
        self.reset()

    @property
    def perfect(self) -> bool:
        """True when every sensor is perfect (the measurement is the truth)."""
        return all(spec == SignalSpec() for spec in self._spec)

    def reset(self) -> None:
        """Forget the delay lines and restart the noise sequence."""
        self._rng = [np.random.Generator(np.random.PCG64([self.seed, i]))
                     for i in range(len(SIGNALS))]
        self._pending: list[np.ndarray | None] = [None] * len(SIGNALS)

    def measure(self, truth: np.ndarray) -> np.ndarray:
        """Measured values of a block of samples: ``truth`` and the result have shape
        (rows, len(SIGNALS)), columns in :data:`SIGNALS` order, SI units."""
        truth = np.asarray(truth, dtype=float)
        if truth.ndim != 2 or truth.shape[1] != len(SIGNALS):
            raise ParameterError(f"truth must have shape (rows, {len(SIGNALS)}), got "
                                 f"{truth.shape}")
        out = np.empty_like(truth)
        for i, spec in enumerate(self._spec):
            out[:, i] = self._sense(i, spec, truth[:, i])
        return out

    def _sense(self, i: int, spec: SignalSpec, x: np.ndarray) -> np.ndarray:
        y = x + self._rng[i].normal(0.0, spec.noise_std, x.size) if spec.noise_std else x.copy()
        if spec.quantum:
            y = np.round(y / spec.quantum) * spec.quantum
        if not spec.delay_periods or x.size == 0:
            return y
        line = self._pending[i]
        if line is None:                          # before the first sample: its value
            line = np.full(spec.delay_periods, y[0])
        joined = np.concatenate([line, y])
        self._pending[i] = joined[-spec.delay_periods:]
        return joined[:x.size]
