"""``mcap_replay``: republish a recording with its original types and timing.

    mcap_replay FILE [--rate R] [--loop] [--start-offset S] [--topics REGEX] [--clock]

Messages are sent as the stored CDR bytes (``publisher.publish(bytes)``: no decode, no
re-encode) on publishers of the recorded types and offered QoS, spaced by their log times
divided by R. ``--clock`` publishes one /clock (rosgraph_msgs/Clock), so nodes with
use_sim_time follow the replay: the log time moved onto the recorded stamps' base (the first
recorded /clock, else the first header stamp, minus its log time), never going back within a
pass; the recorded /clock channel is then not replayed.

A missing or non-MCAP file is an error (exit 2); of a damaged or cut file, every intact chunk
is replayed, with a warning naming what was skipped (exit 1). A file with no ROS 2 channel or
a ``--start-offset`` past its end is refused (exit 2); a replay that sent nothing exits 1.
SIGINT, SIGTERM and SIGHUP stop it alike.
"""

from __future__ import annotations

import argparse
import logging
import re
import sys
import time
from dataclasses import dataclass

import rclpy
from builtin_interfaces.msg import Time
from rclpy.duration import Duration
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from rclpy.publisher import Publisher
from rclpy.qos import QoSProfile
from rclpy.serialization import deserialize_message
from rclpy.utilities import remove_ros_args
from rosgraph_msgs.msg import Clock

from drill_sim_ros.archive.errors import ArchiveError
from drill_sim_ros.archive.pacing import Pacer
from drill_sim_ros.archive.qos import replay_qos
from drill_sim_ros.archive.reader import ArchiveReader, RecordedChannel, RecordedMessage
from drill_sim_ros.archive.ros_types import message_class
from drill_sim_ros.archive.signals import interrupt_on_hangup
from drill_sim_ros.archive.writer import MESSAGE_ENCODING
from drill_sim_ros.model.telemetry import NS_PER_S
from drill_sim_ros.terminal import StatusLine

_log = logging.getLogger(__name__)

PROGRESS_PERIOD_S = 0.2
CLOCK_TOPIC = "/clock"
CLOCK_TYPE = "rosgraph_msgs/msg/Clock"
BASE_SCAN_MESSAGES = 1000    # how far into the file the stamps' base is looked for


@dataclass
class Plan:
    """What a replay will send: the channels and the log-time extent (ns)."""

    channels: list[RecordedChannel]
    first_log_ns: int
    last_log_ns: int


def plan(reader: ArchiveReader, topics: re.Pattern[str]) -> Plan:
    """Channels and time extent: from the summary when it has statistics and every channel
    with messages is replayed (instant, whatever the size), else from one pass over the file
    (which needs no summary; logged first, it takes a while on a large file)."""
    quick = _plan_from_summary(reader, topics)
    if quick is not None:
        return quick
    _log.info("reading %s to plan the replay (%.0f MB; no usable summary)", reader.path,
              reader.size / 1e6)
    first, last = None, 0
    for message in reader.messages(topics.fullmatch):
        first = message.log_time_ns if first is None else min(first, message.log_time_ns)
        last = max(last, message.log_time_ns)
    chosen = [c for c in reader.channels.values() if topics.fullmatch(c.topic)]
    return Plan(chosen, first or 0, last)


def _plan_from_summary(reader: ArchiveReader, topics: re.Pattern[str]) -> Plan | None:
    summary = reader.summary()
    stats = None if summary is None else summary.statistics
    if stats is None or stats.message_count == 0:
        return None
    channels = reader.summary_channels(summary)
    with_messages = [c for c in channels if stats.channel_message_counts.get(c.channel_id)]
    if not all(topics.fullmatch(c.topic) for c in with_messages):
        return None             # the extent of a subset of topics needs the pass
    chosen = [c for c in channels if topics.fullmatch(c.topic)]
    return Plan(chosen, stats.message_start_time, stats.message_end_time)


DELIVERY_TIMEOUT_S = 2.0    # before exiting, let reliable subscribers receive the tail


def recorded_stamp_ns(message: RecordedMessage) -> int | None:
    """The time a message carries: a Clock's clock, else its header stamp (None: neither)."""
    try:
        decoded = deserialize_message(message.data, message_class(message.channel.type_name))
    except Exception:      # an unknown type or bytes that do not decode carry no stamp
        return None
    stamped = getattr(decoded, "clock", None) or getattr(getattr(decoded, "header", None),
                                                          "stamp", None)
    return None if stamped is None else stamped.sec * NS_PER_S + stamped.nanosec


