"""Lockstep's handshake with a controller: one command per sample, and no silent wait.

ROS-free; sim_node holds one :class:`CommandGate` and one :class:`WaitWatch` under its lock.

- In command-triggered lockstep a ``drill/cmd/top_drive`` command advances the sim only when
  it answers the latest sample: its ``header.stamp`` equals that sample's stamp and no command
  answered it yet. Any other command (an older stamp, a future one, a second answer, one sent
  before any sample was seen) is *stale*: neither applied nor advancing, only counted.
- Whatever advances lockstep (an admitted command, a ``~/step`` call), the wall time since
  the sim last advanced is watched: past ``lockstep.warn_after_s`` it is reported once, and
  once more when the sim advances again. In command lockstep a wait is reported again when
  the number of command publishers changed and the wait went on as long once more (a
  controller connected and does not answer, or went away).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from drill_sim_ros.model.telemetry import NS_PER_S


def seconds_text(time_ns: int) -> str:
    """A stamp as the seconds a log line shows (``t = 12.340 s``)."""
    return f"t = {time_ns / NS_PER_S:.3f} s"


class CommandGate:
    """Which command answers the latest sample (``latest_ns``: its stamp; None before the
    first sample is published)."""

    def __init__(self) -> None:
        self.latest_ns: int | None = None
        self.answered = False
        self.stale = 0

    def published(self, stamp_ns: int) -> None:
        """A new latest sample went out: the next command stamped ``stamp_ns`` answers it."""
        self.latest_ns = stamp_ns
        self.answered = False

    def admit(self, stamp_ns: int) -> str | None:
        """None if a command stamped ``stamp_ns`` answers the latest sample (which is then
        answered); else, counted as stale, why not, naming both stamps."""
        if self.latest_ns is not None and stamp_ns == self.latest_ns and not self.answered:
            self.answered = True
            return None
        self.stale += 1
        if self.latest_ns is None:
            return f"stamped {seconds_text(stamp_ns)}, before any sample was published"
        latest = seconds_text(self.latest_ns)
        if stamp_ns == self.latest_ns:
            return f"stamped {latest}, a second answer to the latest sample ({latest})"
        return f"stamped {seconds_text(stamp_ns)}, which is not the latest sample ({latest})"


@dataclass(frozen=True)
class Waiting:
    """What lockstep waits for: ``what`` (a command on a topic, a service call) and since
    when (wall seconds)."""

    what: str
    latest_ns: int
    waited_s: float
    relation: str = "answering"      # how what it waits for relates to the latest sample

    @property
    def text(self) -> str:
        return f"waiting for {self.what} {self.relation} {seconds_text(self.latest_ns)}, " \
               f"{self.waited_s:.1f} s"


class WaitWatch:
    """The wall time since lockstep last advanced (``since_s``, monotonic seconds); ``waits``
    counts the waits that went past the warning time."""

    def __init__(self, now_s: float) -> None:
        self.since_s = now_s
        self.warned = False
        self.waits = 0

    def advanced(self, now_s: float) -> float | None:
        """The sim advanced at ``now_s``; the seconds it had waited if that wait was reported
        (to say once that it resumed), else None."""
        waited_s = now_s - self.since_s if self.warned else None
        self.since_s, self.warned = now_s, False
        return waited_s

    def waited_s(self, now_s: float) -> float:
        return now_s - self.since_s

    def overdue(self, now_s: float, warn_after_s: float) -> bool:
        """True once per wait, when it passes ``warn_after_s`` (0: never)."""
        if self.warned or warn_after_s <= 0 or now_s - self.since_s < warn_after_s:
            return False
        self.warned = True
        self.waits += 1
        return True


COMMAND_MODE, SERVICE_MODE = "command", "service"     # lockstep_trigger values
LOG_THROTTLE_S = 5.0        # at most one stale or lost-command warning per this many seconds


class Handshake:
    """sim_node's side of lockstep: the gate, the wait watch, the commands lost in DDS, and
    their log lines (``logger``: the node's; it takes ``throttle_duration_sec``)."""

    def __init__(self, logger: Any, command_topic: str, step_service: str,
                 now_s: float) -> None:
        self.gate = CommandGate()
        self.watch = WaitWatch(now_s)
        self.lost_commands = 0
        self._publishers = PublisherCount()
        self._logger = logger
        self._waiting_for = {COMMAND_MODE: (f"a command on {command_topic}", "answering"),
                             SERVICE_MODE: (f"a call of {step_service}", "at")}

    def restart(self, now_s: float) -> None:
        """Lockstep (re)starts now: a wait counts from here."""
        self.watch.since_s, self.watch.warned = now_s, False

    def published(self, stamp_ns: int, now_s: float, advanced: bool = True) -> None:
        """A sample stamped ``stamp_ns`` went out: the latest; with ``advanced`` (the sim
        advanced to it, not the t = 0 sample just before the first period) one info line if
        the sim had been reported waiting."""
        self.gate.published(stamp_ns)
        if not advanced:
            return
        waited_s = self.watch.advanced(now_s)
        if waited_s is not None:
            self._logger.info(f"lockstep runs again: {seconds_text(stamp_ns)} published "
                              f"after {waited_s:.1f} s of waiting")

    def admit(self, topic: str, stamp_ns: int) -> bool:
        """Whether a command stamped ``stamp_ns`` answers the latest sample; a stale one is
        counted and warned about (throttled), with both stamps."""
        why = self.gate.admit(stamp_ns)
        if why is None:
            return True
        self._logger.warning(
            f"stale command on {topic}: {why}; not applied, the sim does not advance "
            f"(stamp a command with the stamp of the sample it answers; "
            f"{self.gate.stale} stale so far)", throttle_duration_sec=LOG_THROTTLE_S)
        return False

    def lost(self, topic: str, count: int) -> None:
        """``count`` commands on ``topic`` that DDS reports lost (a publisher's history
        overwrote them before they were delivered)."""
        self.lost_commands += count
        self._logger.warning(
            f"{count} command(s) on {topic} lost in DDS before they reached the sim (a "
            f"publisher sends faster than its history keeps; {self.lost_commands} lost so "
            "far)", throttle_duration_sec=LOG_THROTTLE_S)

    def waiting(self, mode: str | None, now_s: float) -> Waiting | None:
        """What lockstep in ``mode`` (None: not in lockstep) waits for, once reported."""
        if mode is None or not self.watch.warned:
            return None
        what, relation = self._waiting_for[mode]
        return Waiting(what, self.gate.latest_ns or 0, self.watch.waited_s(now_s), relation)

    def check(self, mode: str | None, now_s: float, warn_after_s: float,
              publishers: int) -> None:
        """One warning line when the wait passes ``warn_after_s``; one more each time the
        number of command ``publishers`` changed and the wait went on ``warn_after_s`` after
        that (a controller that connected and does not answer, or one that went away)."""
        if mode is None:
            return
        first = self.watch.overdue(now_s, warn_after_s)
        if first or (mode == COMMAND_MODE and self.watch.warned
                     and self._publishers.changed(publishers, now_s, warn_after_s)):
            self._report(mode, now_s, publishers)

    def _report(self, mode: str, now_s: float, publishers: int) -> None:
        self._publishers.reported(publishers)
        waiting = self.waiting(mode, now_s)
        if mode == SERVICE_MODE:
            hint = "each call advances one period"
        elif publishers == 0:
            hint = "0 command publishers matched: no controller runs (docs/control-loop.md)"
        else:
            hint = (f"{publishers} command publisher(s) matched and none answered: a "
                    "controller answers every sample it receives, and subscribes to the "
                    "samples reliable + transient local to get the one published before it "
                    "connected (docs/control-loop.md)")
        self._logger.warning(f"{waiting.text}; {hint}")


class PublisherCount:
    """The number of command publishers last reported, and since when (monotonic seconds)
    it has differed from the number matched now."""

    def __init__(self) -> None:
        self.last: int | None = None
        self.differs_since_s: float | None = None

    def reported(self, publishers: int) -> None:
        self.last, self.differs_since_s = publishers, None

    def changed(self, publishers: int, now_s: float, settle_s: float) -> bool:
        """True once ``publishers`` has differed from the last report for ``settle_s``."""
        if publishers == self.last:
            self.differs_since_s = None
            return False
        if self.differs_since_s is None:
            self.differs_since_s = now_s
        return now_s - self.differs_since_s >= settle_s
