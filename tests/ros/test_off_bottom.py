"""``~/off_bottom`` (std_srvs/SetBool): the driller picks the bit up off bottom and tags
bottom again, as a command to a running sim_node over loopback DDS. Picked up, the bit
leaves the rock (mode off_bottom, no weight on bit); tagged again, it drills (the weight
comes back). On the lumped string the service refuses with one line."""

from __future__ import annotations

import pytest
from std_srvs.srv import SetBool

from drill_sim_ros import topics
from drill_sim_ros.model.kernel import MODE_OFF_BOTTOM
from drill_sim_ros.ros.sim_node import SimNode
from tests.ros.harness import Probe, Ros, overrides, ros_context

pytestmark = pytest.mark.ros
OFF_BOTTOM = f"/{topics.NODE_NAME}/off_bottom"


def start(ros: Ros, preset: str) -> Probe:
    node = SimNode(context=ros.context, parameter_overrides=overrides(
        status_line=False, publish_clock=False, model__preset=preset, real_time_factor=20.0))
    node.start()
    ros.add(node)
    return ros.add(Probe(ros.context, [topics.BIT_MODE, topics.BIT_WOB]))


def call(ros: Ros, probe: Probe, off: bool) -> SetBool.Response:
    return ros.call(probe, SetBool, OFF_BOTTOM, SetBool.Request(data=off))


def latest(probe: Probe, topic: str) -> float:
    return float(probe.messages(topic)[-1].data)


def test_off_bottom_picks_up_and_tag_drills_again() -> None:
    with ros_context() as ros:
        probe = start(ros, "field_8p5in_shale")
        assert ros.spin_until(lambda: probe.count(topics.BIT_WOB) > 50, 30.0)
        assert latest(probe, topics.BIT_WOB) > 1e3            # drilling: weight on bit
        response = call(ros, probe, True)
        assert response.success, response.message
        # the hook rises at 0.05 m/s to 0.5 m clearance: off the rock within ~10 s sim
        assert ros.spin_until(lambda: latest(probe, topics.BIT_MODE) == MODE_OFF_BOTTOM
                              and latest(probe, topics.BIT_WOB) == 0.0, 30.0)
        response = call(ros, probe, False)
        assert response.success, response.message
        assert ros.spin_until(lambda: latest(probe, topics.BIT_WOB) > 1e3, 60.0)


def test_off_bottom_on_the_lumped_string_is_refused_in_one_line() -> None:
    with ros_context() as ros:
        probe = start(ros, "field_8p5in_shale_lumped")
        response = call(ros, probe, True)
        assert not response.success
        assert "distributed string" in response.message and "\n" not in response.message
