"""mcap_to_rerun on damaged recordings and existing outputs: it converts what mcap_reindex
would keep, warns once, exits 1 when samples were lost, and never leaves a partial .rrd."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from mcap.reader import make_reader
from rclpy.serialization import serialize_message
from std_msgs.msg import Float64MultiArray, MultiArrayDimension

from drill_sim_ros import topics
from drill_sim_ros.archive.writer import Ros2McapWriter
from drill_sim_ros.viz import mcap_to_rerun
from tests.viz.rrd_read import read_recording
from tests.viz.sim_telemetry import default_rows

SECONDS = 10.0                  # 100 Hz: 1000 samples in twenty 0.5 s chunks
SAMPLES_PATH = "/timeseries/rop/bit"


def run_cli(*args: str) -> subprocess.CompletedProcess:
    exe = Path(sys.prefix) / "bin" / "mcap_to_rerun"
    return subprocess.run([str(exe), *args], capture_output=True, text=True, timeout=120)


@pytest.fixture(scope="module")
def recording(tmp_path_factory) -> tuple[Path, np.ndarray]:
    rows = default_rows(SECONDS)
    path = tmp_path_factory.mktemp("faults") / "run.mcap"
    label = ",".join(topics.TELEMETRY_FIELDS)
    with Ros2McapWriter(str(path)) as writer:
        writer.add_metadata("drill_sim", {"preset": "field_8p5in_shale_lumped"})   # as sim_node's
        channel = writer.add_channel(topics.TELEMETRY, "std_msgs/msg/Float64MultiArray")
        for row in rows:
            msg = Float64MultiArray(data=[float(v) for v in row])
            msg.layout.dim = [MultiArrayDimension(label=label, size=len(row), stride=len(row))]
            writer.write(channel, serialize_message(msg), round(row[0] * 1e9))
    return path, rows


def _chunks(path: Path):
    with path.open("rb") as stream:
        return sorted(make_reader(stream).get_summary().chunk_indexes,
                      key=lambda c: c.chunk_start_offset)


def _log_times_ns(rows: np.ndarray) -> np.ndarray:
    return np.array([round(t * 1e9) for t in rows[:, 0]], dtype=np.int64)


def _sample_times_ns(rrd: Path) -> np.ndarray:
    return read_recording(rrd)[SAMPLES_PATH].time_ns


def _leftovers(directory: Path) -> list[str]:
    return sorted(p.name for p in directory.iterdir() if "partial" in p.name)


def test_a_cut_recording_converts_its_intact_chunks(recording, tmp_path) -> None:
    path, rows = recording
    chunks = _chunks(path)
    cut_at = chunks[12].chunk_start_offset + chunks[12].chunk_length // 2
    cut = tmp_path / "cut.mcap"
    cut.write_bytes(path.read_bytes()[:cut_at])
    rrd = tmp_path / "cut.rrd"
    done = run_cli(str(cut), "-o", str(rrd))
    assert done.returncode == 1, done.stderr
    assert "Traceback" not in done.stderr and done.stderr.count("warning") == 1
    times = _log_times_ns(rows)
    kept = times < chunks[12].message_start_time
    np.testing.assert_allclose(_sample_times_ns(rrd), times[kept], atol=1.0)


def test_flipped_bytes_lose_one_chunk_of_samples(recording, tmp_path) -> None:
    path, rows = recording
    chunk = _chunks(path)[7]
    data = bytearray(path.read_bytes())
    middle = chunk.chunk_start_offset + chunk.chunk_length // 2
    data[middle:middle + 64] = bytes(64)
    damaged = tmp_path / "damaged.mcap"
    damaged.write_bytes(bytes(data))
    rrd = tmp_path / "damaged.rrd"
    done = run_cli(str(damaged), "-o", str(rrd))
    assert done.returncode == 1 and "skipped bytes" in done.stderr, done.stderr
    times = _log_times_ns(rows)
    kept = (times < chunk.message_start_time) | (times > chunk.message_end_time)
    np.testing.assert_allclose(_sample_times_ns(rrd), times[kept], atol=1.0)


def test_a_cut_footer_loses_nothing(recording, tmp_path) -> None:
    path, rows = recording
    cut = tmp_path / "nofooter.mcap"
    cut.write_bytes(path.read_bytes()[:-20])
    rrd = tmp_path / "nofooter.rrd"
    done = run_cli(str(cut), "-o", str(rrd))
    assert done.returncode == 0, done.stderr
    assert "summary section" in done.stderr
    assert len(_sample_times_ns(rrd)) == len(rows)


@pytest.mark.parametrize("content", [b"", b"\x89MCAP0\r\n" + bytes(range(256)) * 40,
                                     b"not an mcap" * 100])
def test_garbage_is_one_line_and_no_rrd(tmp_path, content) -> None:
    bad = tmp_path / "bad.mcap"
    bad.write_bytes(content)
    rrd = tmp_path / "bad.rrd"
    done = run_cli(str(bad), "-o", str(rrd))
    assert done.returncode in (1, 2) and "Traceback" not in done.stderr
    assert len(done.stderr.strip().splitlines()) == 1, done.stderr
    assert not rrd.exists() and _leftovers(tmp_path) == []


def test_an_existing_rrd_is_kept_unless_overwrite(recording, tmp_path) -> None:
    path, rows = recording
    rrd = tmp_path / "run.rrd"
    rrd.write_bytes(b"earlier view")
    done = run_cli(str(path), "-o", str(rrd))
    assert done.returncode == 2 and "--overwrite" in done.stderr
    assert rrd.read_bytes() == b"earlier view"
    done = run_cli(str(path), "-o", str(rrd), "--overwrite")
    assert done.returncode == 0, done.stderr
    assert len(_sample_times_ns(rrd)) == len(rows)


def test_an_interrupted_conversion_leaves_nothing(recording, tmp_path, monkeypatch) -> None:
    """SIGINT, SIGTERM and SIGHUP all arrive as KeyboardInterrupt (archive.signals)."""
    path, _ = recording

    def interrupted(self, batch) -> None:
        raise KeyboardInterrupt("SIGTERM")

    monkeypatch.setattr(mcap_to_rerun.Dashboard, "log_batch", interrupted)
    rrd = tmp_path / "run.rrd"
    assert mcap_to_rerun.main([str(path), "-o", str(rrd)]) == 130
    assert not rrd.exists() and _leftovers(tmp_path) == []
