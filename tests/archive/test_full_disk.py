"""A full disk (a 2 MiB tmpfs): the in-process recorder says so, stops counting messages as
written that never reached the file, keeps what it wrote readable, and never raises."""

from __future__ import annotations

import os

from drill_sim_ros.archive.inprocess import InProcessRecorder
from drill_sim_ros.archive.reader import ArchiveReader
from tests.archive.helpers import wait_for

MS = 1_000_000
TOPIC = "/drill/test/blob"
BLOB_BYTES = 20_000            # incompressible: 100 of them fill the disk


def test_inprocess_recorder_on_a_full_disk(small_disk, caplog) -> None:
    path = small_disk / "run.mcap"
    recorder = InProcessRecorder(str(path), compression="none")
    recorder.add_topic(TOPIC, "std_msgs/msg/UInt8MultiArray")
    sent = 0
    while recorder.error is None and sent < 2000:
        recorder.write_serialized(TOPIC, os.urandom(BLOB_BYTES), sent * 10 * MS)
        sent += 1
        if sent % 50 == 0:
            wait_for(lambda: recorder.backlog == 0, 5)
    assert wait_for(lambda: recorder.error is not None, 10), "the disk never filled"
    assert "No space left on device" in recorder.error and str(path) in recorder.error
    written = recorder.written
    recorder.write_serialized(TOPIC, b"late", sent * 10 * MS)
    assert recorder.written == written                       # nothing more counts as written
    assert recorder.close() is False                         # never raises
    assert recorder.written + recorder.dropped == sent + 1   # every message accounted for
    reader = ArchiveReader(path)
    assert sum(1 for _ in reader.messages()) == written       # the count is what is on disk
    failures = [r for r in caplog.records if "No space left" in r.getMessage()]
    assert [r.levelname for r in failures] == ["ERROR"]      # said once
    assert recorder.summary().startswith("recording incomplete: cannot write")
