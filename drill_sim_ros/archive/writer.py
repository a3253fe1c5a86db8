"""An MCAP writer for the ROS 2 profile, readable by rosbag2 (Jazzy), Foxglove and rosbags.

Chunking and the crash-loss bound
---------------------------------
Messages are buffered in a chunk in memory; a chunk reaches the file (and the OS, so it
survives SIGKILL of the process) when it is closed. A chunk is closed when either

* it holds ``max_chunk_span_s`` (default 0.5 s) of log time, or
* it holds ``chunk_size`` bytes uncompressed (default 1 MiB, a memory cap).

At the sim's default rates (10 topics x 100 Hz + 1 Hz diagnostics, about 70-100 kB/s of
records) the time limit always triggers first, at about 50 kB per chunk; so a SIGKILL loses
at most the open chunk, i.e. <= 0.5 s of data at any message rate, plus whatever was still
queued upstream (see :mod:`drill_sim_ros.archive.background`). The stated bound is 1 s.
"""

from __future__ import annotations

import logging
from collections.abc import Iterator
from contextlib import contextmanager, suppress
from dataclasses import dataclass, field
from typing import IO

import yaml
from mcap.writer import CompressionType, Writer

from drill_sim_ros.archive.errors import ArchiveError, WriterClosedError
from drill_sim_ros.archive.output import OVERWRITE_HINT, OutputError, open_output
from drill_sim_ros.archive.schemas import SCHEMA_ENCODING, MessageDefinition, message_definition

_log = logging.getLogger(__name__)

PROFILE = "ros2"
MESSAGE_ENCODING = "cdr"
ROS_DISTRO = "jazzy"
ROSBAG2_METADATA_VERSION = 9
DEFAULT_CHUNK_SIZE = 1024 * 1024
DEFAULT_MAX_CHUNK_SPAN_S = 0.5
COMPRESSIONS = {"zstd": CompressionType.ZSTD, "none": CompressionType.NONE}


@dataclass
class ChannelInfo:
    """One recorded topic: MCAP channel id, ROS type, QoS YAML and its message count."""

    channel_id: int
    topic: str
    type_name: str
    offered_qos_yaml: str
    type_hash: str
    message_count: int = 0


@dataclass
class _Span:
    """Log-time extent of the messages written so far (ns)."""

    start_ns: int | None = None
    end_ns: int = 0
    chunk_start_ns: int | None = None
    chunk_bytes: int = 0
    channel_counts: dict[int, int] = field(default_factory=dict)


