"""The handshake's rules, ROS-free (drill_sim_ros/ros/handshake.py): one command per sample,
one report per wait."""

from __future__ import annotations

from drill_sim_ros.ros.handshake import (
    COMMAND_MODE,
    SERVICE_MODE,
    CommandGate,
    Handshake,
    WaitWatch,
)

PERIOD_NS = 10_000_000


def test_only_the_first_answer_to_the_latest_sample_is_admitted():
    gate = CommandGate()
    assert "before any sample" in gate.admit(0)         # nothing published yet
    gate.published(0)
    assert gate.admit(0) is None                         # the answer to t = 0
    assert "a second answer" in gate.admit(0)
    gate.published(PERIOD_NS)
    older = gate.admit(0)
    assert "t = 0.000 s" in older and "latest sample (t = 0.010 s)" in older
    assert gate.admit(-10**9) and gate.admit(10**18)     # negative, far future: stale
    assert gate.admit(PERIOD_NS) is None
    assert gate.stale == 5


def test_a_wait_is_reported_once_and_its_end_once():
    watch = WaitWatch(now_s=100.0)
    assert not watch.overdue(101.9, warn_after_s=2.0)
    assert watch.overdue(102.0, warn_after_s=2.0)
    assert not watch.overdue(150.0, warn_after_s=2.0)    # the same wait: once
    assert watch.advanced(160.0) == 60.0                 # the wait that was reported ends
    assert watch.advanced(160.5) is None                 # an ordinary step: nothing to say
    assert not watch.overdue(1e6, warn_after_s=0.0)      # 0: never
    assert watch.waits == 1


class Lines:
    """A logger that keeps its warning lines."""

    def __init__(self) -> None:
        self.warnings: list[str] = []

    def warning(self, text: str, **_: object) -> None:
        self.warnings.append(text)

    def info(self, text: str, **_: object) -> None:
        pass


def test_a_wait_is_reported_again_when_a_controller_connects_and_does_not_answer():
    """A controller whose sample subscription is volatile connects after t = 0 went out
    and never gets it: the first report (no publisher) is not the last word."""
    lines = Lines()
    handshake = Handshake(lines, "/drill/cmd/top_drive", "/drill_sim/step", now_s=0.0)
    handshake.published(0, now_s=0.0)
    for now_s, publishers in ((1.9, 0), (2.0, 0), (3.0, 1), (4.9, 1), (5.0, 1), (9.0, 1)):
        handshake.check(COMMAND_MODE, now_s, 2.0, publishers)
    assert len(lines.warnings) == 2
    assert "answering t = 0.000 s, 2.0 s; 0 command publishers matched" in lines.warnings[0]
    assert "answering t = 0.000 s, 5.0 s; 1 command publisher(s) matched and none " \
           "answered" in lines.warnings[1]
    assert "transient local" in lines.warnings[1]
    handshake.check(COMMAND_MODE, 9.5, 2.0, 0)       # it went away: 2 s later, once more
    handshake.check(COMMAND_MODE, 11.5, 2.0, 0)
    handshake.check(COMMAND_MODE, 20.0, 2.0, 0)
    assert len(lines.warnings) == 3 and "0 command publishers" in lines.warnings[2]
    # a controller that connects and answers at once: no second report for the next wait
    handshake.published(10_000_000, now_s=21.0)
    handshake.check(COMMAND_MODE, 23.0, 2.0, 1)
    assert len(lines.warnings) == 4 and "1 command publisher(s)" in lines.warnings[3]
    handshake.check(SERVICE_MODE, 40.0, 2.0, 3)      # step lockstep: publishers do not count
    assert len(lines.warnings) == 4
    assert handshake.watch.waits == 2
