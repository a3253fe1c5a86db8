"""The handshake's rules, ROS-free (drill_sim_ros/ros/handshake.py): one command per sample,
one report per wait."""

from __future__ import annotations

from drill_sim_ros.ros.handshake import CommandGate, WaitWatch

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
