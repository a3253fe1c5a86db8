"""Lockstep: ~/step advances one period and answers after it is published; the same commands
in the same order give the same bytes on every topic, run after run (issue 3)."""

from __future__ import annotations

import pytest
from rclpy.duration import Duration
from rclpy.serialization import deserialize_message
from std_msgs.msg import Float64, Float64MultiArray
from std_srvs.srv import Trigger

from drill_sim_ros import topics
from drill_sim_ros.ros.sim_node import SAMPLE_TOPICS, SimNode
from tests.ros.harness import Probe, overrides, ros_context

pytestmark = pytest.mark.ros
STEPS = 60
COMMANDS = {10: (topics.CMD_WOB, 45e3), 25: (topics.CMD_SURFACE_RPM, 90.0),
            40: (topics.CMD_WOB, 70e3)}
RECORDED = (*SAMPLE_TOPICS, topics.CLOCK)
F = topics.TELEMETRY_INDEX


def lockstep_run() -> dict[str, list[bytes]]:
    """One run in a fresh context: STEPS steps with COMMANDS; serialized messages per topic."""
    with ros_context() as ros:
        node = SimNode(context=ros.context, parameter_overrides=overrides(
            lockstep=True, status_line=False, top_drive__mode="kinematic"))
        node.start()
        ros.add(node)
        probe = ros.add(Probe(ros.context, RECORDED, raw=True))
        pubs = {t: probe.create_publisher(Float64, t, 10) for t in (topics.CMD_WOB,
                                                                      topics.CMD_SURFACE_RPM)}
        assert ros.spin_until(lambda: all(p.get_subscription_count() for p in pubs.values()),
                              10.0)
        for step in range(STEPS):
            if step in COMMANDS:
                topic, value = COMMANDS[step]
                pubs[topic].publish(Float64(data=value))
                # The node holds it before the step request is even sent, and its executor
                # takes ready subscriptions before ready services.
                assert pubs[topic].wait_for_all_acked(Duration(seconds=5))
            response = ros.call(probe, Trigger, f"/{topics.NODE_NAME}/step", Trigger.Request())
            assert response.success, response.message
            # t = 0 goes out just before the first period, then one sample per step
            assert ros.spin_until(lambda s=step: probe.count(topics.TELEMETRY) == s + 2, 5.0), \
                "the step's telemetry is published before the answer"
        assert ros.spin_until(lambda: all(probe.count(t) == STEPS + 1 for t in RECORDED), 5.0)
        ros.spin_for(0.2)
        assert all(probe.count(t) == STEPS + 1 for t in RECORDED), "no step publishes twice"
        return {t: probe.messages(t) for t in RECORDED}


def test_same_commands_give_identical_bytes_run_after_run():
    first, second = lockstep_run(), lockstep_run()
    for topic in RECORDED:
        assert first[topic] == second[topic], topic
    # A command sent before step k acts over the whole of period k (zero-order hold), and
    # step k publishes the state at the end of period k, stamped (k + 1) periods: sample k - 1
    # (the start of period k) still has the old value, sample k the new one.
    rows = [deserialize_message(raw, Float64MultiArray).data for raw in first[topics.TELEMETRY]]
    assert rows[0][F["sim_time_s"]] == 0.0
    rows = rows[1:]                             # sample k: the end of the period of step k
    assert [row[F["sim_time_s"]] for row in rows] == pytest.approx(
        [0.01 * (k + 1) for k in range(STEPS)], abs=1e-12)
    applied = [row[F["applied_wob_n"]] for row in rows]
    surface = [row[F["surface_rpm"]] for row in rows]
    assert applied[9] == applied[0] and applied[10] == pytest.approx(45e3)
    assert surface[24] == surface[0] and surface[25] == pytest.approx(90.0)
    assert applied[39] == pytest.approx(45e3) and applied[40] == pytest.approx(70e3)
