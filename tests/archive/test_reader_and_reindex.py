"""Damaged files: truncated, random bytes, missing. Clear errors, readable parts, no hangs."""

from __future__ import annotations

import os
import random
import subprocess

import pytest
from std_msgs.msg import Float64

from drill_sim_ros.archive.errors import ArchiveNotFoundError, NotAnArchiveError
from drill_sim_ros.archive.reader import ArchiveReader
from drill_sim_ros.archive.reindex import reindex
from tests.archive.helpers import (
    BIN,
    counts_mcap_ros2,
    counts_rosbags,
    statistics_counts,
    write_float64_run,
)

MS = 1_000_000
TOPIC = "/drill/bit/wob"
COUNT = 3000  # 3 s at 1 kHz: six 0.5 s chunks


@pytest.fixture
def finished(tmp_path):
    return write_float64_run(tmp_path / "run.mcap", TOPIC, COUNT, MS)


def _cut(path, size: int, name: str = "cut.mcap"):
    target = path.with_name(name)
    target.write_bytes(path.read_bytes()[:size])
    return target


def _values(reader: ArchiveReader) -> list[int]:
    from rclpy.serialization import deserialize_message

    return [int(deserialize_message(m.data, Float64).data) for m in reader.messages()]


def test_finished_file_reads_completely_without_a_problem(finished) -> None:
    reader = ArchiveReader(finished)
    assert _values(reader) == list(range(COUNT))
    assert reader.problem is None and reader.summary() is not None


def test_truncated_file_yields_whole_chunks_in_order_and_warns(finished, caplog) -> None:
    cut = _cut(finished, finished.stat().st_size // 2)
    reader = ArchiveReader(cut)
    values = _values(reader)
    assert values == list(range(len(values))) and 0 < len(values) < COUNT
    assert len(values) % 501 == 0  # whole chunks only (501 messages span 0.5 s)
    assert "truncated" in reader.problem and "mcap_reindex" in reader.problem
    assert reader.summary() is None
    assert any("truncated" in r.message for r in caplog.records)


def test_file_cut_inside_its_summary_keeps_every_message(finished) -> None:
    cut = _cut(finished, finished.stat().st_size - 30)
    reader = ArchiveReader(cut)
    assert len(_values(reader)) == COUNT and "summary section" in reader.problem


def test_missing_random_and_empty_files_raise_clear_errors(tmp_path) -> None:
    with pytest.raises(ArchiveNotFoundError, match="no such file"):
        ArchiveReader(tmp_path / "absent.mcap")
    noise = tmp_path / "noise.mcap"
    noise.write_bytes(random.Random(1).randbytes(100_000))
    with pytest.raises(NotAnArchiveError, match="not an MCAP file"):
        ArchiveReader(noise)
    empty = tmp_path / "empty.mcap"
    empty.write_bytes(b"")
    with pytest.raises(NotAnArchiveError, match="empty"):
        ArchiveReader(empty)


def test_random_bytes_after_a_valid_start_are_reported_not_raised(finished) -> None:
    data = finished.read_bytes()
    damaged = finished.with_name("damaged.mcap")
    damaged.write_bytes(data[:30_000] + random.Random(2).randbytes(len(data)))
    reader = ArchiveReader(damaged)
    values = _values(reader)
    assert values == list(range(len(values)))
    assert reader.problem is not None


def test_reindex_restores_summary_and_statistics(finished, tmp_path) -> None:
    cut = _cut(finished, finished.stat().st_size * 2 // 3)
    readable = len(_values(ArchiveReader(cut)))
    out = tmp_path / "reindexed.mcap"
    result = reindex(cut, out)
    assert result.messages == readable and "truncated" in result.problem
    counts = {TOPIC: readable}
    assert statistics_counts(out) == counts
    assert counts_mcap_ros2(out) == counts and counts_rosbags(out) == counts
    assert ArchiveReader(out).problem is None


def _run(*argv: str, timeout_s: float = 30) -> subprocess.CompletedProcess:
    return subprocess.run([str(BIN / argv[0]), *argv[1:]], capture_output=True, text=True,
                          timeout=timeout_s, env=os.environ.copy())


def test_reindex_cli_in_place_keeps_the_original_and_reports_the_loss(finished,
                                                                       tmp_path) -> None:
    cut = _cut(finished, finished.stat().st_size // 2)   # inside a chunk: that chunk is lost
    original = cut.read_bytes()
    done = _run("mcap_reindex", str(cut), "--in-place")
    assert done.returncode == 1, done.stderr
    assert "truncated" in done.stderr and "Traceback" not in done.stderr
    assert ArchiveReader(cut).summary() is not None
    assert cut.with_name(cut.name + ".orig").read_bytes() == original
    missing = _run("mcap_reindex", str(tmp_path / "absent.mcap"))
    assert missing.returncode == 2 and "no such file" in missing.stderr


@pytest.mark.parametrize("content", [None, b"", b"not an mcap file at all" * 100])
def test_replay_cli_refuses_missing_or_non_mcap_files(tmp_path, content) -> None:
    path = tmp_path / "bad.mcap"
    if content is not None:
        path.write_bytes(content)
    done = _run("mcap_replay", str(path))
    assert done.returncode == 2
    assert str(path) in done.stderr and "ERROR" in done.stderr
