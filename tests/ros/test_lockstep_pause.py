"""``~/pause`` in command-triggered lockstep: while paused no period runs, whatever the
controller sends; resumed, the same lockstep goes on, sample for sample and byte for byte as
a run that was never paused. sim_node and a controller node (LockstepDriver) in this process,
over loopback DDS."""

from __future__ import annotations

import pytest
from std_srvs.srv import SetBool

from drill_sim_ros import topics
from drill_sim_ros.model.params import RPM_PER_RAD_S
from drill_sim_ros.ros.lockstep_driver import Command, LockstepDriver
from drill_sim_ros.ros.sim_node import PAUSED_COMMAND_LOCKSTEP, SimNode
from tests.ros.harness import Probe, Ros, overrides, ros_context

pytestmark = pytest.mark.ros
F = topics.TELEMETRY_INDEX
PERIODS = 300
PAUSE_AT = 40              # samples received before the pause
PAUSE = f"/{topics.NODE_NAME}/pause"
WARN_AFTER_S = 0.3         # a lockstep wait this long is reported; a pause is no wait


def policy(row) -> Command:
    """Deterministic in the sample: the WOB follows the bit speed, the rpm steps at 0.5 s."""
    if row is None:
        return Command(speed_rad_s=100.0 / RPM_PER_RAD_S)
    rpm = 100.0 if row[F["sim_time_s"]] < 0.5 else 110.0
    return Command(speed_rad_s=rpm / RPM_PER_RAD_S,
                   wob_n=60e3 * (1.0 + 0.001 * (row[F["bit_rpm"]] - 100.0)))


def start(ros: Ros) -> LockstepDriver:
    node = SimNode(context=ros.context, parameter_overrides=overrides(
        lockstep=True, lockstep_trigger="command", status_line=False, publish_clock=False,
        top_drive__mode="kinematic", model__preset="field_8p5in_shale_lumped",
        lockstep__warn_after_s=WARN_AFTER_S))
    node.start()
    ros.add(node)
    return ros.add(LockstepDriver(policy, PERIODS, context=ros.context))


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