def clock_offset_ns(reader: ArchiveReader, scan: int = BASE_SCAN_MESSAGES) -> int:
    """Recorded stamp minus log time, from the first recorded /clock among the first ``scan``
    messages, else the first stamped message; 0 (the log time itself) if none is stamped."""
    first_header = None
    for count, message in enumerate(reader.messages()):
        if count >= scan:
            break
        is_clock = message.channel.type_name == CLOCK_TYPE
        if not is_clock and first_header is not None:
            continue
        stamp_ns = recorded_stamp_ns(message)
        if stamp_ns is None:
            continue
        if is_clock:
            return stamp_ns - message.log_time_ns
        first_header = stamp_ns - message.log_time_ns
    return first_header or 0


class Replayer:
    """Publishers for the recorded topics (plus /clock) on one node."""

    def __init__(self, node: Node, channels: list[RecordedChannel], clock: bool,
                 clock_offset_ns: int = 0) -> None:
        self.node = node
        self.publishers: dict[int, Publisher] = {}
        for channel in channels:
            if clock and channel.topic == CLOCK_TOPIC:
                _log.info("--clock: the recorded %s is not replayed (one clock)", CLOCK_TOPIC)
                continue
            self._add(channel)
        qos = QoSProfile(depth=100)
        self.clock = node.create_publisher(Clock, CLOCK_TOPIC, qos) if clock else None
        self.clock_offset_ns = clock_offset_ns
        self.last_clock_ns: int | None = None
        self.sent = 0

    def _add(self, channel: RecordedChannel) -> None:
        try:
            msg_class = message_class(channel.type_name)
        except ArchiveError as exc:
            _log.warning("not replaying %s: %s", channel.topic, exc)
            return
        qos = replay_qos(channel.offered_qos_yaml)
        self.publishers[channel.channel_id] = self.node.create_publisher(
            msg_class, channel.topic, qos
        )

    def wait_for_subscribers(self, timeout_s: float) -> bool:
        """Wait (bounded) until every topic has a subscriber; True if they all do."""
        deadline = time.monotonic() + timeout_s
        while time.monotonic() < deadline and rclpy.ok():
            if all(p.get_subscription_count() > 0 for p in self.publishers.values()):
                return True
            time.sleep(0.02)
        return False

    def wait_for_delivery(self, timeout_s: float) -> bool:
        """Wait (bounded) until reliable subscribers acknowledged everything sent."""
        deadline = Duration(seconds=timeout_s)
        pubs = [*self.publishers.values(), *([self.clock] if self.clock else [])]
        return all(p.wait_for_all_acked(deadline) for p in pubs)

    def publish_clock(self, log_time_ns: int) -> None:
        """/clock at ``log_time_ns`` on the stamps' base, unless that is not later than the
        last one sent (a file out of log-time order does not turn the clock back)."""
        clock_ns = log_time_ns + self.clock_offset_ns
        if self.last_clock_ns is not None and clock_ns <= self.last_clock_ns:
            return
        self.last_clock_ns = clock_ns
        sec, nanosec = divmod(clock_ns, NS_PER_S)
        self.clock.publish(Clock(clock=Time(sec=sec, nanosec=nanosec)))


class Progress:
    """The terminal progress line: replayed log time, fraction, messages sent."""

    def __init__(self, extent: Plan, rate: float) -> None:
        self._line = StatusLine()
        self._extent = extent
        self._rate = rate
        self._next_s = 0.0

    def update(self, log_time_ns: int, sent: int, force: bool = False) -> None:
        now = time.monotonic()
        if not force and now < self._next_s:
            return
        self._next_s = now + PROGRESS_PERIOD_S
        total = max(1, self._extent.last_log_ns - self._extent.first_log_ns)
        done = log_time_ns - self._extent.first_log_ns
        self._line.show(f"[mcap_replay] {done / 1e9:8.2f} / {total / 1e9:.2f} s "
                        f"({100 * done / total:5.1f} %)  {sent} msgs  x{self._rate:g}")

    def end(self) -> None:
        self._line.close()


def play_once(reader: ArchiveReader, replayer: Replayer, pacer: Pacer, options: argparse.Namespace,
              progress: Progress) -> bool:
    """Replay the file once; False if interrupted."""
    topics = re.compile(options.topics)
    start_ns = pacer.first_log_ns
    replayer.last_clock_ns = None           # a --loop pass starts the clock over
    for message in reader.messages(topics.fullmatch):
        publisher = replayer.publishers.get(message.channel.channel_id)
        if publisher is None or message.log_time_ns < start_ns:
            continue
        if not pacer.wait_until(message.log_time_ns, rclpy.ok):
            return False
        if replayer.clock is not None:
            replayer.publish_clock(message.log_time_ns)
        publisher.publish(message.data)
        replayer.sent += 1
        progress.update(message.log_time_ns, replayer.sent)
    return True


