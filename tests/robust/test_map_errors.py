"""drill_sim map: every mistake is one line before any Dask work (no file left at --out),
a wrong --scheduler ends within its timeout, --out is locked for the run and its lock file
goes when the map ends, a failing controller is one line, the estimate and the rate are
measured, Ctrl-C keeps the points and says so on stderr."""

from __future__ import annotations

import contextlib
import http.server
import os
import queue
import signal
import socket
import subprocess
import sys
import threading
import time
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from drill_sim_ros.model.presets import load_preset
from drill_sim_ros.study import engine, progress, scheduler_probe, store
from drill_sim_ros.study.grid import Axis, Control, MapSpec, Numerics
from tests.robust.helpers import FAULTY, ROOT, one_error_line, run_cli

MAP = ("map", "--tau-end", "1", "--workers", "1")


@pytest.mark.parametrize(("vary", "names"), [
    ("omega0=-5:-1:3", ("omega0=-5", "'omega0' = -5.0", "[0, 10000]")),
    ("psi=0,-1", ("psi=0", "'psi' = 0.0", "(0, 1e+07]")),
    ("n=0.2,1e9", ("n:", "0.2", "not a whole number")),      # never rounded (to 0)
    ("n=2.5,3", ("n:", "2.5", "not a whole number")),        # never rounded (to 2)
    ("n=1:6:4", ("n:", "2.66667", "not a whole number")),    # 1, 2.67, 4.33, 6
    ("n=1,1e9", ("n=1e+09", "'n' = 1000000000", "[1, 64]")),
    ("beta=1e308,2", ("beta=1e+308", "[0, 10]")),
])
def test_axis_values_out_of_range_are_refused_on_the_client(capsys, tmp_path: Path,
                                                           vary: str, names: tuple) -> None:
    out = tmp_path / "map.nc"
    rc, stdout, err = run_cli(capsys, *MAP, "--vary", vary, "--out", str(out))
    one_error_line(rc, err, "--vary", *names)
    assert stdout == "" and not out.exists()


def test_a_corner_of_two_axes_is_checked(capsys, tmp_path: Path) -> None:
    # each axis alone is fine at the base case; W0 = ratio x lam = 300 x 100 is not
    out = tmp_path / "map.nc"
    rc, _, err = run_cli(capsys, *MAP, "--vary", "lam=1,100", "--vary", "w0_ratio=1,300",
                         "--out", str(out))
    one_error_line(rc, err, "lam=100, w0_ratio=300", "'w0' = 30000")
    assert not out.exists()


def test_a_map_larger_than_the_bound_is_refused_before_any_work(capsys,
                                                                 tmp_path: Path) -> None:
    out = tmp_path / "map.nc"
    rc, _, err = run_cli(capsys, *MAP, "--vary", "beta=0.1:0.5:1001", "--vary",
                         "psi=10:100:1000", "--out", str(out))
    one_error_line(rc, err, "--vary", "1,001,000 points", "1,001 x 1,000",
                   "at most 1,000,000")
    assert not out.exists()


@pytest.mark.parametrize(("scheduler", "names"), [
    ("bogus", ("'bogus'", "tcp://HOST:PORT")),
    ("http://127.0.0.1:8787/status", ("http://", "web address")),
    ("tcp://127.0.0.1:99999", ("tcp://HOST:PORT",)),
])
def test_a_malformed_scheduler_address_is_one_line(capsys, tmp_path: Path, scheduler: str,
                                                  names: tuple) -> None:
    out = tmp_path / "map.nc"
    rc, _, err = run_cli(capsys, *MAP, "--vary", "beta=0.1,0.2", "--out", str(out),
                         "--scheduler", scheduler)
    one_error_line(rc, err, "--scheduler", *names)
    assert not out.exists()


@pytest.fixture
def silent_listener() -> Iterator[str]:
    """A TCP port that accepts connections and never says a word."""
    with socket.socket() as server:
        server.bind(("127.0.0.1", 0))
        server.listen(8)
        yield f"tcp://127.0.0.1:{server.getsockname()[1]}"


@pytest.fixture
def http_server() -> Iterator[str]:
    """A real HTTP server on 127.0.0.1 (it answers requests; it never speaks first)."""
    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0),
                                             http.server.SimpleHTTPRequestHandler)
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    try:
        yield f"tcp://127.0.0.1:{server.server_address[1]}"
    finally:
        server.shutdown()
        server.server_close()


