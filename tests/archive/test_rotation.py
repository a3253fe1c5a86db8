"""Split recordings: numbered, complete files whose counts add up."""

from __future__ import annotations

from rclpy.serialization import serialize_message
from std_msgs.msg import Float64

from drill_sim_ros.archive.rotation import RotatingWriter
from tests.archive.helpers import counts_rosbags, statistics_counts

MS = 1_000_000


def test_split_by_duration_gives_complete_numbered_files(tmp_path) -> None:
    files = RotatingWriter(tmp_path / "run.mcap", split_duration_s=1.0)
    topic = files.add_channel("/drill/bit/wob", "std_msgs/msg/Float64")
    for i in range(2500):  # 2.5 s at 1 kHz -> 3 files
        files.write(topic, serialize_message(Float64(data=float(i))), i * MS)
    files.finish()
    assert [p.name for p in files.paths] == ["run_0000.mcap", "run_0001.mcap", "run_0002.mcap"]
    counts = [statistics_counts(p)["/drill/bit/wob"] for p in files.paths]
    assert counts == [1000, 1000, 500] and files.message_count == 2500
    assert counts_rosbags(files.paths[-1]) == {"/drill/bit/wob": 500}


def test_unsplit_recording_keeps_the_given_name(tmp_path) -> None:
    files = RotatingWriter(tmp_path / "run.mcap")
    files.finish()
    assert files.paths == [tmp_path / "run.mcap"] and statistics_counts(files.paths[0]) == {}
