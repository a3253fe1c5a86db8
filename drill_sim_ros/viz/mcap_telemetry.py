"""Read ``/drill/telemetry`` out of a recorded MCAP (ROS 2 profile, CDR) as batches.

Decoding uses ``mcap`` with ``mcap_ros2``'s decoder, independent of the archive package.
"""

from __future__ import annotations

import json
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory

from drill_sim_ros import topics
from drill_sim_ros.viz.telemetry import N_FIELDS, TelemetryBatch, field_order

PRESET_KEYS = ("preset", "model.preset")


class NoTelemetryError(RuntimeError):
    """The recording has no usable /drill/telemetry message."""


def read_telemetry(path: str | Path, batch_rows: int = 20_000) -> Iterator[TelemetryBatch]:
    """Yield the telemetry samples in file order, ``batch_rows`` at a time.

    Messages shorter than the field list are skipped. Raises NoTelemetryError if none is read.
    """
    rows: list[np.ndarray] = []
    order: np.ndarray | None = None
    seen = 0
    with open(path, "rb") as stream:
        reader = make_reader(stream, decoder_factories=[DecoderFactory()])
        for _, _, _, msg in reader.iter_decoded_messages(topics=[topics.TELEMETRY]):
            if order is None:
                order = field_order([d.label for d in msg.layout.dim])
            if len(msg.data) < N_FIELDS:
                continue
            rows.append(np.asarray(msg.data, dtype=np.float64))
            seen += 1
            if len(rows) >= batch_rows:
                yield TelemetryBatch.from_rows(np.stack(rows), order)
                rows = []
    if rows:
        yield TelemetryBatch.from_rows(np.stack(rows), order)
    if not seen:
        raise NoTelemetryError(f"{path}: no {topics.TELEMETRY} messages with "
                               f"{N_FIELDS} fields")


def recorded_run_info(path: str | Path) -> dict[str, Any] | None:
    """What the recorded sim ran (its first /drill/run_info message, JSON), if any."""
    with open(path, "rb") as stream:
        reader = make_reader(stream, decoder_factories=[DecoderFactory()])
        for _, _, _, msg in reader.iter_decoded_messages(topics=[topics.RUN_INFO]):
            return json.loads(msg.data)
    return None


def recorded_preset(path: str | Path) -> str | None:
    """A preset name stored in the file's metadata records (key 'preset'), if any."""
    with open(path, "rb") as stream:
        reader = make_reader(stream)
        for record in reader.iter_metadata():
            for key in PRESET_KEYS:
                if record.metadata.get(key):
                    return record.metadata[key]
    return None
