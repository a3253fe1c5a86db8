"""Damaged files made here: flipped bytes inside one chunk, a broken length field, a non-ROS
MCAP. Readers and mcap_reindex keep every message of every intact chunk and say what they
skipped; mcap_reindex never touches its input unless asked."""

from __future__ import annotations

import os
import subprocess

import pytest
from mcap.reader import make_reader
from mcap.writer import Writer
from rclpy.serialization import deserialize_message
from std_msgs.msg import Float64

from drill_sim_ros.archive.reader import ArchiveReader
from drill_sim_ros.archive.reindex import reindex
from tests.archive.helpers import BIN, counts_mcap_ros2, counts_rosbags, write_float64_run

MS = 1_000_000
TOPIC = "/drill/bit/wob"
COUNT = 10_000            # 10 s at 1 kHz: twenty 0.5 s chunks
DAMAGED_CHUNK = 10


@pytest.fixture
def recording(tmp_path):
    return write_float64_run(tmp_path / "run.mcap", TOPIC, COUNT, MS)


def _chunks(path):
    """The chunk indexes, as mcap's own reader sees them in the intact file."""
    with path.open("rb") as stream:
        return sorted(make_reader(stream).get_summary().chunk_indexes,
                      key=lambda c: c.chunk_start_offset)


def _damaged_copy(path, offset: int, size: int = 64, name: str = "damaged.mcap"):
    data = bytearray(path.read_bytes())
    data[offset:offset + size] = bytes(b ^ 0xFF for b in data[offset:offset + size])
    target = path.with_name(name)
    target.write_bytes(bytes(data))
    return target


def _values(reader: ArchiveReader) -> list[int]:
    return [int(deserialize_message(m.data, Float64).data) for m in reader.messages()]


def _outside(chunk) -> list[int]:
    return [i for i in range(COUNT)
            if not chunk.message_start_time <= i * MS <= chunk.message_end_time]


def _run(*argv: str) -> subprocess.CompletedProcess:
    return subprocess.run([str(BIN / argv[0]), *argv[1:]], capture_output=True, text=True,
                          timeout=60, env=os.environ.copy())


def test_bytes_flipped_inside_one_chunk_lose_that_chunk_only(recording) -> None:
    chunks = _chunks(recording)
    assert len(chunks) == 20
    chunk = chunks[DAMAGED_CHUNK]
    damaged = _damaged_copy(recording, chunk.chunk_start_offset + chunk.chunk_length // 2)
    reader = ArchiveReader(damaged)
    expected = _outside(chunk)
    assert _values(reader) == expected
    assert reader.lost_data and len(reader.damage) == 1
    lost = COUNT - len(expected)
    problem = reader.problem
    assert f"{lost} messages" in problem and f"{chunk.chunk_start_offset}-" in problem
    assert f"log time {chunk.message_start_time / 1e9:.3f}" in problem


def test_a_broken_length_field_is_skipped_up_to_the_next_intact_chunk(recording) -> None:
    chunk = _chunks(recording)[DAMAGED_CHUNK]
    damaged = _damaged_copy(recording, chunk.chunk_start_offset + 1, size=8)  # the u64 length
    reader = ArchiveReader(damaged)
    assert _values(reader) == _outside(chunk)
    assert reader.lost_data and "unreadable record" in reader.problem


def test_reindex_of_a_damaged_file_keeps_every_intact_chunk(recording, tmp_path) -> None:
    chunk = _chunks(recording)[DAMAGED_CHUNK]
    damaged = _damaged_copy(recording, chunk.chunk_start_offset + chunk.chunk_length // 2)
    before = damaged.read_bytes()
    done = _run("mcap_reindex", str(damaged))
    assert done.returncode == 1, done.stderr
    assert "skipped" in done.stderr and "Traceback" not in done.stderr
    assert damaged.read_bytes() == before                    # the input is untouched
    out = damaged.with_name("damaged.reindexed.mcap")
    expected = {TOPIC: len(_outside(chunk))}
    assert counts_mcap_ros2(out) == expected and counts_rosbags(out) == expected
    again = _run("mcap_reindex", str(damaged))              # the output exists now
    assert again.returncode == 2 and "--overwrite" in again.stderr
    assert counts_mcap_ros2(out) == expected


def test_reindex_of_an_intact_file_exits_zero_and_refuses_to_write_onto_it(recording) -> None:
    done = _run("mcap_reindex", str(recording), "-o", str(recording))
    assert done.returncode == 2 and "--in-place" in done.stderr
    done = _run("mcap_reindex", str(recording))
    assert done.returncode == 0, done.stderr
    assert counts_mcap_ros2(recording.with_name("run.reindexed.mcap")) == {TOPIC: COUNT}


def _json_mcap(path, profile: str) -> None:
    with path.open("wb") as stream:
        writer = Writer(stream)
        writer.start(profile=profile, library="test")
        schema = writer.register_schema("Reading", "jsonschema", b'{"type": "object"}')
        channel = writer.register_channel("/sensor", "json", schema)
        for i in range(100):
            writer.add_message(channel, i * MS, b'{"value": %d}' % i, i * MS)
        writer.finish()


@pytest.mark.parametrize("profile", ["", "ros2"])
def test_reindex_refuses_a_non_ros_mcap_and_leaves_it_alone(tmp_path, profile) -> None:
    path = tmp_path / "sensor.mcap"
    _json_mcap(path, profile)
    before = path.read_bytes()
    for args in ([], ["--in-place"]):
        done = _run("mcap_reindex", str(path), *args)
        assert done.returncode == 2 and "not a ROS 2 recording" in done.stderr
        assert path.read_bytes() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["sensor.mcap"]


def test_reindex_api_refuses_non_ros_input(tmp_path) -> None:
    path = tmp_path / "sensor.mcap"
    _json_mcap(path, "")
    with pytest.raises(Exception, match="not a ROS 2 recording"):
        reindex(path, tmp_path / "out.mcap")


def test_replay_refuses_a_non_ros_file_and_an_offset_past_the_end(tmp_path,
                                                                 recording) -> None:
    path = tmp_path / "sensor.mcap"
    _json_mcap(path, "")
    done = _run("mcap_replay", str(path))
    assert done.returncode == 2 and "not a ROS 2 recording" in done.stderr
    done = _run("mcap_replay", str(recording), "--start-offset", "100")
    assert done.returncode == 2 and "past the end" in done.stderr
    assert len(done.stderr.strip().splitlines()) == 1


@pytest.mark.ros
def test_replay_of_a_damaged_chunk_goes_on_after_it(recording) -> None:
    chunk = _chunks(recording)[DAMAGED_CHUNK]
    damaged = _damaged_copy(recording, chunk.chunk_start_offset + chunk.chunk_length // 2)
    done = _run("mcap_replay", str(damaged), "--rate", "100", "--delay", "0")
    assert done.returncode == 1, done.stderr
    assert "skipped bytes" in done.stderr and "Traceback" not in done.stderr
    assert f"sent {len(_outside(chunk))} messages" in done.stderr