class Ros2McapWriter:
    """Writes serialized CDR messages to an MCAP file in the ROS 2 profile.

    A context manager; :meth:`finish` writes the summary (statistics, indexes) and the
    ``rosbag2`` metadata record, and may be called more than once. A path is opened under
    the output policy (:func:`~drill_sim_ros.archive.output.open_output`): an existing file
    is refused unless ``overwrite``. An OS error while writing (a full disk) raises one
    :class:`~drill_sim_ros.archive.output.OutputError`; :attr:`messages_on_disk` counts only
    the messages of chunks handed to the OS.
    """

    def __init__(
        self,
        output: str | IO[bytes],
        compression: str = "zstd",
        chunk_size: int = DEFAULT_CHUNK_SIZE,
        max_chunk_span_s: float = DEFAULT_MAX_CHUNK_SPAN_S,
        rosbag2_metadata: bool = True,
        overwrite: bool = False,
        overwrite_hint: str = OVERWRITE_HINT,
    ) -> None:
        if compression not in COMPRESSIONS:
            raise ArchiveError(f"compression must be one of {sorted(COMPRESSIONS)}")
        if chunk_size <= 0 or max_chunk_span_s <= 0:
            raise ArchiveError("chunk_size and max_chunk_span_s must be positive")
        self._path = output if isinstance(output, str) else getattr(output, "name", "<stream>")
        self._owns_stream = isinstance(output, str)
        self._stream: IO[bytes] = (open_output(output, overwrite, overwrite_hint)
                                   if isinstance(output, str) else output)
        self._error: OutputError | None = None
        self._on_disk = 0
        self._compression = compression
        self._writer = Writer(
            self._stream, chunk_size=chunk_size, compression=COMPRESSIONS[compression]
        )
        with self._guard():
            self._writer.start(profile=PROFILE, library="drill_sim_ros")
        self._max_span_ns = int(max_chunk_span_s * 1e9)
        self._chunk_size = chunk_size
        self._rosbag2_metadata = rosbag2_metadata
        self._schema_ids: dict[str, int] = {}
        self.channels: dict[str, ChannelInfo] = {}
        self._span = _Span()
        self._finished = False
        self._final_size = 0

    # ---- set-up -------------------------------------------------------------------------
    def _schema_id(self, definition: MessageDefinition) -> int:
        schema_id = self._schema_ids.get(definition.type_name)
        if schema_id is None:
            data = definition.text.encode("utf-8")
            schema_id = self._writer.register_schema(definition.type_name, SCHEMA_ENCODING, data)
            self._schema_ids[definition.type_name] = schema_id
        return schema_id

    def add_channel(
        self,
        topic: str,
        type_name: str,
        offered_qos_yaml: str = "",
        definition: MessageDefinition | None = None,
    ) -> ChannelInfo:
        """Register ``topic`` once (later calls return the same channel).

        definition: the schema to store; by default the installed package's definition.
        """
        self._check_open()
        if topic in self.channels:
            return self.channels[topic]
        definition = definition or message_definition(type_name)
        metadata = {"offered_qos_profiles": offered_qos_yaml}
        if definition.type_hash:
            metadata["topic_type_hash"] = definition.type_hash
        with self._guard():
            channel_id = self._writer.register_channel(
                topic, MESSAGE_ENCODING, self._schema_id(definition), metadata
            )
        info = ChannelInfo(
            channel_id, topic, definition.type_name, offered_qos_yaml, definition.type_hash
        )
        self.channels[topic] = info
        return info

    # ---- data ---------------------------------------------------------------------------
    def write(
        self,
        channel: ChannelInfo,
        data: bytes,
        log_time_ns: int,
        publish_time_ns: int | None = None,
        sequence: int = 0,
    ) -> None:
        """Append one serialized message; closes the chunk when it spans the time limit."""
        self._check_open()
        publish_time = log_time_ns if publish_time_ns is None else publish_time_ns
        before = self._stream.tell()
        channel.message_count += 1                  # counted as lost if this raises
        with self._guard():
            self._writer.add_message(channel.channel_id, log_time_ns, data, publish_time,
                                     sequence)
            if self._stream.tell() != before:       # mcap closed the chunk by size
                self._hand_over()
            self._track(log_time_ns, len(data))

    @contextmanager
    def _guard(self) -> Iterator[None]:
        """OS errors (ENOSPC, EIO) become one OutputError, kept in :attr:`error`."""
        try:
            yield
        except OSError as exc:
            self._error = OutputError(f"cannot write {self._path}: {exc.strerror or exc}")
            raise self._error from None

    def _hand_over(self) -> None:
        self._stream.flush()
        self._on_disk = self.message_count

    def _track(self, log_time_ns: int, size: int) -> None:
        span = self._span
        span.start_ns = log_time_ns if span.start_ns is None else min(span.start_ns, log_time_ns)
        span.end_ns = max(span.end_ns, log_time_ns)
        if span.chunk_start_ns is None:
            span.chunk_start_ns = log_time_ns
        span.chunk_bytes += size + 31  # message record overhead: opcode, length, header
        if span.chunk_bytes > self._chunk_size:
            span.chunk_start_ns, span.chunk_bytes = None, 0  # mcap closed it by size
        elif log_time_ns - span.chunk_start_ns >= self._max_span_ns:
            self.flush()

    def flush(self) -> None:
        """Close the open chunk (if any) and hand everything to the OS."""
        if self._finished:
            return
        with self._guard():
            self._writer.flush()
            self._on_disk = self.message_count
        self._span.chunk_start_ns, self._span.chunk_bytes = None, 0

    @property
    def has_open_chunk(self) -> bool:
        return self._span.chunk_start_ns is not None

    @property
    def messages_on_disk(self) -> int:
        """Messages in chunks handed to the OS (the open chunk excluded)."""
        return self._on_disk

    @property
    def error(self) -> OutputError | None:
        """The write error that stopped this file, if any."""
        return self._error

    @property
    def message_count(self) -> int:
        return sum(c.message_count for c in self.channels.values())

    @property
    def bytes_written(self) -> int:
        """Bytes in the file so far (the open chunk excluded)."""
        return self._final_size if self._finished else self._stream.tell()

    @property
    def log_time_range_ns(self) -> tuple[int, int]:
        """(first, last) log time written, ns; (0, 0) before the first message."""
        span = self._span
        return (0, 0) if span.start_ns is None else (span.start_ns, span.end_ns)

    @property
    def path(self) -> str:
        return self._path

    # ---- end ----------------------------------------------------------------------------
    def _check_open(self) -> None:
        if self._finished:
            raise WriterClosedError(f"{self._path} is already finished")
        if self._error is not None:
            raise self._error

    def add_metadata(self, name: str, data: dict[str, str]) -> None:
        self._check_open()
        with self._guard():
            self._writer.add_metadata(name, data)

    def finish(self) -> None:
        """Write the summary and close the file. Safe to call again."""
        if self._finished:
            return
        self._finished = True
        try:
            if self._error is None:
                with self._guard():
                    self._end()
        finally:
            self._release()
        _log.debug("finished %s: %d messages", self._path, self.message_count)

    def _end(self) -> None:
        if self._rosbag2_metadata:
            self._writer.add_metadata("rosbag2", self._rosbag2_record())
        self._writer.finish()
        self._stream.flush()
        self._final_size = self._stream.tell()
        self._on_disk = self.message_count

    def _release(self) -> None:
        """Close the file even after a write error (what could not be written is lost)."""
        if not self._final_size:
            self._final_size = self._stream.tell()
        if not self._owns_stream:
            return
        with suppress(OSError):                 # the buffer could not be written either
            self._stream.close()

    def _rosbag2_record(self) -> dict[str, str]:
        text = yaml.safe_dump(rosbag2_bag_metadata(self), default_flow_style=False,
                              sort_keys=False)
        return {"serialized_metadata": text, "ROS_DISTRO": ROS_DISTRO}

    def __enter__(self) -> Ros2McapWriter:
        return self

    def __exit__(self, *exc_info: object) -> None:
        self.finish()


