"""Nothing waits in silence (issue 22): sim_node in ``~/step`` lockstep reports a wait past
``lockstep.warn_after_s`` on /diagnostics, and a step ends it."""

from __future__ import annotations

import pytest
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


def test_a_step_lockstep_wait_is_reported_and_a_step_ends_it():
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
