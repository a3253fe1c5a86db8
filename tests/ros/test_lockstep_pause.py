"""``~/pause`` in command-triggered lockstep: while paused no period runs, whatever the
controller sends; resumed, the same lockstep goes on, sample for sample and byte for byte as
a run that was never paused. sim_node and a controller node in this process, over loopback
DDS; the controller is plain rclpy, written from docs/control-loop.md as
examples/lockstep_controller.py is."""

from __future__ import annotations

import math

import pytest
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from rclpy.serialization import serialize_message
from sensor_msgs.msg import JointState
from std_srvs.srv import SetBool

from drill_sim_ros import topics
from drill_sim_ros.ros.sim_node import PAUSED_COMMAND_LOCKSTEP, SimNode
from tests.ros.harness import Probe, Ros, overrides, ros_context

pytestmark = pytest.mark.ros
PERIODS = 300
PAUSE_AT = 40              # samples received before the pause
PAUSE = f"/{topics.NODE_NAME}/pause"
WARN_AFTER_S = 0.3         # a lockstep wait this long is reported; a pause is no wait
LATEST_SAMPLE = QoSProfile(depth=1, reliability=ReliabilityPolicy.RELIABLE,
                           durability=DurabilityPolicy.TRANSIENT_LOCAL)


class Controller(Node):
    """Answers every new sample of drill/surface/measured with one drill/cmd/top_drive
    command stamped with it: a speed setpoint that steps at 0.5 s and follows the string
    torque, so the run depends on every sample. ``received`` counts the samples after the
    first; ``payloads`` keeps them serialized."""

    def __init__(self, **node_kwargs) -> None:
        super().__init__("pause_test_controller", **node_kwargs)
        self.sent, self.received, self.payloads = 0, 0, []
        self._last_ns = -1
        self._pub = self.create_publisher(JointState, "drill/cmd/top_drive", 10)
        self.create_subscription(JointState, "drill/surface/measured", self._on_sample,
                                 LATEST_SAMPLE)

    @property
    def done(self) -> bool:
        return self.received >= PERIODS

    def _on_sample(self, sample: JointState) -> None:
        time_ns = sample.header.stamp.sec * 1_000_000_000 + sample.header.stamp.nanosec
        if time_ns <= self._last_ns:
            return                                  # answered already
        if self._last_ns >= 0:
            self.received += 1
            self.payloads.append(serialize_message(sample))
        self._last_ns = time_ns
        if self.done:
            return
        rpm = 100.0 if time_ns < 500_000_000 else 110.0
        setpoint = rpm * math.pi / 30.0 - 1e-4 * (sample.effort[1] - 5000.0)
        command = JointState(name=["top_drive"], velocity=[setpoint])
        command.header.stamp = sample.header.stamp
        self._pub.publish(command)
        self.sent += 1


def start(ros: Ros) -> Controller:
    node = SimNode(context=ros.context, parameter_overrides=overrides(
        lockstep=True, lockstep_trigger="command", status_line=False, publish_clock=False,
        top_drive__mode="kinematic", model__preset="field_8p5in_shale_lumped",
        lockstep__warn_after_s=WARN_AFTER_S))
    node.start()
    ros.add(node)
    return ros.add(Controller(context=ros.context))


def pause(ros: Ros, probe: Probe, paused: bool) -> str:
    response = ros.call(probe, SetBool, PAUSE, SetBool.Request(data=paused))
    assert response.success
    return response.message


def test_pause_holds_command_lockstep_and_resume_continues_it(capfd) -> None:
    with ros_context() as ros:
        driver = start(ros)
        probe = ros.add(Probe(ros.context, []))
        assert ros.spin_until(lambda: driver.received >= PAUSE_AT, 30.0), driver.received
        capfd.readouterr()          # (a wait before the driver connected may be reported)
        assert pause(ros, probe, True) == PAUSED_COMMAND_LOCKSTEP
        # a sample out before the pause may still arrive, and the driver answers it
        assert ros.spin_until(lambda: driver.sent == driver.received + 1, 5.0)
        ros.spin_for(0.3)
        held = driver.received
        assert held < PERIODS
        ros.spin_for(1.0)
        # the controller's answer to the latest sample is out; no period ran on it
        assert driver.received == held and driver.sent == held + 1
        assert "waiting for" not in capfd.readouterr().err
        assert pause(ros, probe, False) == "running"
        assert ros.spin_until(lambda: driver.done, 30.0), driver.received
        paused_run = driver.payloads
    with ros_context() as ros:
        driver = start(ros)
        assert ros.spin_until(lambda: driver.done, 30.0), driver.received
        straight_run = driver.payloads
    assert len(paused_run) == len(straight_run) == PERIODS
    assert paused_run == straight_run


def test_pause_outside_command_lockstep_says_paused() -> None:
    with ros_context() as ros:
        node = SimNode(context=ros.context, parameter_overrides=overrides(
            lockstep=True, status_line=False, top_drive__mode="kinematic"))
        node.start()
        ros.add(node)
        probe = ros.add(Probe(ros.context, []))
        assert pause(ros, probe, True) == "paused"
        assert pause(ros, probe, False) == "running"
