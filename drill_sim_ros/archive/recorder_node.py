"""``mcap_recorder``: record the sim's topics over DDS into MCAP, bytes unchanged.

    mcap_recorder -o FILE.mcap [--topics REGEX] [--compression zstd|none]
                  [--split-size MB | --split-duration S]

Topics matching REGEX (default: every drill/... topic of the recorder's namespace, so
``-r __ns:=/rig1`` records /rig1/drill/..., plus /diagnostics and /clock) are found by
discovery as they appear. Each is subscribed with raw=True, so the serialized CDR bytes go to
the file unchanged, with a QoS compatible with what its publishers offer; the offered profiles
are stored in the channel metadata. SIGINT, SIGTERM or SIGHUP finishes the file with its
summary. An existing output is refused unless ``--overwrite``. If the file cannot be written
(a full disk), the recorder says so once, stops, and exits 1 with what it kept.
"""

from __future__ import annotations

import argparse
import logging
import re
import sys
from collections.abc import Callable
from typing import Any

import rclpy
from rclpy.clock import Clock, ClockType
from rclpy.executors import ExternalShutdownException
from rclpy.impl.implementation_singleton import rclpy_implementation
from rclpy.node import Node
from rclpy.utilities import remove_ros_args

from drill_sim_ros.archive.background import BackgroundWriter
from drill_sim_ros.archive.errors import ArchiveError
from drill_sim_ros.archive.qos import qos_profiles_yaml, subscription_qos
from drill_sim_ros.archive.ros_types import message_class
from drill_sim_ros.archive.rotation import RotatingWriter
from drill_sim_ros.archive.signals import interrupt_on_hangup
from drill_sim_ros.terminal import StatusLine

_log = logging.getLogger(__name__)

RCLError = rclpy_implementation.RCLError
DEFAULT_TOPICS = r"/drill/.*|/diagnostics|/clock"    # of the root namespace
DISCOVERY_PERIOD_S = 0.5
STATUS_PERIOD_S = 0.5


def default_topics(namespace: str) -> str:
    """The sim's topics under ``namespace`` (``/rig1``: ``/rig1/drill/.*``), /diagnostics and
    /clock, as a regex."""
    prefix = re.escape(namespace.rstrip("/"))
    return rf"{prefix}/drill/.*|/diagnostics|/clock"


class McapRecorder(Node):
    """Subscribes to matching topics as they appear and queues their raw bytes to ``sink``."""

    def __init__(self, sink: BackgroundWriter, topics_regex: str | None = None,
                 **node_kwargs: Any) -> None:
        super().__init__("mcap_recorder", **node_kwargs)
        self._sink = sink
        self._pattern = re.compile(topics_regex or default_topics(self.get_namespace()))
        self._recorded: dict[str, object] = {}
        self._skipped: set[str] = set()
        # steady: discovery goes on while a sim's /clock (use_sim_time) stands still
        self.steady = Clock(clock_type=ClockType.STEADY_TIME)
        self._discovery = self.create_timer(DISCOVERY_PERIOD_S, self.discover,
                                            clock=self.steady)
        self._health = self.create_timer(DISCOVERY_PERIOD_S, self._stop_if_failed,
                                         clock=self.steady)

    def _stop_if_failed(self) -> None:
        """A recorder that cannot write stops (the writer thread has said why)."""
        if self._sink.failure is not None:
            self._health.cancel()
            rclpy.try_shutdown(context=self.context)

    @property
    def topics(self) -> list[str]:
        return sorted(self._recorded)

    def discover(self) -> None:
        """Subscribe to every matching topic that has a publisher and no subscription yet."""
        for topic, types in self.get_topic_names_and_types():
            if topic in self._recorded or topic in self._skipped:
                continue
            if self._pattern.fullmatch(topic) and types:
                self._subscribe(topic, types[0])

    def _subscribe(self, topic: str, type_name: str) -> None:
        offered = [info.qos_profile for info in self.get_publishers_info_by_topic(topic)]
        if not offered:
            return  # a subscriber-only topic; retry once a publisher shows up
        try:
            msg_class = message_class(type_name)
        except ArchiveError as exc:
            self._skipped.add(topic)
            self.get_logger().warning(f"not recording {topic}: {exc}")
            return
        self._sink.add_channel(topic, type_name, qos_profiles_yaml(offered))
        self._recorded[topic] = self.create_subscription(
            msg_class, topic, self._callback(topic), subscription_qos(offered), raw=True
        )
        self.get_logger().info(f"recording {topic} [{type_name}]")

    def _callback(self, topic: str) -> Callable[[bytes], None]:
        put, clock = self._sink.put, self.get_clock()

        def on_message(data: bytes) -> None:
            put(topic, data, clock.now().nanoseconds)

        return on_message


