"""Generator-based reading of MCAP archives, including damaged or summary-less files.

Messages are read in file order from the data section, chunk by chunk, with chunk CRCs checked.
A damaged chunk (flipped bytes) is skipped and reading goes on with the next intact one
(:mod:`drill_sim_ros.archive.recovery`); a file cut short (a recorder killed with SIGKILL, a
partial copy) yields every message up to its last complete chunk. Either way
:attr:`ArchiveReader.problem` then says in one line what was skipped, and a warning is logged.
A missing file or one that is not MCAP raises at construction.
"""

from __future__ import annotations

import logging
import mmap
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path

from mcap.reader import make_reader
from mcap.records import Channel, DataEnd, Header, Message, Metadata, Schema
from mcap.summary import Summary

from drill_sim_ros.archive.errors import ArchiveNotFoundError, NotAnArchiveError
from drill_sim_ros.archive.recovery import DAMAGE, MAGIC_SIZE, Damage, RecordScanner

_log = logging.getLogger(__name__)

MCAP_MAGIC = b"\x89MCAP0\r\n"
ROS2_PROFILE = "ros2"


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
    """Reads the messages, channels and metadata of one MCAP file (ROS 2 profile).

    Damaged stretches (a cut, flipped bytes in a chunk) are skipped; after a pass over
    :meth:`messages`, :attr:`damage` lists them, :attr:`problem` says in one line what was
    skipped (chunks, messages, log times) and :attr:`lost_data` whether any message was.
    """

    def __init__(self, path: str | Path) -> None:
        self.path = Path(path)
        _check_file(self.path)
        self.size = self.path.stat().st_size
        self.channels: dict[int, RecordedChannel] = {}
        self.metadata: list[Metadata] = []
        self.profile: str | None = None
        self.message_encodings: dict[str, str] = {}     # topic -> channel message encoding
        self.problem: str | None = None
        self.damage: list[Damage] = []
        self.read_count = 0
        self._schemas: dict[int, Schema] = {}
        self._summary_channels: dict[int, Channel] | None = None

    def summary(self) -> Summary | None:
        """The summary section (statistics, channels, chunk indexes), or None if absent."""
        try:
            with self.path.open("rb") as stream:
                return make_reader(stream).get_summary()
        except (*DAMAGE, EOFError, OSError):
            return None

    def summary_channels(self, summary: Summary) -> list[RecordedChannel]:
        """The channels listed in ``summary`` (registered as :meth:`messages` would)."""
        for schema in summary.schemas.values():
            self._register(schema)
        for channel in summary.channels.values():
            self._register(channel)
        return [self.channels[i] for i in summary.channels]

    @property
    def lost_data(self) -> bool:
        """True if a damaged stretch of the data section was skipped (messages lost)."""
        return any(not d.in_summary for d in self.damage)

    def messages(
        self, topic_filter: Callable[[str], bool] | None = None
    ) -> Iterator[RecordedMessage]:
        """Yield the stored messages in file order, optionally only topics passing the filter."""
        for record in self._data_records():
            if isinstance(record, Message):
                channel = self._channel_of(record.channel_id)
                if channel is None or (topic_filter and not topic_filter(channel.topic)):
                    continue
                yield RecordedMessage(
                    channel, record.data, record.log_time, record.publish_time, record.sequence
                )

    def _data_records(self) -> Iterator[object]:
        """Records of the data section; registers schemas/channels/metadata on the way."""
        self.read_count, self.damage, self.problem = 0, [], None
        if self.size <= MAGIC_SIZE:
            self._report_end(False, False)
            return
        with self.path.open("rb") as raw, mmap.mmap(raw.fileno(), 0,
                                                     access=mmap.ACCESS_READ) as data:
            scanner = RecordScanner(data)
            for record in scanner.records():
                if isinstance(record, DataEnd) or scanner.scan.in_summary:
                    continue
                self._register(record)
                if isinstance(record, Message):
                    self.read_count += 1
                yield record
            self.damage = scanner.scan.damage
            self._report_end(scanner.scan.footer, scanner.scan.in_summary)

    def _report_end(self, footer: bool, in_summary: bool) -> None:
        parts = [f"skipped {d.describe()}" for d in self.damage if not d.at_end]
        cut = next((d for d in self.damage if d.at_end), None)
        if cut is not None or not footer:
            where = "in its summary section" if in_summary else "without a summary"
            lost = "" if cut is None or cut.in_summary else f", losing {cut.describe()}"
            parts.append(f"truncated: ends at byte {self.size} {where} after "
                         f"{self.read_count} messages{lost}")
        if not parts:
            return
        total = self._lost_by_statistics()
        if total:
            parts.append(f"{total} of the file's messages lost in all")
        hint = "" if in_summary and not self.lost_data else \
            f" (`mcap_reindex {self.path}` writes a complete copy of the rest)"
        self.problem = f"{self.path}: " + "; ".join(parts) + hint
        _log.warning("%s", self.problem)

    def _lost_by_statistics(self) -> int | None:
        if not self.lost_data:
            return None
        summary = self.summary()
        if summary is None or summary.statistics is None:
            return None
        return summary.statistics.message_count - self.read_count

    def _channel_of(self, channel_id: int) -> RecordedChannel | None:
        """A channel met in the data section, else the summary's copy (its chunk was lost)."""
        channel = self.channels.get(channel_id)
        if channel is None and self.damage is not None:
            if self._summary_channels is None:
                summary = self.summary()
                self._summary_channels = {} if summary is None else dict(summary.channels)
                for schema in ([] if summary is None else summary.schemas.values()):
                    self._schemas.setdefault(schema.id, schema)
            record = self._summary_channels.get(channel_id)
            if record is not None:
                self._register(record)
                channel = self.channels[channel_id]
        return channel

    def _register(self, record: object) -> None:
        if isinstance(record, Header):
            self.profile = record.profile
        elif isinstance(record, Schema):
            self._schemas[record.id] = record
        elif isinstance(record, Channel):
            self.channels[record.id] = self._channel(record)
            self.message_encodings[record.topic] = record.message_encoding
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
