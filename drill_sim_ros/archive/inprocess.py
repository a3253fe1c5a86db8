"""In-process recording for sim_node: serialize in the caller, write on a background thread.

Lossless by construction: the caller serializes (a few microseconds) and appends to a queue
sized for about 100 s of the sim's default output; the writer thread sustains well over the
sim's rate (see benchmarks/bench_mcap.py), so in lockstep and in free-run the queue never
fills and ``close()`` drains every queued message. Only a writer that falls ~100 s behind
drops messages, and each drop is counted in ``dropped``.
"""

from __future__ import annotations

import logging

from rclpy.qos import QoSProfile
from rclpy.serialization import serialize_message

from drill_sim_ros.archive.background import DEFAULT_CAPACITY, BackgroundWriter
from drill_sim_ros.archive.qos import qos_profiles_yaml
from drill_sim_ros.archive.writer import Ros2McapWriter

_log = logging.getLogger(__name__)
RUN_METADATA = "drill_sim"


class InProcessRecorder:
    """Records rclpy messages to ``path`` (MCAP, ROS 2 profile, zstd chunks).

    node_name: the publishing node, for the log; topics must be added before they are written.
    metadata: written once as an MCAP metadata record named ``drill_sim`` (e.g. the preset,
    so ``mcap_to_rerun`` picks the right scales).
    """

    def __init__(
        self,
        path: str,
        node_name: str = "drill_sim",
        capacity: int = DEFAULT_CAPACITY,
        compression: str = "zstd",
        metadata: dict[str, str] | None = None,
    ) -> None:
        self.path = path
        self.node_name = node_name
        self._topics: set[str] = set()
        writer = Ros2McapWriter(path, compression=compression)
        if metadata:
            writer.add_metadata(RUN_METADATA, {k: str(v) for k, v in metadata.items()})
        self._writer = BackgroundWriter(writer, capacity, name="mcap-inprocess")
        self._unknown_topic_drops = 0
        self._closed = False

    def add_topic(self, topic: str, msg_type: str, qos_profile: QoSProfile | None = None) -> None:
        """Declare ``topic`` of type ``pkg/msg/Type`` with the QoS its publisher offers."""
        if topic in self._topics:
            return
        offered = qos_profiles_yaml([qos_profile]) if qos_profile is not None else ""
        self._topics.add(topic)
        self._writer.add_channel(topic, msg_type, offered)

    def write(self, topic: str, message: object, log_time_ns: int) -> None:
        """Serialize ``message`` and queue it; never blocks, counts a drop on overflow."""
        if topic not in self._topics:
            self._unknown_topic_drops += 1
            return
        self._writer.put(topic, serialize_message(message), log_time_ns)

    def write_serialized(self, topic: str, data: bytes, log_time_ns: int) -> None:
        """Queue bytes already in CDR (what the publisher sent); never blocks."""
        if topic not in self._topics:
            self._unknown_topic_drops += 1
            return
        self._writer.put(topic, data, log_time_ns)

    @property
    def dropped(self) -> int:
        """Messages not recorded: queue overflow, writes after close or to undeclared topics."""
        return self._writer.dropped + self._unknown_topic_drops

    @property
    def written(self) -> int:
        """Messages handed to the MCAP writer so far."""
        return self._writer.written

    @property
    def backlog(self) -> int:
        """Messages queued but not yet written."""
        return self._writer.backlog

    def close(self) -> None:
        """Drain the queue and finish the file with its summary. Idempotent."""
        if self._closed:
            return
        self._closed = True
        self._writer.close()
        _log.info(
            "%s: recorded %d messages to %s (%d dropped)",
            self.node_name, self.written, self.path, self.dropped,
        )