def _parse(argv: list[str]) -> argparse.Namespace:
    parser = argparse.ArgumentParser(prog="mcap_recorder", description=__doc__.splitlines()[0])
    parser.add_argument("-o", "--output", required=True, help="output .mcap file")
    parser.add_argument("--topics", default=None,
                        help=f"regex that topic names must match (default: {DEFAULT_TOPICS}, "
                             "under the node's namespace)")
    parser.add_argument("--compression", choices=("zstd", "none"), default="zstd")
    parser.add_argument("--overwrite", action="store_true",
                        help="replace an existing output file (default: refuse)")
    split = parser.add_mutually_exclusive_group()
    split.add_argument("--split-size", type=float, metavar="MB",
                       help="start a new file after MB megabytes")
    split.add_argument("--split-duration", type=float, metavar="S",
                       help="start a new file after S seconds of log time")
    args = parser.parse_args(argv)
    if (args.split_size or 1) <= 0 or (args.split_duration or 1) <= 0:
        parser.error("split limits must be positive")
    try:
        re.compile(args.topics or DEFAULT_TOPICS)
    except re.error as exc:
        parser.error(f"bad --topics regex: {exc}")
    return args


def _open_sink(args: argparse.Namespace) -> tuple[RotatingWriter, BackgroundWriter]:
    split_bytes = int(args.split_size * 1e6) if args.split_size else None
    files = RotatingWriter(args.output, args.compression, split_bytes, args.split_duration,
                           overwrite=args.overwrite)
    return files, BackgroundWriter(files, name="mcap-recorder")


def _status_text(files: RotatingWriter, sink: BackgroundWriter, node: McapRecorder) -> str:
    return (f"[mcap_recorder] {sink.written} msgs  {files.bytes_written / 1e6:.2f} MB  "
            f"{len(node.topics)} topics  dropped {sink.dropped}  -> {files.paths[-1].name}")


def _spin(node: McapRecorder, files: RotatingWriter, sink: BackgroundWriter) -> None:
    status = StatusLine()
    if status.active:
        node.create_timer(STATUS_PERIOD_S, lambda: status.show(_status_text(files, sink, node)),
                          clock=node.steady)
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    except RCLError:
        if rclpy.ok():
            raise                   # a shutdown while the wait set was built is a clean stop
    finally:
        status.close()


def main(args: list[str] | None = None) -> int:
    logging.basicConfig(level=logging.INFO, format="[mcap_recorder] %(levelname)s %(message)s")
    argv = sys.argv if args is None else args
    options = _parse(remove_ros_args(argv)[1:])
    try:
        files, sink = _open_sink(options)
    except (ArchiveError, OSError) as exc:
        _log.error("%s", exc)
        return 2
    rclpy.init(args=argv)
    interrupt_on_hangup()
    node = McapRecorder(sink, options.topics)
    failure = None
    try:
        _spin(node, files, sink)
    finally:
        node.destroy_node()
        rclpy.try_shutdown()
        try:
            sink.close()
        except ArchiveError as exc:
            failure = str(exc)
    where = ", ".join(str(p) for p in files.paths)
    if failure is not None:
        _log.error("recording incomplete: %s; %d messages kept in %s, %d lost", failure,
                   sink.written, where, sink.dropped)
        return 1
    _log.info("%d messages on %d topics in %s (%d dropped)", sink.written, len(node.topics),
              where, sink.dropped)
    return 0


if __name__ == "__main__":
    sys.exit(main())
