"""Generator-based reading of MCAP archives, including truncated or summary-less files.

Messages are read in file order from the data section, chunk by chunk, with chunk CRCs checked.
A file cut short (a recorder killed with SIGKILL, a partial copy) yields every message up to
its last complete chunk; then :attr:`ArchiveReader.problem` says what was wrong and a warning
is logged. A missing file or one that is not MCAP raises at construction.
"""

from __future__ import annotations

import logging
import struct
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import IO

import zstandard
from mcap.exceptions import EndOfFile, McapError
from mcap.reader import make_reader
from mcap.records import Channel, DataEnd, Footer, Message, Metadata, Schema
from mcap.stream_reader import MAGIC_SIZE, StreamReader
from mcap.summary import Summary

from drill_sim_ros.archive.errors import ArchiveNotFoundError, NotAnArchiveError

_log = logging.getLogger(__name__)

MCAP_MAGIC = b"\x89MCAP0\r\n"
# No record we write comes near this; a larger length field means corruption.
RECORD_SIZE_LIMIT = 256 * 1024 * 1024
# What a damaged data section raises inside mcap's parser (CRC errors are ValueErrors).
_DAMAGE = (McapError, ValueError, struct.error, zstandard.ZstdError, RuntimeError, MemoryError)


@dataclass(frozen=True)
class RecordedChannel:
    """A channel as stored: topic, ROS type, QoS YAML, type hash and schema text."""

    channel_id: int
    topic: str
    type_name: str
    offered_qos_yaml: str
    type_hash: str
    schema_text: str


@dataclass(frozen=True)
class RecordedMessage:
    """One stored message: serialized CDR bytes and its times (ns)."""

    channel: RecordedChannel
    data: bytes
    log_time_ns: int
    publish_time_ns: int
    sequence: int

    @property
    def topic(self) -> str:
        return self.channel.topic


class _ExactStream:
    """A file whose short reads raise EndOfFile, so a cut record is never half-parsed."""

    def __init__(self, stream: IO[bytes]) -> None:
        self._stream = stream
        self.offset = 0

    def read(self, size: int) -> bytes:
        data = self._stream.read(size)
        if len(data) < size:
            raise EndOfFile()
        self.offset += size
        return data


def _check_file(path: Path) -> None:
    if not path.exists():
        raise ArchiveNotFoundError(f"{path}: no such file")
    if path.is_dir():
        raise NotAnArchiveError(f"{path} is a directory, not an MCAP file")
    with path.open("rb") as stream:
        magic = stream.read(MAGIC_SIZE)
    if magic != MCAP_MAGIC:
        what = "empty" if not magic else "not an MCAP file (bad magic bytes)"
        raise NotAnArchiveError(f"{path} is {what}")


class ArchiveReader:
    """Reads the messages, channels and metadata of one MCAP file (ROS 2 profile)."""

    def __init__(self, path: str | Path) -> None:
        self.path = Path(path)
        _check_file(self.path)
        self.size = self.path.stat().st_size
        self.channels: dict[int, RecordedChannel] = {}
        self.metadata: list[Metadata] = []
        self.problem: str | None = None
        self._schemas: dict[int, Schema] = {}

    def summary(self) -> Summary | None:
        """The summary section (statistics, channels, chunk indexes), or None if absent."""
        try:
            with self.path.open("rb") as stream:
                return make_reader(stream).get_summary()
        except (*_DAMAGE, EOFError, OSError):
            return None

    def messages(
        self, topic_filter: Callable[[str], bool] | None = None
    ) -> Iterator[RecordedMessage]:
        """Yield the stored messages in file order, optionally only topics passing the filter."""
        for record in self._data_records():
            if isinstance(record, Message):
                channel = self.channels.get(record.channel_id)
                if channel is None or (topic_filter and not topic_filter(channel.topic)):
                    continue
                yield RecordedMessage(
                    channel, record.data, record.log_time, record.publish_time, record.sequence
                )

    def _data_records(self) -> Iterator[object]:
        """Records of the data section; registers schemas/channels/metadata on the way."""
        with self.path.open("rb") as raw:
            stream = _ExactStream(raw)
            reader = StreamReader(
                stream, validate_crcs=True, record_size_limit=RECORD_SIZE_LIMIT
            )
            yield from self._guarded(reader, stream)

    def _guarded(self, reader: StreamReader, stream: _ExactStream) -> Iterator[object]:
        count, in_summary = 0, False
        try:
            for record in reader.records:
                if isinstance(record, Footer):
                    return
                in_summary = in_summary or isinstance(record, DataEnd)
                if not in_summary:
                    self._register(record)
                    count += isinstance(record, Message)
                    yield record
            self._report(f"no footer after {count} messages")
        except EndOfFile:
            where = "in its summary section" if in_summary else "without a summary"
            self._report(
                f"truncated: ends at byte {self.size} {where} after {count} messages "
                f"(recording interrupted? `mcap_reindex {self.path}` restores the summary)"
            )
        except _DAMAGE as exc:
            self._report(f"corrupt near byte {stream.offset} after {count} messages: {exc}")

    def _report(self, problem: str) -> None:
        self.problem = f"{self.path}: {problem}"
        _log.warning("%s; the readable part was read", self.problem)

    def _register(self, record: object) -> None:
        if isinstance(record, Schema):
            self._schemas[record.id] = record
        elif isinstance(record, Channel):
            self.channels[record.id] = self._channel(record)
        elif isinstance(record, Metadata):
            self.metadata.append(record)

    def _channel(self, record: Channel) -> RecordedChannel:
        schema = self._schemas.get(record.schema_id)
        return RecordedChannel(
            channel_id=record.id,
            topic=record.topic,
            type_name=schema.name if schema else "",
            offered_qos_yaml=record.metadata.get("offered_qos_profiles", ""),
            type_hash=record.metadata.get("topic_type_hash", ""),
            schema_text=schema.data.decode("utf-8", "replace") if schema else "",
        )
