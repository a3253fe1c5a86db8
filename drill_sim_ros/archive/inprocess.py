"""In-process recording for sim_node: serialize in the caller, write on a background thread.

Lossless by construction: the caller serializes (a few microseconds) and appends to a queue
sized for about 100 s of the sim's default output; the writer thread sustains well over the
sim's rate (see benchmarks/bench_mcap.py), so in lockstep and in free-run the queue never
fills and ``close()`` drains every queued message. Only a writer that falls ~100 s behind
drops messages, and each drop is counted in ``dropped``.

Log time: the caller passes each message's simulated time (its header stamp); the file stores
log time = wall-clock origin + simulated time. The spacing stays that of simulated time (a
replay at rate 1 paces like the sim), and the file starts at the real date of the run
(Foxglove, ``ros2 bag info``), like an ``mcap_recorder`` file. The origin defaults to the
wall clock at the first message minus its simulated time; the stamps are not changed.
"""

from __future__ import annotations

import logging
import threading
import time

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
    log_time_origin_ns: wall-clock ns (Unix epoch) of simulated time 0; None: set from the
    wall clock at the first message.
    """

    def __init__(
        self,
        path: str,
        node_name: str = "drill_sim",
        capacity: int = DEFAULT_CAPACITY,
        compression: str = "zstd",
        metadata: dict[str, str] | None = None,
        log_time_origin_ns: int | None = None,
    ) -> None:
        self.path = path
        self._origin_ns = log_time_origin_ns
        self._origin_lock = threading.Lock()
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

    @property
    def log_time_origin_ns(self) -> int | None:
        """Wall-clock ns of simulated time 0 in the file's log times (None before a message)."""
        return self._origin_ns

    def _log_time(self, sim_time_ns: int) -> int:
        if self._origin_ns is None:
            with self._origin_lock:          # the first writer on any thread sets it
                if self._origin_ns is None:
                    self._origin_ns = time.time_ns() - sim_time_ns
        return self._origin_ns + sim_time_ns

    def write(self, topic: str, message: object, sim_time_ns: int) -> None:
        """Serialize ``message`` and queue it; never blocks, counts a drop on overflow."""
        if topic not in self._topics:
            self._unknown_topic_drops += 1
            return
        self._writer.put(topic, serialize_message(message), self._log_time(sim_time_ns))

    def write_serialized(self, topic: str, data: bytes, sim_time_ns: int) -> None:
        """Queue bytes already in CDR (what the publisher sent); never blocks."""
        if topic not in self._topics:
            self._unknown_topic_drops += 1
            return
        self._writer.put(topic, data, self._log_time(sim_time_ns))

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
