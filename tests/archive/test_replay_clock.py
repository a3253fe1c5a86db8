"""mcap_replay --clock: one /clock, on the recorded stamps' base, that never jumps (issue 26).

The recording is what mcap_recorder makes of a sim running at twice real time: log times in
the Unix epoch (wall clock), 10 ms apart; the sim's stamps and its recorded /clock start at
5 s and advance 20 ms per sample. The replayed clock must be the log time moved onto the
stamps' base (5 s + 10 ms per sample), from one publisher: were the recorded /clock replayed
beside it, the two would interleave and the clock would jump back and forth.
"""

from __future__ import annotations

import threading

import pytest
from rclpy.qos import QoSProfile
from rclpy.serialization import serialize_message
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import JointState
from std_msgs.msg import Float64

from drill_sim_ros.archive.reader import ArchiveReader
from drill_sim_ros.archive.replay_node import clock_offset_ns
from drill_sim_ros.archive.writer import Ros2McapWriter
from drill_sim_ros.ros.messages import stamp
from tests.archive.helpers import running, stop, wait_for
from tests.archive.ros_fixtures import ros_node

MS = 1_000_000
COUNT = 60
T0_NS = 1_700_000_000 * 1_000_000_000     # wall-clock log time of the first message
SIM0_NS = 5_000 * MS                      # the sim time of the first sample
JOINTS = "/drill/test/joint_states"


def _write(path, with_clock: bool = True, with_header: bool = True) -> None:
    """COUNT samples: a stamped JointState (or a bare Float64) and optionally the /clock."""
    with Ros2McapWriter(str(path)) as writer:
        joints = writer.add_channel(JOINTS, "sensor_msgs/msg/JointState") if with_header \
            else writer.add_channel(JOINTS, "std_msgs/msg/Float64")
        clock = writer.add_channel("/clock", "rosgraph_msgs/msg/Clock") if with_clock else None
        for i in range(COUNT):
            log_ns, sim_ns = T0_NS + i * 10 * MS, SIM0_NS + i * 20 * MS
            if clock is not None:
                writer.write(clock, serialize_message(Clock(clock=stamp(sim_ns))), log_ns)
            if with_header:
                msg = JointState(name=["a"], position=[float(i)])
                msg.header.stamp = stamp(sim_ns)
            else:
                msg = Float64(data=float(i))
            writer.write(joints, serialize_message(msg), log_ns)


@pytest.mark.parametrize(("with_clock", "with_header", "offset_ns"), [
    (True, True, SIM0_NS - T0_NS), (False, True, SIM0_NS - T0_NS), (False, False, 0)],
    ids=["recorded-clock", "header-stamps", "unstamped"])
def test_the_clock_base_comes_from_the_recorded_stamps(tmp_path, with_clock, with_header,
                                                       offset_ns) -> None:
    path = tmp_path / "run.mcap"
    _write(path, with_clock, with_header)
    assert clock_offset_ns(ArchiveReader(path)) == offset_ns


class _ClockListener:
    """Every /clock value received, and how many publishers /clock had while it ran."""

    def __init__(self, node) -> None:
        self.node = node
        self.values_ns: list[int] = []
        self.publishers_seen: set[int] = set()
        self._lock = threading.Lock()
        node.create_subscription(Clock, "/clock", self._on_clock, QoSProfile(depth=1000))
        node.create_subscription(JointState, JOINTS, lambda _msg: None, QoSProfile(depth=1000))

    def _on_clock(self, msg: Clock) -> None:
        with self._lock:
            self.values_ns.append(msg.clock.sec * 1_000_000_000 + msg.clock.nanosec)
        self.publishers_seen.add(self.node.count_publishers("/clock"))


@pytest.mark.ros
def test_replay_clock_is_one_clock_on_the_stamps_base_that_never_jumps(tmp_path) -> None:
    path = tmp_path / "run.mcap"
    _write(path)
    command = ["mcap_replay", str(path), "--clock", "--rate", "2", "--delay", "0.3",
               "--wait-for-subscribers", "20"]
    with ros_node("test_clock_listener") as node:
        listener = _ClockListener(node)
        with running(command, tmp_path / "replay.log") as replay:
            assert wait_for(lambda: replay.poll() is not None, 60), "replay did not end"
            code = stop(replay)
            wait_for(lambda: len(listener.values_ns) >= COUNT, 5)
    log = (tmp_path / "replay.log").read_text()
    assert code == 0, log
    expected = [SIM0_NS + i * 10 * MS for i in range(COUNT)]     # log time on the base
    assert listener.values_ns == expected, log
    steps = [b - a for a, b in zip(listener.values_ns, listener.values_ns[1:], strict=False)]
    assert min(steps) > 0 and max(steps) == 10 * MS               # never back, never a jump
    assert listener.publishers_seen == {1}                        # the recorded one is not
    assert "not replayed" in log
