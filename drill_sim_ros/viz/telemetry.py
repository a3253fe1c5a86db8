"""Telemetry samples as columns: the one input shared by the live bridge and mcap_to_rerun.

A ``/drill/telemetry`` message (std_msgs/Float64MultiArray) carries one sample whose fields
are :data:`drill_sim_ros.topics.TELEMETRY_FIELDS` (SI units). A :class:`TelemetryBatch`
holds n such samples, columns always in that canonical order.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from drill_sim_ros.topics import TELEMETRY_FIELDS, TELEMETRY_INDEX

N_FIELDS = len(TELEMETRY_FIELDS)


def field_order(labels: Sequence[str]) -> np.ndarray:
    """Positions of the canonical fields in a message, from its ``layout.dim`` labels.

    Accepts ``dim[0].label`` listing every name (separated by commas, semicolons or
    spaces) or one dim per field. Without usable labels the canonical order is assumed.
    Returns an int array of shape (N_FIELDS,): message position of each canonical field.
    """
    names = [n for n in re.split(r"[,;\s]+", labels[0]) if n] if labels else []
    if len(names) < N_FIELDS and len(labels) >= N_FIELDS:
        names = list(labels)
    if not set(TELEMETRY_FIELDS) <= set(names):
        return np.arange(N_FIELDS)
    return np.array([names.index(name) for name in TELEMETRY_FIELDS])


@dataclass(frozen=True)
class TelemetryBatch:
    """n telemetry samples; ``rows`` has shape (n, N_FIELDS), columns in canonical order."""

    rows: np.ndarray

    @classmethod
    def from_rows(cls, rows: np.ndarray | Sequence[Sequence[float]],
                  order: np.ndarray | None = None) -> TelemetryBatch:
        """Build from message rows (n, >= N_FIELDS); ``order`` from :func:`field_order`."""
        data = np.asarray(rows, dtype=np.float64)
        if data.size == 0:
            data = np.empty((0, N_FIELDS))
        index = np.arange(N_FIELDS) if order is None else order
        return cls(np.ascontiguousarray(data[:, index]))

    def __len__(self) -> int:
        return self.rows.shape[0]

    def column(self, name: str) -> np.ndarray:
        """One field over the batch, shape (n,)."""
        return self.rows[:, TELEMETRY_INDEX[name]]

    @property
    def sim_time_s(self) -> np.ndarray:
        return self.column("sim_time_s")

    def monotonic_parts(self) -> list[TelemetryBatch]:
        """Split where sim time goes backwards (a simulator reset starts a new part)."""
        cuts = np.flatnonzero(np.diff(self.sim_time_s) < 0.0) + 1
        return [TelemetryBatch(part) for part in np.split(self.rows, cuts) if len(part)]
