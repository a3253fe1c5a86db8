"""``mcap_reindex FILE [-o OUT | --in-place]``: a complete copy of a damaged or cut recording.

Every intact message is copied, with its times, sequence number, channel metadata and stored
schema, into a new file that ends with a full summary (statistics, indexes). Damaged chunks
are skipped and listed; the exit code is 1 when any message was lost, 0 when everything that
reached the file was kept. The input is never changed unless ``--in-place`` asks for it, and
then the original is kept as ``FILE.orig``. By default the copy goes beside the input as
``FILE.reindexed.mcap``. No existing output is replaced without ``--overwrite``, and the output
appears only when complete. Only ROS 2 recordings (profile ``ros2``, ``cdr`` channels) are
accepted; any other MCAP is refused untouched.
"""

from __future__ import annotations

import argparse
import logging
import shutil
import sys
from dataclasses import dataclass
from pathlib import Path

from drill_sim_ros.archive.errors import ArchiveError, NotAnArchiveError
from drill_sim_ros.archive.output import OutputError, check_output, commit, temporary_beside
from drill_sim_ros.archive.reader import ROS2_PROFILE, ArchiveReader, RecordedChannel
from drill_sim_ros.archive.schemas import MessageDefinition
from drill_sim_ros.archive.signals import stop_on_signals
from drill_sim_ros.archive.writer import MESSAGE_ENCODING, ChannelInfo, Ros2McapWriter

_log = logging.getLogger(__name__)
BACKUP_SUFFIX = ".orig"


class NotRos2Error(NotAnArchiveError):
    """The MCAP file is not a ROS 2 recording (another profile or message encoding)."""


@dataclass(frozen=True)
class ReindexResult:
    """What a reindex copied: message count, channels, and the reader's complaint if any."""

    messages: int
    channels: int
    problem: str | None
    lost_data: bool = False


def _add(writer: Ros2McapWriter, channel: RecordedChannel) -> ChannelInfo:
    definition = MessageDefinition(channel.type_name, channel.schema_text, channel.type_hash)
    return writer.add_channel(channel.topic, channel.type_name, channel.offered_qos_yaml,
                              definition)


def _require_ros2(reader: ArchiveReader) -> None:
    if reader.profile is not None and reader.profile != ROS2_PROFILE:
        raise NotRos2Error(f"{reader.path} is not a ROS 2 recording (MCAP profile "
                           f"{reader.profile!r}, not {ROS2_PROFILE!r}); left unchanged")
    for topic, encoding in reader.message_encodings.items():
        if encoding != MESSAGE_ENCODING:
            raise NotRos2Error(f"{reader.path} is not a ROS 2 recording ({topic} is encoded "
                               f"{encoding!r}, not {MESSAGE_ENCODING!r}); left unchanged")


def reindex(source: str | Path, target: str | Path, compression: str = "zstd",
            overwrite: bool = False) -> ReindexResult:
    """Copy every intact message of ``source`` into a finished file at ``target``."""
    reader = ArchiveReader(source)
    with Ros2McapWriter(str(target), compression=compression, overwrite=overwrite) as writer:
        for message in reader.messages():
            _require_ros2(reader)
            channel = _add(writer, message.channel)
            writer.write(channel, message.data, message.log_time_ns, message.publish_time_ns,
                         message.sequence)
        _require_ros2(reader)
        for channel in reader.channels.values():
            _add(writer, channel)
        for record in reader.metadata:
            if record.name != "rosbag2":
                writer.add_metadata(record.name, dict(record.metadata))
        count = writer.message_count
    return ReindexResult(count, len(reader.channels), reader.problem, reader.lost_data)


def reindex_file(source: Path, output: Path | None, compression: str, in_place: bool = False,
                 overwrite: bool = False) -> tuple[ReindexResult, Path]:
    """Reindex ``source`` to ``output`` (default beside it) or in place; nothing partial is
    left behind. Returns the result and the path written."""
    target = source if in_place else (output or default_output(source))
    if not in_place and target.resolve() == source.resolve():
        raise OutputError(f"{target} is the input; use --in-place to replace it")
    if in_place:
        check_output(source.with_name(source.name + BACKUP_SUFFIX), overwrite)
    else:
        check_output(target, overwrite)
    temporary = temporary_beside(target, overwrite=True)
    try:
        result = reindex(source, temporary, compression, overwrite=True)
        if in_place:
            shutil.copy2(source, source.with_name(source.name + BACKUP_SUFFIX))
        commit(temporary, target, overwrite=in_place or overwrite)
    finally:
        temporary.unlink(missing_ok=True)
    return result, target


def default_output(source: Path) -> Path:
    """``run.mcap`` -> ``run.reindexed.mcap`` beside it."""
    return source.with_name(f"{source.stem}.reindexed{source.suffix or '.mcap'}")


def _parse(argv: list[str] | None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(prog="mcap_reindex", description=__doc__.splitlines()[0])
    parser.add_argument("file", type=Path, help="MCAP file, possibly damaged or cut short")
    where = parser.add_mutually_exclusive_group()
    where.add_argument("-o", "--output", type=Path,
                       help="output file (default: FILE.reindexed.mcap beside the input)")
    where.add_argument("--in-place", action="store_true",
                       help="replace FILE, keeping the original as FILE.orig")
    parser.add_argument("--overwrite", action="store_true",
                        help="replace an existing output (or FILE.orig)")
    parser.add_argument("--compression", choices=("zstd", "none"), default="zstd")
    return parser.parse_args(argv)


def main(argv: list[str] | None = None) -> int:
    logging.basicConfig(level=logging.INFO, format="[mcap_reindex] %(levelname)s %(message)s")
    args = _parse(argv)
    try:
        with stop_on_signals():
            result, target = reindex_file(args.file, args.output, args.compression,
                                          args.in_place, args.overwrite)
    except ArchiveError as exc:
        _log.error("%s", exc)
        return 2
    except KeyboardInterrupt as exc:
        _log.error("interrupted (%s); nothing written, %s unchanged", exc or "SIGINT",
                   args.file)
        return 130
    backup = f" (original kept as {args.file}{BACKUP_SUFFIX})" if args.in_place else ""
    _log.info("%d messages on %d channels -> %s%s", result.messages, result.channels, target,
              backup)
    if result.lost_data:
        _log.error("messages were lost: see the warning above")
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
