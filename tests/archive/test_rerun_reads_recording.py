"""rerun's own MCAP reader (rr.chunk.McapReader) opens a recording and decodes every topic."""

from __future__ import annotations

from collections import Counter
from pathlib import Path

import rerun as rr
from rclpy.qos import QoSProfile
from sensor_msgs.msg import JointState
from std_msgs.msg import Float64

from drill_sim_ros import topics
from drill_sim_ros.archive.inprocess import InProcessRecorder

COUNT = 25


def _record(path: Path) -> None:
    recorder = InProcessRecorder(str(path))
    recorder.add_topic(topics.BIT_WOB, topics.MSG_TYPES[topics.BIT_WOB], QoSProfile(depth=10))
    recorder.add_topic(topics.BIT_JOINT_STATES, topics.MSG_TYPES[topics.BIT_JOINT_STATES],
                       QoSProfile(depth=10))
    for i in range(COUNT):
        t_ns = i * 10_000_000
        recorder.write(topics.BIT_WOB, Float64(data=1000.0 + i), t_ns)
        joints = JointState(name=list(topics.BIT_JOINTS), position=[0.1 * i, 2.0],
                            velocity=[6.0, 1e-3], effort=[3000.0, 1000.0 + i])
        joints.header.stamp.sec, joints.header.stamp.nanosec = divmod(t_ns, 1_000_000_000)
        recorder.write(topics.BIT_JOINT_STATES, joints, t_ns)
    recorder.close()


def test_rerun_decodes_every_recorded_message(tmp_path: Path) -> None:
    path = tmp_path / "run.mcap"
    _record(path)
    rows: Counter[str] = Counter()
    efforts: list[float] = []
    for chunk in rr.chunk.McapReader(path).stream().to_chunks():
        if chunk.is_static:
            continue
        batch = chunk.to_record_batch()
        rows[chunk.entity_path] += batch.num_rows
        if chunk.entity_path == f"{topics.BIT_JOINT_STATES}/effort":
            efforts += [v[1] for v in batch.column("Scalars:scalars").to_pylist()]
    assert rows[topics.BIT_WOB] == COUNT
    assert rows[f"{topics.BIT_JOINT_STATES}/effort"] == COUNT
    assert sorted(efforts) == [1000.0 + i for i in range(COUNT)]     # WOB round-trips
