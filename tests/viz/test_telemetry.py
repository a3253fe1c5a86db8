"""Telemetry layout parsing and batching."""

from __future__ import annotations

import numpy as np

from drill_sim_ros.topics import TELEMETRY_FIELDS
from drill_sim_ros.viz.telemetry import TelemetryBatch, field_order

N = len(TELEMETRY_FIELDS)


def test_comma_joined_label_in_dim0() -> None:
    np.testing.assert_array_equal(field_order([",".join(TELEMETRY_FIELDS)]), np.arange(N))


def test_permuted_labels_are_reordered() -> None:
    names = list(reversed(TELEMETRY_FIELDS))
    row = np.arange(N, dtype=float)[::-1]           # value i belongs to TELEMETRY_FIELDS[i]
    batch = TelemetryBatch.from_rows(row[None, :], field_order(names))
    np.testing.assert_array_equal(batch.rows[0], np.arange(N))
    assert batch.column("sim_time_s")[0] == 0.0


def test_missing_labels_mean_canonical_order() -> None:
    np.testing.assert_array_equal(field_order([]), np.arange(N))
    np.testing.assert_array_equal(field_order(["bogus"]), np.arange(N))


def test_backwards_time_splits_the_batch() -> None:
    rows = np.zeros((5, N))
    rows[:, 0] = [0.0, 0.1, 0.2, 0.0, 0.1]
    parts = TelemetryBatch(rows).monotonic_parts()
    assert [len(p) for p in parts] == [3, 2]
