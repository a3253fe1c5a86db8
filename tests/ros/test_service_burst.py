"""sim_node's services keep up with a burst: 1000 calls, 1000 replies, none lost silently
(issue 52, point 7). Real rclpy over loopback DDS, a client with the default service QoS (a
queue of 10): the node keeps every request and every reply (sim_node.SERVICE_QOS)."""

from __future__ import annotations

import pytest
from rclpy.node import Node
from std_srvs.srv import SetBool, Trigger

from drill_sim_ros.ros.sim_node import SimNode
from tests.ros.harness import Ros, overrides, ros_context

pytestmark = pytest.mark.ros
BURST = 1000
TIMEOUT_S = 60.0


@pytest.fixture
def ros():
    with ros_context() as r:
        yield r


@pytest.mark.parametrize(("name", "srv_type", "request_"), [
    ("off_bottom", SetBool, SetBool.Request(data=True)),
    ("pause", SetBool, SetBool.Request(data=False)),
    ("reset", Trigger, Trigger.Request()),
    ("step", Trigger, Trigger.Request()),
])
def test_a_burst_of_calls_gets_every_reply(ros: Ros, name: str, srv_type, request_) -> None:
    node = SimNode(context=ros.context,
                   parameter_overrides=overrides(status_line=False, real_time_factor=1.0))
    node.start()
    ros.add(node)
    caller = ros.add(Node("burst_caller", context=ros.context))
    client = caller.create_client(srv_type, f"/drill_sim/{name}")
    assert ros.spin_until(client.service_is_ready, TIMEOUT_S), f"~/{name} not ready"
    futures = [client.call_async(request_) for _ in range(BURST)]
    ros.spin_until(lambda: all(f.done() for f in futures), TIMEOUT_S)
    replies = [f.result() for f in futures if f.done()]
    assert len(replies) == BURST, f"{len(replies)} replies of {BURST}"
    assert all(r is not None and r.message for r in replies)