def _parse(argv: list[str]) -> argparse.Namespace:
    parser = argparse.ArgumentParser(prog="mcap_replay", description=__doc__.splitlines()[0])
    parser.add_argument("file", help="MCAP file to replay")
    parser.add_argument("--rate", type=float, default=1.0, help="speed factor (default 1)")
    parser.add_argument("--loop", action="store_true", help="start over at the end")
    parser.add_argument("--start-offset", type=float, default=0.0, metavar="S",
                        help="skip the first S seconds of log time")
    parser.add_argument("--topics", default=".*", help="regex of topics to replay (default all)")
    parser.add_argument("--clock", action="store_true",
                        help="publish /clock from the log time on the recorded stamps' base "
                             "(the recorded /clock is not replayed)")
    parser.add_argument("--delay", type=float, default=0.5, metavar="S",
                        help="wait S seconds after creating publishers (discovery)")
    parser.add_argument("--wait-for-subscribers", type=float, default=0.0, metavar="S",
                        help="wait up to S seconds for a subscriber on every topic")
    args = parser.parse_args(argv)
    if not args.rate > 0 or args.start_offset < 0 or args.delay < 0:
        parser.error("--rate must be > 0; --start-offset and --delay must be >= 0")
    try:
        re.compile(args.topics)
    except re.error as exc:
        parser.error(f"bad --topics regex: {exc}")
    return args


def _replay(reader: ArchiveReader, extent: Plan, options: argparse.Namespace) -> int:
    node = Node("mcap_replay")
    offset_ns = clock_offset_ns(reader) if options.clock else 0
    replayer = Replayer(node, extent.channels, options.clock, offset_ns)
    progress = Progress(extent, options.rate)
    try:
        if options.wait_for_subscribers > 0:
            replayer.wait_for_subscribers(options.wait_for_subscribers)
        time.sleep(options.delay)
        pacer = Pacer(extent.first_log_ns + int(options.start_offset * 1e9), options.rate)
        while play_once(reader, replayer, pacer, options, progress) and options.loop:
            pacer.restart()
        progress.update(extent.last_log_ns, replayer.sent, force=True)
        if not replayer.wait_for_delivery(DELIVERY_TIMEOUT_S):
            _log.warning("some subscribers did not acknowledge the last messages")
    finally:
        progress.end()
        _log.info("sent %d messages", replayer.sent)
        node.destroy_node()
    return replayer.sent


def main(args: list[str] | None = None) -> int:
    logging.basicConfig(level=logging.INFO, format="[mcap_replay] %(levelname)s %(message)s")
    argv = sys.argv if args is None else args
    options = _parse(remove_ros_args(argv)[1:])
    try:
        reader = ArchiveReader(options.file)
    except ArchiveError as exc:
        _log.error("%s", exc)
        return 2
    try:
        extent = plan(reader, re.compile(options.topics))
    except KeyboardInterrupt:
        _log.info("interrupted while planning; nothing was sent")
        return 130
    refusal = _nothing_to_send(reader, extent, options)
    if refusal is not None:
        _log.error("%s", refusal)
        return 2
    rclpy.init(args=argv)
    interrupt_on_hangup()
    sent = None
    try:
        sent = _replay(reader, extent, options)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        rclpy.try_shutdown()
    if sent == 0:
        _log.error("nothing was sent")
        return 1
    return 1 if reader.lost_data else 0


def _nothing_to_send(reader: ArchiveReader, extent: Plan,
                     options: argparse.Namespace) -> str | None:
    """Why the replay would send nothing (None if it will send something)."""
    foreign = sorted(t for t, e in reader.message_encodings.items() if e != MESSAGE_ENCODING)
    if not extent.channels:
        what = f"; not ROS 2 (cdr): {', '.join(foreign)}" if foreign else ""
        return f"{options.file}: no readable messages on topics matching {options.topics!r}{what}"
    if all(not c.type_name or c.topic in foreign for c in extent.channels):
        return (f"{options.file} is not a ROS 2 recording: {', '.join(foreign)} "
                f"not encoded as {MESSAGE_ENCODING!r}")
    length_s = (extent.last_log_ns - extent.first_log_ns) / 1e9
    if options.start_offset > length_s:
        return (f"--start-offset {options.start_offset:g} s is past the end of the recording "
                f"({length_s:.3f} s of log time)")
    return None


if __name__ == "__main__":
    sys.exit(main())
