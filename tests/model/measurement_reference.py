"""A second, plain implementation of the rig sensors (``model.measurement``) for the tests.

The block-by-block numpy form the sensors had before issue 35: per signal, the noise drawn
for the block (``Generator.normal``), ``np.round`` to the quantum, and the delay as the
concatenation of the pending samples and the block. Slow (allocations per call), obviously
right; the production sensors must give the same measurements bit for bit.
"""

from __future__ import annotations

import numpy as np

from drill_sim_ros.model.measurement import SIGNALS, SignalSpec


class ReferenceSensors:
    """The sensors of ``specs`` (a name of SIGNALS -> SignalSpec) seeded with ``seed``."""

    def __init__(self, specs: dict[str, SignalSpec], seed: int = 0) -> None:
        self._spec = [specs.get(name, SignalSpec()) for name in SIGNALS]
        self._rng = [np.random.Generator(np.random.PCG64([seed, i]))
                     for i in range(len(SIGNALS))]
        self._pending: list[np.ndarray | None] = [None] * len(SIGNALS)

    def measure(self, truth: np.ndarray) -> np.ndarray:
        """Measured values of a block (rows, len(SIGNALS)) of true ones."""
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
        if line is None:
            line = np.full(spec.delay_periods, y[0])
        joined = np.concatenate([line, y])
        self._pending[i] = joined[-spec.delay_periods:]
        return joined[:x.size]
