"""Nothing waits in silence (issue 22): sim_node in ``~/step`` lockstep reports a wait past
``lockstep.warn_after_s`` on /diagnostics, and a step ends it."""

from __future__ import annotations

import pytest
from rclpy.node import Node
from rclpy.parameter import Parameter
from sensor_msgs.msg import JointState
from std_srvs.srv import Trigger

from drill_sim_ros import topics
from drill_sim_ros.ros.sim_node import SimNode
from tests.ros.harness import Probe, overrides, ros_context

pytestmark = pytest.mark.ros


def simulation_status(probe: Probe):
    statuses = [s for m in probe.messages(topics.DIAGNOSTICS) for s in m.status
                if s.name.endswith("simulation")]
    return statuses[-1] if statuses else None


def values(status) -> dict[str, str]:
    return {kv.key: kv.value for kv in status.values}


def test_a_step_lockstep_wait_is_reported_and_a_step_ends_it(capfd):
    with ros_context() as ros:
        node = SimNode(context=ros.context, parameter_overrides=overrides(
            lockstep=True, status_line=False, lockstep__warn_after_s=0.3))
        node.start()
        ros.add(node)
        probe = ros.add(Probe(ros.context, [topics.DIAGNOSTICS]))
        assert ros.spin_until(lambda: simulation_status(probe) is not None
                              and simulation_status(probe).level == b"\x01", 10.0)
        status = simulation_status(probe)
        assert status.message.startswith(
            f"waiting for a call of /{topics.NODE_NAME}/step at t = 0.000 s, ")
        assert values(status)["lockstep_waits"] == "1"
        response = ros.call(probe, Trigger, f"/{topics.NODE_NAME}/step", Trigger.Request())
        assert response.success
        count = len(probe.messages(topics.DIAGNOSTICS))
        assert ros.spin_until(lambda: len(probe.messages(topics.DIAGNOSTICS)) > count, 5.0)
        # the wait ended; the next one (no more steps) is reported again, once
        after = values(simulation_status(probe))
        assert after["waiting"] == "" or after["lockstep_waits"] == "2"
    # one log line for the wait, one when it ended
    log = capfd.readouterr().err
    assert log.count(f"waiting for a call of /{topics.NODE_NAME}/step at t = 0.000 s") == 1
    assert log.count("lockstep runs again: t = 0.010 s published after") == 1, log


def test_a_controller_that_connects_and_does_not_answer_is_reported(capfd):
    """A controller written without the docs' QoS (a volatile sample subscription) started
    after sim_node never gets the t = 0 sample, so it never answers: the wait is reported
    once with no publisher, and once more, naming the QoS, after it has connected."""
    with ros_context() as ros:
        node = SimNode(context=ros.context, parameter_overrides=overrides(
            lockstep=True, lockstep_trigger="command", status_line=False,
            lockstep__warn_after_s=0.3))
        node.start()
        ros.add(node)
        probe = ros.add(Probe(ros.context, [topics.DIAGNOSTICS]))
        assert ros.spin_until(lambda: simulation_status(probe) is not None
                              and simulation_status(probe).level == b"\x01", 10.0)
        controller = ros.add(Node("volatile_controller", context=ros.context))
        commands = controller.create_publisher(JointState, "drill/cmd/top_drive", 10)

        def answer(sample: JointState) -> None:
            command = JointState(name=["top_drive"], velocity=[6.0])
            command.header.stamp = sample.header.stamp
            commands.publish(command)
        controller.create_subscription(JointState, "drill/surface/measured", answer, 10)
        assert ros.spin_until(lambda: commands.get_subscription_count() > 0, 10.0)
        text = ""

        def reported() -> bool:
            nonlocal text
            text += capfd.readouterr().err
            return "none answered" in text
        assert ros.spin_until(reported, 10.0), text
        assert ros.spin_until(lambda: values(simulation_status(probe))[
            "command_publishers"] == "1", 5.0)          # /diagnostics: 1 Hz
        status = simulation_status(probe)
    lines = [line for line in text.splitlines() if "waiting for a command" in line]
    assert len(lines) == 2, lines
    assert "answering t = 0.000 s" in lines[0] and "0 command publishers matched" in lines[0]
    assert "answering t = 0.000 s" in lines[1] and "1 command publisher(s) matched" in lines[1]
    assert "reliable + transient local" in lines[1]
    assert values(status)["sim_time_s"] == "0.000"           # it still waits for t = 0


def test_a_lockstep_switched_on_while_running_is_watched_too(capfd):
    """The wait check runs only in lockstep (a node at real time never wakes its executor
    for it), so switching lockstep on by parameter must arm it: the wait is reported."""
    with ros_context() as ros:
        node = SimNode(context=ros.context, parameter_overrides=overrides(
            status_line=False, lockstep__warn_after_s=0.3))
        node.start()
        ros.add(node)
        probe = ros.add(Probe(ros.context, [topics.DIAGNOSTICS]))
        assert ros.spin_until(lambda: simulation_status(probe) is not None, 10.0)
        assert "waiting for a call" not in capfd.readouterr().err
        result = node.set_parameters([Parameter("lockstep", value=True)])
        assert result[0].successful, result[0].reason
        text = ""

        def reported() -> bool:
            nonlocal text
            text += capfd.readouterr().err
            return f"waiting for a call of /{topics.NODE_NAME}/step" in text
        assert ros.spin_until(reported, 10.0), text