@pytest.mark.parametrize("server", ["silent_listener", "http_server"])
def test_a_server_that_is_not_a_scheduler_ends_within_the_timeout(
        capsys, monkeypatch, request, tmp_path: Path, server: str) -> None:
    address = request.getfixturevalue(server)
    monkeypatch.setattr(scheduler_probe, "PROBE_TIMEOUT_S", 1.0)
    out = tmp_path / "map.nc"
    start = time.monotonic()
    rc, _, err = run_cli(capsys, *MAP, "--vary", "beta=0.1,0.2", "--out", str(out),
                         "--scheduler", address)
    one_error_line(rc, err, address, "sent nothing in 1 s", "not a Dask scheduler")
    assert time.monotonic() - start < 30        # not distributed's own wait (> 150 s)
    assert not out.exists()


def test_a_refused_connection_is_one_line(capsys, tmp_path: Path) -> None:
    with socket.socket() as probe:                 # a free port, closed again
        probe.bind(("127.0.0.1", 0))
        port = probe.getsockname()[1]
    rc, _, err = run_cli(capsys, *MAP, "--vary", "beta=0.1,0.2", "--out",
                         str(tmp_path / "m.nc"), "--scheduler", f"127.0.0.1:{port}")
    one_error_line(rc, err, f"127.0.0.1:{port}", "cannot connect")


@pytest.mark.parametrize("vary", ["beta=0.1,0.2", "beta=0.1,0.2,0.3"])
def test_out_in_use_by_another_map_is_refused_at_start(capsys, tmp_path: Path,
                                                      vary: str) -> None:
    out = tmp_path / "map.nc"
    out.write_bytes(b"the other run's map")
    holder = subprocess.Popen([sys.executable, "-c", "import sys, time\n"
                               "from pathlib import Path\n"
                               "from drill_sim_ros.study.store import map_lock\n"
                               "with map_lock(Path(sys.argv[1])):\n"
                               "    print('held', flush=True); time.sleep(60)\n", str(out)],
                              stdout=subprocess.PIPE, text=True, cwd=ROOT)
    try:
        assert holder.stdout.readline().strip() == "held"
        rc, _, err = run_cli(capsys, *MAP, "--vary", vary, "--out", str(out))
        one_error_line(rc, err, str(out), "in use by another drill_sim map",
                       f"pid {holder.pid}")
        assert out.read_bytes() == b"the other run's map"
    finally:
        holder.kill()
        holder.wait(timeout=10)
    with store.map_lock(out):                   # released when its holder died
        pass


def test_the_lock_file_goes_when_a_map_ends(capsys, tmp_path: Path) -> None:
    out = tmp_path / "map.nc"
    rc, _, err = run_cli(capsys, *MAP, "--vary", "beta=0.2,0.4", "--out", str(out))
    assert rc == 0, err
    assert out.exists() and not store.lock_path(out).exists()


def test_an_interrupted_map_says_so_on_stderr_and_its_lock_file_goes(
        capsys, monkeypatch, tmp_path: Path) -> None:
    """Ctrl-C while the map runs (KeyboardInterrupt out of run_map, no cluster needed)."""
    out = tmp_path / "map.nc"
    held = []

    def interrupted(*_args, **_kwargs):
        held.append(store.lock_path(out).exists())
        raise KeyboardInterrupt

    monkeypatch.setattr(engine, "connect", lambda *_args: contextlib.nullcontext(None))
    monkeypatch.setattr(engine, "run_map", interrupted)
    rc, stdout, err = run_cli(capsys, *MAP, "--vary", "beta=0.2,0.4", "--out", str(out))
    assert rc == 130 and held == [True]
    assert stdout == ""
    assert err.strip().splitlines()[-1] == (
        "drill_sim map: interrupted; no point was done; re-run the same command to resume")
    assert not store.lock_path(out).exists()


@pytest.mark.parametrize("ending", [None, KeyboardInterrupt, RuntimeError])
def test_map_lock_removes_its_file_however_the_block_ends(tmp_path: Path, ending) -> None:
    out = tmp_path / "map.nc"
    with contextlib.ExitStack() as stack:
        if ending is not None:
            stack.enter_context(pytest.raises(ending))
        with store.map_lock(out):
            assert store.lock_path(out).read_text() == f"pid {os.getpid()}"
            if ending is not None:
                raise ending
    assert not store.lock_path(out).exists()
    with store.map_lock(out):                   # and the next run takes it
        pass


