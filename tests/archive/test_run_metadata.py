"""The in-process recorder stores the run's metadata (read back by mcap_to_rerun)."""

from __future__ import annotations

from pathlib import Path

from mcap.reader import make_reader
from rclpy.qos import QoSProfile
from std_msgs.msg import Float64

from drill_sim_ros.archive.inprocess import RUN_METADATA, InProcessRecorder
from drill_sim_ros.viz.mcap_telemetry import recorded_preset


def test_metadata_record_round_trips(tmp_path: Path) -> None:
    path = tmp_path / "run.mcap"
    recorder = InProcessRecorder(str(path), metadata={"preset": "fig5_8a", "dtau": 1e-4})
    recorder.add_topic("/x", "std_msgs/msg/Float64", QoSProfile(depth=10))
    recorder.write("/x", Float64(data=1.0), 5)
    recorder.close()
    with path.open("rb") as stream:
        records = {m.name: m.metadata for m in make_reader(stream).iter_metadata()}
    assert records[RUN_METADATA] == {"preset": "fig5_8a", "dtau": "0.0001"}
    assert recorded_preset(path) == "fig5_8a"


def test_serialized_bytes_are_recorded_unchanged(tmp_path: Path) -> None:
    from rclpy.serialization import serialize_message

    path = tmp_path / "raw.mcap"
    payloads = [serialize_message(Float64(data=float(i))) for i in range(50)]
    recorder = InProcessRecorder(str(path), log_time_origin_ns=0)
    recorder.add_topic("/x", "std_msgs/msg/Float64", QoSProfile(depth=10))
    for i, data in enumerate(payloads):
        recorder.write_serialized("/x", data, 1000 + i)
    recorder.write_serialized("/undeclared", payloads[0], 0)
    recorder.close()
    assert recorder.dropped == 1
    with path.open("rb") as stream:
        stored = [(m.log_time, m.data) for _, _, m in make_reader(stream).iter_messages()]
    assert stored == [(1000 + i, data) for i, data in enumerate(payloads)]
