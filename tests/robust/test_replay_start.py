"""mcap_replay plans from the summary (no pass over the messages, so a large file starts
sending at once); a file without one is still planned by the pass; Ctrl-C while planning
is a clean exit."""

from __future__ import annotations

import logging
import re
from pathlib import Path

import pytest
from mcap.reader import make_reader

from drill_sim_ros.archive import replay_node
from drill_sim_ros.archive.reader import ArchiveReader
from tests.archive.helpers import write_float64_run

TOPIC = "/drill/test/value"
COUNT, PERIOD_NS = 3000, 1_000_000


def _extent_by_mcap(path: Path) -> tuple[int, int]:
    """First and last log time, read by mcap's own reader (independent of the archive's)."""
    with path.open("rb") as stream:
        times = [message.log_time for _, _, message in make_reader(stream).iter_messages()]
    return min(times), max(times)


def test_the_plan_comes_from_the_summary_without_reading_messages(tmp_path, monkeypatch):
    path = write_float64_run(tmp_path / "run.mcap", TOPIC, COUNT, PERIOD_NS)
    reader = ArchiveReader(path)

    def no_pass(*_args, **_kwargs):
        raise AssertionError("the plan read the messages")
    monkeypatch.setattr(reader, "messages", no_pass)
    plan = replay_node.plan(reader, re.compile(".*"))
    assert (plan.first_log_ns, plan.last_log_ns) == _extent_by_mcap(path)
    assert plan.last_log_ns - plan.first_log_ns == (COUNT - 1) * PERIOD_NS
    assert [c.topic for c in plan.channels] == [TOPIC]
    assert reader.message_encodings == {TOPIC: "cdr"}


def test_a_file_without_summary_is_planned_by_the_pass(tmp_path):
    path = write_float64_run(tmp_path / "run.mcap", TOPIC, COUNT, PERIOD_NS)
    data = path.read_bytes()
    summary_start = _summary_offset(data)
    cut = tmp_path / "cut.mcap"
    cut.write_bytes(data[:summary_start])       # the data section only: no summary, no footer
    reader = ArchiveReader(cut)
    assert reader.summary() is None
    plan = replay_node.plan(reader, re.compile(".*"))
    assert (plan.first_log_ns, plan.last_log_ns) == _extent_by_mcap(path)


def _summary_offset(data: bytes) -> int:
    """summary_start of the footer record (MCAP spec: opcode 0x02, length, summary_start,
    summary_offset_start, summary_crc; then the closing magic)."""
    footer = data[-8 - 29:-8]
    assert footer[0] == 0x02
    return int.from_bytes(footer[9:17], "little")


def test_ctrl_c_while_planning_is_a_clean_exit(tmp_path, monkeypatch, caplog):
    path = write_float64_run(tmp_path / "run.mcap", TOPIC, 10, PERIOD_NS)

    def interrupted(*_args):
        raise KeyboardInterrupt
    monkeypatch.setattr(replay_node, "plan", interrupted)
    caplog.set_level(logging.INFO, logger="drill_sim_ros.archive.replay_node")
    assert replay_node.main(["mcap_replay", str(path)]) == 130
    assert any("interrupted while planning" in r.getMessage() for r in caplog.records)


@pytest.mark.parametrize("topics", [".*", f"{TOPIC}"])
def test_the_summary_plan_equals_the_pass(tmp_path, topics):
    path = write_float64_run(tmp_path / "run.mcap", TOPIC, COUNT, PERIOD_NS)
    quick = replay_node.plan(ArchiveReader(path), re.compile(topics))
    slow_reader = ArchiveReader(path)
    first = min(m.log_time_ns for m in slow_reader.messages())
    last = max(m.log_time_ns for m in slow_reader.messages())
    assert (quick.first_log_ns, quick.last_log_ns) == (first, last)
