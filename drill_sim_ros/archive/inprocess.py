"""In-process recording for sim_node: serialize in the caller, write on a background thread.

Lossless by construction: the caller serializes (a few microseconds) and appends to a queue
sized for about 100 s of the sim's default output; the writer thread sustains well over the
sim's rate (see benchmarks/bench_mcap.py), so in lockstep and in free-run the queue never
fills and ``close()`` drains every queued message. Only a writer that falls ~100 s behind
drops messages, and each drop is counted in ``dropped``.

The output is opened at construction under the archive's output policy: an existing file is
refused (:class:`~drill_sim_ros.archive.output.OutputExistsError`) unless ``overwrite``, and
an unwritable path raises :class:`~drill_sim_ros.archive.output.OutputError`, one line each.
With ``split_size_bytes`` or ``split_duration_s`` the run goes into numbered files
(``run_0000.mcap``, ...) like ``mcap_recorder``'s, each complete with the run metadata, so
the summary kept in memory (about 1 kB per chunk) is bounded by the split. If writing fails
(a full disk), :attr:`error` says why from then on, and :meth:`close` finishes what it can.

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
from drill_sim_ros.archive.errors import ArchiveError
from drill_sim_ros.archive.qos import qos_profiles_yaml
from drill_sim_ros.archive.rotation import RotatingWriter

_log = logging.getLogger(__name__)
RUN_METADATA = "drill_sim"
OVERWRITE_PARAMETER_HINT = "-p record.overwrite:=true"


class InProcessRecorder:
    """Records rclpy messages to ``path`` (MCAP, ROS 2 profile, zstd chunks).

    node_name: the publishing node, for the log; topics must be added before they are written.
    metadata: written once per file as an MCAP metadata record named ``drill_sim`` (e.g. the
    preset, so ``mcap_to_rerun`` picks the right scales).
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
        overwrite: bool = False,
        split_size_bytes: int | None = None,
        split_duration_s: float | None = None,
        overwrite_hint: str = OVERWRITE_PARAMETER_HINT,
        log_time_origin_ns: int | None = None,
    ) -> None:
        self._origin_ns = log_time_origin_ns
        self._origin_lock = threading.Lock()
        self.node_name = node_name
        self._topics: set[str] = set()
        records = {RUN_METADATA: {k: str(v) for k, v in metadata.items()}} if metadata else {}
        self._files = RotatingWriter(path, compression, split_size_bytes, split_duration_s,
                                     overwrite=overwrite, metadata=records,
                                     overwrite_hint=overwrite_hint)
        self._writer = BackgroundWriter(self._files, capacity, name="mcap-inprocess")
        self._unknown_topic_drops = 0
        self._closed = False
        self._close_error: str | None = None

    @property
    def path(self) -> str:
        """The file being written (the latest part when splitting)."""
        return str(self._files.paths[-1])

    @property
    def paths(self) -> list[str]:
        return [str(p) for p in self._files.paths]

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
        """Messages not recorded: queue overflow, a failed disk, writes after close or to
        undeclared topics."""
        return self._writer.dropped + self._unknown_topic_drops

    @property
    def written(self) -> int:
        """Messages in the file(s): handed to the OS, not merely buffered."""
        return self._writer.written

    @property
    def backlog(self) -> int:
        """Messages queued but not yet written."""
        return self._writer.backlog

    @property
    def backlog_s(self) -> float:
        """The log time (= simulated time) the queued messages span, s."""
        return self._writer.backlog_ns * 1e-9

    @property
    def error(self) -> str | None:
        """One line: why recording stopped (e.g. a full disk), None while it works."""
        return self._close_error or self._writer.failure

    def close(self) -> bool:
        """Drain the queue and finish the file(s); True if complete. Idempotent, never raises
        (the caller logs :meth:`summary`)."""
        if not self._closed:
            self._closed = True
            try:
                self._writer.close()
            except ArchiveError as exc:
                self._close_error = str(exc)
        return self.error is None

    def summary(self) -> str:
        """One line: the counts, or why the recording is incomplete."""
        files = ", ".join(self.paths)
        if self.error is None:
            return f"recorded {self.written} messages to {files} ({self.dropped} dropped)"
        return (f"recording incomplete: {self.error}; {self.written} messages kept in "
                f"{files}, {self.dropped} lost")