def test_a_lock_taken_on_a_file_its_holder_removed_is_taken_again(tmp_path: Path,
                                                                   monkeypatch) -> None:
    """A second map opens the lock file, then the first ends (removes it, lets go) before the
    second locks it: the second must lock the file the name holds, or a third map could lock
    a new file and run beside it."""
    out = tmp_path / "map.nc"
    lock = store.lock_path(out)
    real_flock = store.fcntl.flock
    removed = []

    def flock_after_the_holder_ended(stream, operation):
        if not removed:                         # the first attempt: the holder ends now
            lock.unlink()
            removed.append(stream.name)
        return real_flock(stream, operation)

    lock.write_text("pid 1")
    monkeypatch.setattr(store.fcntl, "flock", flock_after_the_holder_ended)
    with store.map_lock(out):
        assert removed and lock.exists()
        assert lock.read_text() == f"pid {os.getpid()}"
    assert not lock.exists()


def test_the_rate_is_measured_from_the_start() -> None:
    clock = iter([100.0, 110.0, 120.0])
    bar = progress.MapProgress(enabled=False)
    shown: list[str] = []
    bar.line.show = shown.append                # type: ignore[method-assign]
    real = progress.time.perf_counter
    progress.time.perf_counter = lambda: next(clock)
    try:
        bar(0, 100, 0.0)          # the engine's call at the start
        bar(20, 100, 10.0)        # two tasks of 10 points arriving together after 10 s
        bar(40, 100, 20.0)
    finally:
        progress.time.perf_counter = real
    assert "2.00 points/s" in shown[-1] and "eta     30 s" in shown[-1]
    assert engine.estimate_line(20, 100, 10.0).startswith(
        "drill_sim map: the first 20 points took 10.0 s (2 points/s): about 40 s for the "
        "other 80")
    assert "about 5.8 days" in engine.estimate_line(5, 2_500_005, 1.0)


@pytest.fixture(scope="module")
def client():
    with engine.connect(workers=1) as dask_client:
        yield dask_client


def test_a_map_prints_its_size_and_a_measured_estimate(client, tmp_path: Path) -> None:
    spec = MapSpec(load_preset("fig5_8a").params, (Axis("beta", (0.2, 0.3, 0.4)),),
                   Numerics(tau_end=1.0, average_from=0.5))
    lines: list[str] = []
    run = engine.run_map(spec, tmp_path / "m.nc", client, batch=1, log=lines.append)
    assert run.computed == 3 and len(lines) == 2, lines
    assert lines[0] == "drill_sim map: 3 points (3), 3 to compute in tasks of 1 on 1 workers"
    assert lines[1].startswith("drill_sim map: the first 1 points took ")


def test_a_failing_controller_in_a_map_is_one_line_and_leaves_no_file(client,
                                                                     tmp_path: Path) -> None:
    preset = load_preset("field_8p5in_shale")
    spec = MapSpec(preset.params, (Axis("surface_rpm", (50.0, 60.0)),),
                   Numerics(tau_end=2.0 / preset.scales.time_s, average_from=0.0),
                   scales=preset.scales, preset=preset.name,
                   control=Control(f"{ROOT}/{FAULTY}:RaisesInStep"))
    out = tmp_path / "m.nc"
    with pytest.raises(engine.DrillSimError) as caught:
        engine.run_map(spec, out, client, batch=1)
    message = str(caught.value)
    assert "\n" not in message and "RaisesInStep" in message and "t = 0.500 s" in message
    assert "step exploded" in message and not out.exists()


def test_ctrl_c_keeps_the_points_done(tmp_path: Path) -> None:
    out = tmp_path / "m.nc"
    process = subprocess.Popen(
        [sys.executable, "-m", "drill_sim_ros.cli", "map", "--params", "fig5_8a", "--vary",
         "beta=0.1:0.5:200", "--tau-end", "100", "--workers", "1", "--batch", "1",
         "--out", str(out)], cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
        text=True)
    lines: queue.Queue[str] = queue.Queue()
    reader = threading.Thread(target=lambda: [lines.put(x) for x in process.stderr],
                              daemon=True)
    reader.start()
    seen = []
    while not any(x.startswith("drill_sim map: the first 1 points") for x in seen):
        seen.append(lines.get(timeout=120))      # the size line, then the first result
    assert seen[0].startswith("drill_sim map: 200 points"), seen
    process.send_signal(signal.SIGINT)
    process.wait(timeout=60)                    # (its stdout is a line at most)
    reader.join(timeout=10)                     # stderr is the reader's alone, to its end
    stdout = process.stdout.read()
    err = "".join(seen) + "".join(lines.queue)
    assert process.returncode == 130, err
    assert "Traceback" not in err
    assert stdout == ""
    assert err.strip().splitlines()[-1] == (
        f"drill_sim map: interrupted; the points done are kept in {out}; re-run the same "
        "command to resume")
    done = xr.load_dataset(out)["done"].values
    assert 1 <= int(np.sum(done)) < 200
    assert not store.lock_path(out).exists()