def _qos_entries(text: str) -> list:
    return (yaml.safe_load(text) or []) if text else []


def rosbag2_bag_metadata(writer: Ros2McapWriter) -> dict:
    """rosbag2's BagMetadata (version 9) for the ``serialized_metadata`` entry."""
    start, end = writer.log_time_range_ns
    duration = end - start
    count = writer.message_count
    name = writer.path.rsplit("/", 1)[-1]
    return {
        "version": ROSBAG2_METADATA_VERSION,
        "storage_identifier": "mcap",
        "duration": {"nanoseconds": duration},
        "starting_time": {"nanoseconds_since_epoch": start},
        "message_count": count,
        "topics_with_message_count": [
            {
                "topic_metadata": {
                    "name": c.topic,
                    "type": c.type_name,
                    "serialization_format": MESSAGE_ENCODING,
                    "offered_qos_profiles": _qos_entries(c.offered_qos_yaml),
                    "type_description_hash": c.type_hash,
                },
                "message_count": c.message_count,
            }
            for c in writer.channels.values()
        ],
        "compression_format": "",
        "compression_mode": "",
        "relative_file_paths": [name],
        "files": [
            {
                "path": name,
                "starting_time": {"nanoseconds_since_epoch": start},
                "duration": {"nanoseconds": duration},
                "message_count": count,
            }
        ],
        "custom_data": {},
        "ros_distro": ROS_DISTRO,
    }
