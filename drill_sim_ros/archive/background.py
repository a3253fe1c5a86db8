"""A writer thread behind a bounded queue: producers never block, overflow is counted.

The producer (a sim loop, a subscription callback) appends to a deque, which is atomic under
the GIL and costs well under a microsecond; the thread drains it in batches into a sink (a
:class:`~drill_sim_ros.archive.writer.Ros2McapWriter` or a rotating set of them). A message is
dropped only when ``capacity`` messages are already waiting, i.e. when the writer has fallen
about ``capacity / rate`` behind; every drop is counted. Channel registrations are never
dropped. When the queue stays empty for ``idle_flush_s``, the open chunk is flushed, so the
file on disk lags the producer by at most about one chunk.

When the sink fails (a full disk), the thread stops, logs the reason once, and :attr:`error`
holds it; from then on every message is counted as dropped. :attr:`written` counts only what
the sink handed to the OS, never what it merely buffered.
"""

from __future__ import annotations

import collections
import logging
import threading
from typing import Any, Protocol

from drill_sim_ros.archive.errors import ArchiveError

_log = logging.getLogger(__name__)

# 100 s of backlog at the sim's default ~1000 msg/s; about 20-30 MB if it ever fills.
DEFAULT_CAPACITY = 100_000
DEFAULT_IDLE_FLUSH_S = 0.25
_CLOSE_TIMEOUT_S = 60.0


class Sink(Protocol):
    """What the thread writes into."""

    def add_channel(self, topic: str, type_name: str, offered_qos_yaml: str = "") -> Any: ...
    def write(self, channel: Any, data: bytes, log_time_ns: int) -> None: ...
    def flush(self) -> None: ...
    def finish(self) -> None: ...
    @property
    def messages_on_disk(self) -> int: ...
    @property
    def message_count(self) -> int: ...


class _Channel:
    """A queued channel registration (a control item, never dropped)."""

    __slots__ = ("offered_qos_yaml", "topic", "type_name")

    def __init__(self, topic: str, type_name: str, offered_qos_yaml: str) -> None:
        self.topic, self.type_name, self.offered_qos_yaml = topic, type_name, offered_qos_yaml


class BackgroundWriter:
    """Feeds ``sink`` from a bounded queue on a daemon thread."""

    def __init__(
        self,
        sink: Sink,
        capacity: int = DEFAULT_CAPACITY,
        idle_flush_s: float = DEFAULT_IDLE_FLUSH_S,
        name: str = "mcap-writer",
    ) -> None:
        if capacity < 1:
            raise ArchiveError("queue capacity must be at least 1")
        self._sink = sink
        self._capacity = capacity
        self._idle_flush_s = idle_flush_s
        self._items: collections.deque = collections.deque()
        self._handles: dict[str, Any] = {}
        self._wakeup = threading.Event()
        self._closing = False
        self._closed = False
        self.error: BaseException | None = None
        self.dropped = 0
        self.max_backlog = 0
        self._thread = threading.Thread(target=self._run, name=name, daemon=True)
        self._thread.start()

    # ---- producer side (any thread) -----------------------------------------------------
    def add_channel(self, topic: str, type_name: str, offered_qos_yaml: str = "") -> None:
        """Queue the registration of ``topic`` (before its first message)."""
        self._items.append(_Channel(topic, type_name, offered_qos_yaml))
        self._wakeup.set()

    def put(self, topic: str, data: bytes, log_time_ns: int) -> bool:
        """Queue one message; False (and counted in ``dropped``) when it had to be dropped."""
        items = self._items
        if self._closing or self.error is not None or len(items) >= self._capacity:
            self.dropped += 1
            return False
        items.append((topic, data, log_time_ns))
        if not self._wakeup.is_set():
            self._wakeup.set()
        return True

    @property
    def backlog(self) -> int:
        return len(self._items)

    @property
    def backlog_ns(self) -> int:
        """The log time the queue spans (its newest message's less its oldest's; 0 when it
        holds fewer than two messages): what a SIGKILL would lose beyond the open chunk."""
        items = self._items
        try:
            first, last = items[0], items[-1]
        except IndexError:                       # emptied by the writer meanwhile
            return 0
        if isinstance(first, _Channel) or isinstance(last, _Channel):
            return 0
        return max(0, last[2] - first[2])

    @property
    def written(self) -> int:
        """Messages the sink handed to the OS (a full disk stops this count)."""
        return self._sink.messages_on_disk

    @property
    def failure(self) -> str | None:
        """One line: why writing stopped, or None."""
        return None if self.error is None else str(self.error)

    # ---- writer thread ------------------------------------------------------------------
    def _run(self) -> None:
        try:
            self._loop()
        except BaseException as exc:  # a disk error must not vanish with the thread
            self.error = exc
            # lost: what the sink buffered but never wrote, and everything still queued
            self.dropped += self._sink.message_count - self._sink.messages_on_disk
            self.dropped += sum(not isinstance(item, _Channel) for item in self._items)
            self._items.clear()
            _log.error("recording stopped: %s; every further message is dropped", exc)

    def _loop(self) -> None:
        while True:
            self._wakeup.clear()
            wrote = self._drain()
            if self._closing and not self._items:
                return
            if not wrote and not self._wakeup.wait(self._idle_flush_s):
                self._sink.flush()

    def _drain(self) -> bool:
        items, sink, handles = self._items, self._sink, self._handles
        self.max_backlog = max(self.max_backlog, len(items))
        count = 0
        while items:
            item = items.popleft()
            if isinstance(item, _Channel):
                handles[item.topic] = sink.add_channel(
                    item.topic, item.type_name, item.offered_qos_yaml
                )
                continue
            sink.write(handles[item[0]], item[1], item[2])
            count += 1
        return count > 0

    # ---- end ----------------------------------------------------------------------------
    def close(self) -> None:
        """Write everything queued, then finish the sink. Idempotent.

        Raises one ArchiveError (after finishing what it can) if anything failed.
        """
        if self._closed:
            return
        self._closing = True
        self._wakeup.set()
        self._thread.join(_CLOSE_TIMEOUT_S)
        self._closed = True
        if self._thread.is_alive():
            raise ArchiveError(f"the MCAP writer did not drain within {_CLOSE_TIMEOUT_S} s")
        try:
            self._sink.finish()
        except ArchiveError as exc:
            self.error = self.error or exc
        if self.error is not None:
            raise ArchiveError(str(self.error)) from None
