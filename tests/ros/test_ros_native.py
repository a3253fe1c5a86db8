"""sim_node as a ROS user expects it (issue 26), in process over loopback DDS: /clock at its
own rate, diagnostics named per rig with levels that mean faults, malformed commands refused,
and the typed drill_sim_msgs topics beside the standard ones."""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np
import pytest
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
from rclpy.duration import Duration
from rclpy.node import Node
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import JointState
from std_msgs.msg import Float64MultiArray
from std_srvs.srv import Trigger

from drill_sim_ros import topics
from drill_sim_ros.model.params import RPM_PER_RAD_S
from drill_sim_ros.ros import typed
from drill_sim_ros.ros.messages import RUN_INFO_QOS, stamp, stamp_ns
from drill_sim_ros.ros.sim_node import SimNode
from tests.ros.harness import PROBE_QOS, Ros, overrides, ros_context

pytestmark = pytest.mark.ros
F = topics.TELEMETRY_INDEX
PERIOD_NS = 10_000_000          # publish_rate_hz 100


@pytest.fixture
def ros():
    with ros_context() as r:
        yield r


def start_sim(ros: Ros, namespace: str | None = None, **params: Any) -> SimNode:
    params.setdefault("status_line", False)
    params.setdefault("top_drive__mode", "kinematic")
    node = SimNode(context=ros.context, namespace=namespace,
                   parameter_overrides=overrides(**params))
    node.start()
    return ros.add(node)


class Collector(Node):
    """Keeps every message of the topics it is given (name -> type), in arrival order."""

    def __init__(self, ros: Ros, subscriptions: dict[str, type], qos: Any = PROBE_QOS) -> None:
        super().__init__("collector", context=ros.context)
        self.got: dict[str, list[Any]] = {name: [] for name in subscriptions}
        for name, msg_type in subscriptions.items():
            self.create_subscription(msg_type, name, self.got[name].append, qos)
        ros.add(self)

    def matched(self) -> Callable[[], bool]:
        return lambda: all(sub.get_publisher_count() > 0 for sub in self.subscriptions)


def step(ros: Ros, node: Node, count: int, name: str = "/drill_sim/step") -> None:
    for _ in range(count):
        response = ros.call(node, Trigger, name, Trigger.Request())
        assert response.success, response.message


def clock_ns(msg: Clock) -> int:
    return stamp_ns(msg.clock)


# ---- /clock at its own rate ---------------------------------------------------------------
@pytest.mark.parametrize(("clock_rate_hz", "every"), [(25.0, 4), (1000.0, 1)],
                         ids=["25Hz", "above-the-sample-rate"])
def test_clock_goes_out_at_its_own_rate_on_sample_stamps(ros, clock_rate_hz, every) -> None:
    start_sim(ros, lockstep=True, clock_rate_hz=clock_rate_hz)
    probe = Collector(ros, {topics.CLOCK: Clock, topics.TELEMETRY: Float64MultiArray})
    assert ros.spin_until(probe.matched(), 10)
    periods = 40
    step(ros, probe, periods)
    assert ros.spin_until(lambda: len(probe.got[topics.TELEMETRY]) > periods, 10)
    ros.spin_for(0.2)
    stamps = [round(m.data[F["sim_time_s"]] * 1e9) for m in probe.got[topics.TELEMETRY]]
    assert stamps == [k * PERIOD_NS for k in range(periods + 1)]     # t = 0 and 40 periods
    # one /clock on the first sample of each clock period, never two for a sample
    expected = [k * PERIOD_NS for k in range(0, periods + 1, every)]
    assert [clock_ns(m) for m in probe.got[topics.CLOCK]] == expected


# ---- diagnostics ----------------------------------------------------------------------------
def statuses(probe: Collector, suffix: str) -> list[DiagnosticStatus]:
    return [s for m in probe.got[topics.DIAGNOSTICS] for s in m.status
            if s.name.endswith(suffix)]


def values(status: DiagnosticStatus) -> dict[str, str]:
    return {kv.key: kv.value for kv in status.values}


