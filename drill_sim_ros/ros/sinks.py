"""Where every block of samples goes: the DDS publishers and the in-process recorder.

One path for all of sim_node's ticks (real time, free run, lockstep, paused stepping): the
block's SI rows are packed into CDR once (:class:`~drill_sim_ros.ros.frame.SampleFrame`),
each payload is published through rclpy's public ``Publisher.publish(bytes)``, and the very
same bytes are queued for the recorder, logged at the sample's stamp.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from rclpy.publisher import Publisher

from drill_sim_ros.model.session import Block
from drill_sim_ros.model.telemetry import N_FIELDS
from drill_sim_ros.ros.frame import SampleFrame

# The ticker waits while the recorder has this many messages queued (about 2 s of the writer
# thread's work), so a run as fast as possible loses nothing,
RECORDER_HIGH_WATER = 100_000 // 2
# or while its queue spans more than this much simulated time: with the chunk it has open
# (at most 0.5 s of log time, archive.writer) a SIGKILL loses at most 1 s of simulated time
# in free run too (docs/archive.md), where the sim outruns the writer.
RECORDER_MAX_LAG_S = 0.5


@dataclass(frozen=True)
class TypedTelemetry:
    """drill/typed/telemetry's publisher and the packer of its payloads."""

    publisher: Publisher
    packer: Any


class SampleSinks:
    """Publishers by topic (``topics`` names), and an optional in-process recorder
    (``write_serialized``), which logs each message under its publisher's resolved name."""

    def __init__(self, publishers: dict[str, Publisher]) -> None:
        self._publishers = publishers
        self._frames = {with_clock: SampleFrame(with_clock) for with_clock in (False, True)}
        # per frame: its publishers and their resolved names, in its topics order
        self._targets = {with_clock: [publishers[topic] for topic in frame.topics]
                         for with_clock, frame in self._frames.items()}
        self._names = {with_clock: [publisher.topic_name for publisher in targets]
                       for with_clock, targets in self._targets.items()}
        self.recorder: Any = None
        self.clock_period_ns = 1        # /clock at most once per clock period of sim time
        self.typed: TypedTelemetry | None = None      # drill/typed/telemetry, if installed
        self._clock_index = -1            # the clock period of the last /clock sent

    def warm_up(self) -> None:
        """Compile the packing now rather than on the first tick (packs a row of zeros)."""
        for frame in self._frames.values():
            frame.pack(np.zeros((1, N_FIELDS)), np.zeros(1, dtype=np.int64))

    def emit(self, block: Block, with_clock: bool) -> None:
        """Publish (and record) every sample of ``block``; if ``with_clock``, /clock too on
        the first sample of each clock period (``clock_period_ns`` of sim time)."""
        publishers, names = self._targets[with_clock], self._names[with_clock]
        recorder = self.recorder
        packed = self._frames[with_clock].pack(block.rows, block.stamps_ns)
        without_clock = len(self._targets[False])
        typed = self.typed
        typed_payloads = typed.packer.pack(block.rows, block.stamps_ns) if typed else packed
        for payloads, typed_payload, time_ns in zip(packed, typed_payloads,
                                                    block.stamps_ns.tolist(), strict=True):
            count = len(payloads) if with_clock and self._clock_due(time_ns) else without_clock
            for publisher, payload in zip(publishers[:count], payloads, strict=False):
                publisher.publish(payload)
            if typed is not None:
                typed.publisher.publish(typed_payload)
            if recorder is not None:
                for name, payload in zip(names[:count], payloads, strict=False):
                    recorder.write_serialized(name, payload, time_ns)
                if typed is not None:
                    recorder.write_serialized(typed.publisher.topic_name, typed_payload,
                                              time_ns)

    def _clock_due(self, time_ns: int) -> bool:
        """The sample at ``time_ns`` is the first of a new clock period (/clock goes out)."""
        index = time_ns // self.clock_period_ns
        if index == self._clock_index:
            return False
        self._clock_index = index
        return True

    def emit_one(self, topic: str, payload: bytes, time_ns: int,
                 publishers: dict[str, Publisher] | None = None) -> None:
        """Publish (and record) one serialized message, e.g. /diagnostics (on ``topic`` of
        ``publishers``; default: the sinks' own)."""
        publisher = (publishers or self._publishers)[topic]
        publisher.publish(payload)
        if self.recorder is not None:
            self.recorder.write_serialized(publisher.topic_name, payload, time_ns)

    def backlogged(self, ahead_s: float = 0.0) -> bool:
        """The recorder is behind by more than :data:`RECORDER_HIGH_WATER` messages, or
        would be by more than :data:`RECORDER_MAX_LAG_S` of simulated time once the block
        about to be simulated (``ahead_s``) is queued too."""
        recorder = self.recorder
        return recorder is not None and (
            recorder.backlog > RECORDER_HIGH_WATER
            or recorder.backlog_s + ahead_s > RECORDER_MAX_LAG_S)
