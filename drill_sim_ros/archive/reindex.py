"""``mcap_reindex FILE [-o OUT]``: rebuild a finished MCAP (summary, statistics, indexes).

For a file without a summary (a recorder killed by SIGKILL, a partial copy), every complete
message is copied, with its times, sequence number, channel metadata and stored schema, into a
new file that ends with a full summary. Without ``-o`` the file is replaced in place (through a
temporary file and an atomic rename); if the reader met corrupt data rather than a clean cut,
the original is kept as ``FILE.orig``.
"""

from __future__ import annotations

import argparse
import logging
import os
import shutil
import sys
from dataclasses import dataclass
from pathlib import Path

from drill_sim_ros.archive.errors import ArchiveError
from drill_sim_ros.archive.reader import ArchiveReader, RecordedChannel
from drill_sim_ros.archive.schemas import MessageDefinition
from drill_sim_ros.archive.writer import ChannelInfo, Ros2McapWriter

_log = logging.getLogger(__name__)


@dataclass(frozen=True)
class ReindexResult:
    """What a reindex copied: message count, channels, and the reader's complaint if any."""

    messages: int
    channels: int
    problem: str | None


def _add(writer: Ros2McapWriter, channel: RecordedChannel) -> ChannelInfo:
    definition = MessageDefinition(channel.type_name, channel.schema_text, channel.type_hash)
    return writer.add_channel(channel.topic, channel.type_name, channel.offered_qos_yaml,
                              definition)


def reindex(source: str | Path, target: str | Path, compression: str = "zstd") -> ReindexResult:
    """Copy every readable message of ``source`` into a finished file at ``target``."""
    reader = ArchiveReader(source)
    with Ros2McapWriter(str(target), compression=compression) as writer:
        for message in reader.messages():
            channel = _add(writer, message.channel)
            writer.write(channel, message.data, message.log_time_ns, message.publish_time_ns,
                         message.sequence)
        for channel in reader.channels.values():
            _add(writer, channel)
        for record in reader.metadata:
            if record.name != "rosbag2":
                writer.add_metadata(record.name, dict(record.metadata))
        count = writer.message_count
    return ReindexResult(count, len(reader.channels), reader.problem)


def reindex_file(source: Path, output: Path | None, compression: str) -> ReindexResult:
    """Reindex to ``output``, or in place (keeping ``source.orig`` if data was corrupt)."""
    if output is not None:
        return reindex(source, output, compression)
    temporary = source.with_name(source.name + ".reindex.tmp")
    try:
        result = reindex(source, temporary, compression)
        if result.problem and "corrupt" in result.problem:
            shutil.copy2(source, source.with_name(source.name + ".orig"))
        os.replace(temporary, source)
    finally:
        temporary.unlink(missing_ok=True)
    return result


def _parse(argv: list[str] | None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(prog="mcap_reindex", description=__doc__.splitlines()[0])
    parser.add_argument("file", type=Path, help="MCAP file, possibly without a summary")
    parser.add_argument("-o", "--output", type=Path, help="output file (default: in place)")
    parser.add_argument("--compression", choices=("zstd", "none"), default="zstd")
    return parser.parse_args(argv)


def main(argv: list[str] | None = None) -> int:
    logging.basicConfig(level=logging.INFO, format="[mcap_reindex] %(levelname)s %(message)s")
    args = _parse(argv)
    try:
        result = reindex_file(args.file, args.output, args.compression)
    except ArchiveError as exc:
        _log.error("%s", exc)
        return 2
    _log.info("%d messages on %d channels -> %s", result.messages, result.channels,
              args.output or args.file)
    return 0


if __name__ == "__main__":
    sys.exit(main())