def test_diagnostics_are_named_per_node_and_rig(ros) -> None:
    start_sim(ros, namespace="/rig7", lockstep=True)
    probe = Collector(ros, {topics.DIAGNOSTICS: DiagnosticArray})
    assert ros.spin_until(lambda: probe.got[topics.DIAGNOSTICS], 10)
    status = probe.got[topics.DIAGNOSTICS][0].status
    assert [s.name for s in status] == ["rig7/drill_sim: simulation",
                                        "rig7/drill_sim: bit dynamics"]
    assert {s.hardware_id for s in status} == {"rig7"}


def test_stick_slip_is_reported_at_level_ok_and_a_silent_controller_warns(ros) -> None:
    """The lumped field preset sticks within its first 30 s (tests/ros/test_sim_node.py); over a
    5 s window that is stick-slip in the message, not a WARN. One top_drive command, then
    none: once more than command_timeout_s of sim time passed, the simulation status warns."""
    start_sim(ros, model__preset="field_8p5in_shale_lumped", real_time_factor=0.0,
              diagnostics__window_s=5.0,
              diagnostics__command_timeout_s=1.0)
    probe = Collector(ros, {topics.DIAGNOSTICS: DiagnosticArray,
                            topics.TELEMETRY: Float64MultiArray})
    stuck = lambda: any(m.data[F["mode"]] == 2 for m in probe.got[topics.TELEMETRY])  # noqa: E731
    assert ros.spin_until(lambda: stuck() and any(
        float(values(s)["stick_fraction"]) > 0 for s in statuses(probe, ": bit dynamics")), 60)
    dynamics = statuses(probe, ": bit dynamics")
    for status in dynamics:
        assert status.level == DiagnosticStatus.OK, status
    sticking = [s for s in dynamics if float(values(s)["stick_fraction"]) > 0]
    assert sticking[-1].message.startswith("stick-slip (")
    assert values(sticking[-1])["stick_slip"] in ("mild", "severe")
    assert all(s.level == DiagnosticStatus.OK for s in statuses(probe, ": simulation"))

    pub = probe.create_publisher(JointState, topics.CMD_TOP_DRIVE, 10)
    assert ros.spin_until(lambda: pub.get_subscription_count() > 0, 10)
    pub.publish(JointState(name=["top_drive"], velocity=[1.0]))
    assert pub.wait_for_all_acked(Duration(seconds=5))
    before = len(probe.got[topics.DIAGNOSTICS])

    def silent() -> list[DiagnosticStatus]:
        later = [s for m in probe.got[topics.DIAGNOSTICS][before:] for s in m.status
                 if s.name.endswith(": simulation")]
        return [s for s in later if s.level == DiagnosticStatus.WARN]

    assert ros.spin_until(lambda: bool(silent()), 30)
    warn = silent()[0]
    assert warn.message.startswith("controller silent")
    assert float(values(warn)["command_silence_s"]) > 1.0


# ---- malformed commands ------------------------------------------------------------------
def test_a_joint_state_with_ragged_arrays_is_rejected_counted_and_steps_nothing(ros,
                                                                                capfd) -> None:
    node = start_sim(ros, lockstep=True, lockstep_trigger="command")
    probe = Collector(ros, {topics.TELEMETRY: Float64MultiArray})
    pub = probe.create_publisher(JointState, topics.CMD_TOP_DRIVE, 100)
    assert ros.spin_until(lambda: pub.get_subscription_count() > 0 and probe.matched()(), 10)
    ragged = JointState(name=["top_drive", "hook"], velocity=[3.0], effort=[70_000.0])
    for _ in range(5):
        pub.publish(ragged)
    assert pub.wait_for_all_acked(Duration(seconds=5))
    assert ros.spin_until(lambda: node.rejected_commands == 5, 10)
    ros.spin_for(0.3)
    # command lockstep publishes t = 0 to be answered; no period was advanced
    assert ros.spin_until(lambda: len(probe.got[topics.TELEMETRY]) >= 1, 10)
    assert [m.data[F["sim_time_s"]] for m in probe.got[topics.TELEMETRY]] == [0.0]
    good = JointState(name=["top_drive", "hook"], velocity=[3.0, math.nan],
                      effort=[math.nan, 70_000.0])
    pub.publish(good)
    assert ros.spin_until(lambda: len(probe.got[topics.TELEMETRY]) == 2, 10)   # t = 0, one
    row = probe.got[topics.TELEMETRY][1].data
    assert row[F["surface_rpm"]] == pytest.approx(3.0 * RPM_PER_RAD_S)
    assert row[F["applied_wob_n"]] == pytest.approx(70_000.0)
    assert node.rejected_commands == 5
    warnings = [line for line in capfd.readouterr().err.splitlines()
                if "rejected /drill/cmd/top_drive" in line]
    assert len(warnings) == 1, warnings                  # throttled: one per second
    assert "2 names but velocity has 1, effort has 1 values" in warnings[0]


