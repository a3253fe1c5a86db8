"""Read ``/drill/telemetry`` out of a recorded MCAP (ROS 2 profile, CDR) as batches.

The records come from the archive's damage-tolerant reader (what ``mcap_reindex`` would keep:
every intact chunk); decoding uses ``mcap_ros2``'s decoder on the stored schema.
"""

from __future__ import annotations

import json
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import numpy as np
from mcap.reader import make_reader
from mcap.records import Schema
from mcap_ros2.decoder import DecoderFactory

from drill_sim_ros import topics
from drill_sim_ros.archive.reader import ArchiveReader, RecordedChannel
from drill_sim_ros.archive.recovery import DAMAGE
from drill_sim_ros.viz.string_views import StringBatch, string_batch
from drill_sim_ros.viz.telemetry import N_FIELDS, TelemetryBatch, field_order

PRESET_KEYS = ("preset", "model.preset")


class NoTelemetryError(RuntimeError):
    """The recording has no usable /drill/telemetry message."""


def channel_decoder(channel: RecordedChannel) -> Callable[[bytes], Any]:
    """A decoder of the CDR messages of ``channel``, from its stored schema."""
    schema = Schema(id=channel.channel_id, name=channel.type_name, encoding="ros2msg",
                    data=channel.schema_text.encode("utf-8"))
    return DecoderFactory().decoder_for("cdr", schema)


def read_telemetry(path: str | Path | ArchiveReader,
                   batch_rows: int = 20_000) -> Iterator[TelemetryBatch]:
    """Yield the telemetry samples in file order, ``batch_rows`` at a time.

    Messages shorter than the field list are skipped, and so are damaged chunks (the reader's
    ``problem`` says which). Raises NoTelemetryError if no sample is read.
    """
    reader = path if isinstance(path, ArchiveReader) else ArchiveReader(path)
    rows: list[np.ndarray] = []
    order: np.ndarray | None = None
    seen, decode = 0, None
    for message in reader.messages(lambda topic: topic == topics.TELEMETRY):
        decode = decode or channel_decoder(message.channel)
        msg = decode(message.data)
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
        raise NoTelemetryError(f"{reader.path}: no readable {topics.TELEMETRY} messages with "
                               f"{N_FIELDS} fields")


def read_string_profiles(path: str | Path | ArchiveReader,
                         batch_profiles: int = 1000) -> Iterator[StringBatch]:
    """Yield the string profiles in file order, ``batch_profiles`` at a time: those of
    drill/typed/string/torsion (StringProfile) or of drill/string/torsion (JointState),
    whichever the recording has (none for a lumped string or a recording made before the
    topics existed)."""
    reader = path if isinstance(path, ArchiveReader) else ArchiveReader(path)
    messages: list[Any] = []
    decoders: dict[int, Callable[[bytes], Any]] = {}
    for message in reader.messages(lambda topic: topic in topics.PROFILE_TOPICS):
        channel = message.channel
        if channel.channel_id not in decoders:
            decoders[channel.channel_id] = channel_decoder(channel)
        messages.append(decoders[channel.channel_id](message.data))
        if len(messages) >= batch_profiles:
            if (batch := string_batch(messages)) is not None:
                yield batch
            messages = []
    if messages and (batch := string_batch(messages)) is not None:
        yield batch


def recorded_run_info(path: str | Path) -> dict[str, Any] | None:
    """What the recorded sim ran (its first /drill/run_info message, JSON), if any; read
    through the damage-tolerant reader."""
    reader = ArchiveReader(path)
    for message in reader.messages(lambda topic: topic == topics.RUN_INFO):
        return json.loads(channel_decoder(message.channel)(message.data).data)
    return None


def recorded_preset(path: str | Path) -> str | None:
    """A preset name stored in the file's metadata records (key 'preset'), if any.

    Read from the summary's metadata index, or (no or damaged summary) from the metadata
    records that precede the first message, where the recorders write them.
    """
    try:
        with open(path, "rb") as stream:
            records = list(make_reader(stream).iter_metadata())
    except (*DAMAGE, EOFError):
        reader = ArchiveReader(path)
        next(iter(reader.messages()), None)
        records = reader.metadata
    for record in records:
        for key in PRESET_KEYS:
            if record.metadata.get(key):
                return record.metadata[key]
    return None
