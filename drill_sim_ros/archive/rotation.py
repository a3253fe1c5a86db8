"""A writer that splits a recording into numbered files by size or by duration.

``FILE.mcap`` unsplit; with a limit, ``FILE_0000.mcap``, ``FILE_0001.mcap``, ... Each file is a
complete MCAP of its own (every channel re-registered, its own summary), so any one of them
can be replayed or opened alone.
"""

from __future__ import annotations

import logging
from pathlib import Path

from drill_sim_ros.archive.errors import ArchiveError
from drill_sim_ros.archive.output import OVERWRITE_HINT, check_output
from drill_sim_ros.archive.writer import ChannelInfo, Ros2McapWriter

_log = logging.getLogger(__name__)


class RotatingWriter:
    """Sink for :class:`~drill_sim_ros.archive.background.BackgroundWriter`; channels by topic."""

    def __init__(
        self,
        path: str | Path,
        compression: str = "zstd",
        split_size_bytes: int | None = None,
        split_duration_s: float | None = None,
        overwrite: bool = False,
        metadata: dict[str, dict[str, str]] | None = None,
        overwrite_hint: str = OVERWRITE_HINT,
    ) -> None:
        if (split_size_bytes or 0) < 0 or (split_duration_s or 0) < 0:
            raise ArchiveError("split limits must be positive")
        self._base = Path(path)
        self._compression = compression
        self._split_size = split_size_bytes or None
        self._split_ns = int(split_duration_s * 1e9) if split_duration_s else None
        self._overwrite, self._hint = overwrite, overwrite_hint
        self._metadata = metadata or {}
        self._topics: dict[str, tuple[str, str]] = {}
        self.paths: list[Path] = []
        self._finished_messages = 0
        self._finished_on_disk = 0
        self._finished_bytes = 0
        self._refuse_existing_parts()
        self._writer: Ros2McapWriter | None = self._open_next()
        self._channels: dict[str, ChannelInfo] = {}
        self._file_start_ns: int | None = None

    def _refuse_existing_parts(self) -> None:
        """Split files are numbered from 0000: any existing part is refused up front."""
        if not self.splitting or self._overwrite:
            return
        parts = sorted(self._base.parent.glob(f"{self._base.stem}_[0-9][0-9][0-9][0-9]"
                                              f"{self._base.suffix}"))
        if parts:
            check_output(parts[0], self._overwrite, self._hint)

    @property
    def splitting(self) -> bool:
        return self._split_size is not None or self._split_ns is not None

    def _next_path(self) -> Path:
        if not self.splitting:
            return self._base
        return self._base.with_name(f"{self._base.stem}_{len(self.paths):04d}{self._base.suffix}")

    def _open_next(self) -> Ros2McapWriter:
        path = self._next_path()
        writer = Ros2McapWriter(str(path), compression=self._compression,
                                overwrite=self._overwrite, overwrite_hint=self._hint)
        self.paths.append(path)
        for name, data in self._metadata.items():
            writer.add_metadata(name, data)
        return writer

    def add_channel(self, topic: str, type_name: str, offered_qos_yaml: str = "") -> str:
        self._topics[topic] = (type_name, offered_qos_yaml)
        self._channels[topic] = self._writer.add_channel(topic, type_name, offered_qos_yaml)
        return topic

    def write(self, topic: str, data: bytes, log_time_ns: int) -> None:
        if self._due(log_time_ns):
            self._rotate()
        if self._file_start_ns is None:
            self._file_start_ns = log_time_ns
        self._writer.write(self._channels[topic], data, log_time_ns)

    def _due(self, log_time_ns: int) -> bool:
        if self._file_start_ns is None:
            return False
        if self._split_ns is not None and log_time_ns - self._file_start_ns >= self._split_ns:
            return True
        return self._split_size is not None and self._writer.bytes_written >= self._split_size

    def _rotate(self) -> None:
        self._close_current()
        self._writer = self._open_next()
        self._file_start_ns = None
        self._channels = {
            topic: self._writer.add_channel(topic, type_name, qos)
            for topic, (type_name, qos) in self._topics.items()
        }
        _log.info("split: now writing %s", self.paths[-1])

    def _close_current(self) -> None:
        writer, self._writer = self._writer, None
        try:
            writer.finish()
        finally:
            self._finished_messages += writer.message_count
            self._finished_on_disk += writer.messages_on_disk
            self._finished_bytes += writer.bytes_written

    def flush(self) -> None:
        if self._writer is not None and self._writer.has_open_chunk:
            self._writer.flush()

    def finish(self) -> None:
        if self._writer is not None:
            self._close_current()

    # Read from other threads (status, /diagnostics) while the writer thread may rotate:
    # take the current writer once.
    @property
    def message_count(self) -> int:
        writer = self._writer
        return self._finished_messages + (writer.message_count if writer is not None else 0)

    @property
    def messages_on_disk(self) -> int:
        writer = self._writer
        return self._finished_on_disk + (writer.messages_on_disk if writer is not None else 0)

    @property
    def bytes_written(self) -> int:
        writer = self._writer
        return self._finished_bytes + (writer.bytes_written if writer is not None else 0)
