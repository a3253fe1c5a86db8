"""The fan-out of recording streams and the viewer link's checks, without ROS.

The fan-out writes two real .rrd files (one stream detached half-way) read back by rerun's
reader; the link probes a real TCP listener on loopback that the test closes and reopens.
"""

from __future__ import annotations

import socket
import threading
import time
from pathlib import Path

import numpy as np
import rerun as rr

from drill_sim_ros.viz import entities as ent
from drill_sim_ros.viz.dashboard import Dashboard
from drill_sim_ros.viz.paper_units import PaperUnits
from drill_sim_ros.viz.recording import Recordings, close_recording
from drill_sim_ros.viz.telemetry import TelemetryBatch
from drill_sim_ros.viz.viewer_link import CHECK_PERIOD_S, Progress, ViewerLink
from tests.viz.rrd_read import read_recording
from tests.viz.sim_telemetry import default_rows


def _file_stream(path: Path) -> rr.RecordingStream:
    stream = rr.RecordingStream(ent.APP_ID, recording_id="one-recording")
    stream.set_sinks(rr.FileSink(str(path)))
    return stream


def test_a_detached_stream_misses_what_follows_and_the_other_keeps_everything(tmp_path):
    rows = default_rows(4.0)
    half = len(rows) // 2
    kept, cut = _file_stream(tmp_path / "kept.rrd"), _file_stream(tmp_path / "cut.rrd")
    recordings = Recordings(kept, cut)
    dashboard = Dashboard(recordings, PaperUnits.load("field_8p5in_shale_lumped"))
    dashboard.log_batch(TelemetryBatch.from_rows(rows[:half]))
    recordings.detach(cut)
    close_recording(cut)
    dashboard.log_batch(TelemetryBatch.from_rows(rows[half:]))
    close_recording(kept)
    t_ns = rows[:, 0] * 1e9
    kept_data = read_recording(tmp_path / "kept.rrd")
    cut_data = read_recording(tmp_path / "cut.rrd")
    np.testing.assert_allclose(kept_data[ent.ROP].time_ns, t_ns, rtol=0, atol=1)
    np.testing.assert_allclose(cut_data[ent.ROP].time_ns, t_ns[:half], rtol=0, atol=1)
    assert kept_data[ent.ROP].static and cut_data[ent.ROP].static     # series styles in both


class _Stream:
    """What the link does to a viewer's stream: attach, flush, disconnect."""

    def __init__(self) -> None:
        self.disconnected = False

    def flush(self, timeout_sec: float) -> None:
        pass

    def disconnect(self) -> None:
        self.disconnected = True


class _Logger:
    def __init__(self) -> None:
        self.lines: list[tuple[str, str]] = []

    def warning(self, text: str) -> None:
        self.lines.append(("warning", text))

    def info(self, text: str) -> None:
        self.lines.append(("info", text))


def _listener(port: int = 0) -> socket.socket:
    sock = socket.socket()
    sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
    sock.bind(("127.0.0.1", port))
    sock.listen()
    return sock


def _let_go(link: ViewerLink, timeout_s: float = 5.0) -> bool:
    """Until the stream let go is disconnected (a daemon thread does it; bounded)."""
    deadline = time.monotonic() + timeout_s
    while link.closing() and time.monotonic() < deadline:
        time.sleep(0.01)
    return not link.closing()


def test_the_link_cuts_once_and_reconnects_with_the_gap_named() -> None:
    viewer = _listener()
    port = viewer.getsockname()[1]
    url = f"rerun+http://127.0.0.1:{port}/proxy"
    opened: list[_Stream] = []
    recordings, logger = Recordings(), _Logger()
    link = ViewerLink(url, recordings, lambda: opened.append(_Stream()) or opened[-1],
                      logger, "x.rrd continues")
    link.poll(0.0, Progress(0, None))
    assert recordings.streams == opened and len(opened) == 1 and logger.lines == []
    link.poll(0.5 * CHECK_PERIOD_S, Progress(10, 0.1))              # not due: no probe
    link.poll(1.0 * CHECK_PERIOD_S, Progress(100, 1.0))             # still listening
    viewer.close()
    for i, progress in enumerate([Progress(200, 2.0), Progress(300, 3.0), Progress(400, 4.0)]):
        link.poll((2.0 + i) * CHECK_PERIOD_S, progress)
    assert recordings.streams == [] and _let_go(link) and opened[0].disconnected
    assert [kind for kind, _ in logger.lines] == ["warning"]
    assert url in logger.lines[0][1] and "x.rrd continues" in logger.lines[0][1]
    viewer = _listener(port)
    try:
        link.poll(5.0 * CHECK_PERIOD_S, Progress(500, 5.0))
    finally:
        viewer.close()
    assert recordings.streams == [opened[1]] and len(opened) == 2
    kind, text = logger.lines[-1]
    assert kind == "info" and "lacks up to 400 samples" in text          # 500 - 100 seen
    assert "sim_time 1.000 s to 5.000 s" in text
    assert link.close(1.0) is None and _let_go(link) and opened[1].disconnected
    assert recordings.streams == []


def test_no_viewer_at_start_is_one_warning_until_one_listens() -> None:
    port = _listener().getsockname()[1]        # closed again at once: nothing listens there
    logger = _Logger()
    link = ViewerLink(f"rerun+http://127.0.0.1:{port}/proxy", Recordings(), _Stream, logger,
                      "nothing else records it meanwhile")
    for i in range(4):
        link.poll(i * CHECK_PERIOD_S, Progress(i, float(i)))
    assert link.stream is None
    assert [kind for kind, _ in logger.lines] == ["warning"]
    assert "no viewer listening" in logger.lines[0][1]


class _StuckStream(_Stream):
    """A stream whose viewer does not read: flush times out, disconnect waits for ``freed``."""

    def __init__(self) -> None:
        super().__init__()
        self.freed = threading.Event()

    def flush(self, timeout_sec: float) -> None:
        raise RuntimeError("Flush timed out - not all log messages were sent")

    def disconnect(self) -> None:
        self.freed.wait(timeout=30.0)
        super().disconnect()


def test_a_viewer_that_does_not_read_is_cut_and_no_stream_opened_while_it_holds_one() -> None:
    viewer = _listener()
    url = f"rerun+http://127.0.0.1:{viewer.getsockname()[1]}/proxy"
    opened: list[_Stream] = []
    recordings, logger = Recordings(), _Logger()
    link = ViewerLink(url, recordings, lambda: opened.append(_StuckStream()) or opened[-1],
                      logger, "x.rrd continues")
    try:
        link.poll(0.0, Progress(0, None))
        link.poll(CHECK_PERIOD_S, Progress(100, 1.0))        # flush times out: cut
        link.poll(2 * CHECK_PERIOD_S, Progress(200, 2.0))    # still held: no new stream
        assert len(opened) == 1 and recordings.streams == [] and link.closing()
        assert [kind for kind, _ in logger.lines] == ["warning"]
        assert "does not read" in logger.lines[0][1]
        opened[0].freed.set()
        assert _let_go(link)
        link.poll(3 * CHECK_PERIOD_S, Progress(300, 3.0))
        assert len(opened) == 2 and recordings.streams == [opened[1]]
    finally:
        for stream in opened:
            stream.freed.set()
        viewer.close()