# ---- typed messages ------------------------------------------------------------------------
def test_typed_message_fields_are_the_telemetry_fields() -> None:
    assert typed.AVAILABLE, "drill_sim_msgs is not installed (make venv builds msgs/)"
    assert typed.telemetry_fields() == [f for f in topics.TELEMETRY_FIELDS
                                        if f != "sim_time_s"]
    constants = [getattr(typed.BitMode, name.upper()) for name in topics.MODE_NAMES]
    assert constants == list(range(len(topics.MODE_NAMES)))      # the kernel's codes


def test_typed_topics_carry_the_standard_ones_values_and_take_commands(ros) -> None:
    assert typed.AVAILABLE, "drill_sim_msgs is not installed (make venv builds msgs/)"
    ns = "/rig3"
    start_sim(ros, namespace=ns, lockstep=True, lockstep_trigger="command")
    probe = Collector(ros, {ns + topics.TELEMETRY: Float64MultiArray,
                            ns + topics.TYPED_TELEMETRY: typed.Telemetry})
    info = Collector(ros, {ns + topics.TYPED_RUN_INFO: typed.RunInfo}, RUN_INFO_QOS)
    pub = probe.create_publisher(typed.TopDriveCommand, ns + topics.TYPED_CMD_TOP_DRIVE, 100)
    assert ros.spin_until(lambda: pub.get_subscription_count() > 0 and probe.matched()(), 10)
    for k in range(5):
        command = typed.TopDriveCommand(speed_rad_s=2.0 + k, motor_torque_nm=math.nan,
                                        wob_n=math.nan)
        command.header.stamp = stamp(k * PERIOD_NS)
        pub.publish(command)
    typed_name, standard_name = ns + topics.TYPED_TELEMETRY, ns + topics.TELEMETRY
    assert ros.spin_until(lambda: len(probe.got[typed_name]) == 6
                          and len(probe.got[standard_name]) == 6, 10)
    for msg, row in zip(probe.got[typed_name], probe.got[standard_name], strict=True):
        assert stamp_ns(msg.header.stamp) == round(row.data[F["sim_time_s"]] * 1e9)
        assert msg.header.frame_id == "rig3"
        got = [getattr(msg, name) for name in typed.telemetry_fields()]
        np.testing.assert_array_equal(got, [row.data[F[name]]
                                            for name in typed.telemetry_fields()])
    rows = [m.data for m in probe.got[standard_name]]
    for k in range(5):             # sample k + 1 ran under command k, which reacted to k
        assert rows[k + 1][F["surface_rpm"]] == pytest.approx((2.0 + k) * RPM_PER_RAD_S)
        assert rows[k + 1][F["command_stamp_s"]] == pytest.approx(k * PERIOD_NS * 1e-9)
    assert ros.spin_until(lambda: info.got[ns + topics.TYPED_RUN_INFO], 10)
    run_info = info.got[ns + topics.TYPED_RUN_INFO][0]
    assert run_info.preset == "field_8p5in_shale" and run_info.lockstep
    assert run_info.publish_rate_hz == 100.0 and '"period_ns": 10000000' in run_info.json
    # the typed command goes through the same handshake: a second answer to t = 0 is stale;
    # and its publisher is a command publisher on /diagnostics (the only one here)
    diagnostics = Collector(ros, {topics.DIAGNOSTICS: DiagnosticArray})
    stale = typed.TopDriveCommand(speed_rad_s=9.0, motor_torque_nm=math.nan, wob_n=math.nan)
    stale.header.stamp = stamp(0)
    pub.publish(stale)

    def simulation() -> dict[str, str]:
        found = statuses(diagnostics, ": simulation")
        return values(found[-1]) if found else {}
    assert ros.spin_until(lambda: simulation().get("stale_commands") == "1", 10), simulation()
    assert simulation()["command_publishers"] == "1"
    assert len(probe.got[standard_name]) == 6            # nothing advanced
