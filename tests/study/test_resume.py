"""An interrupted map keeps what is done and completes without recomputing it."""

from __future__ import annotations

import re
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np

from drill_sim_ros.model.errors import DrillSimError
from drill_sim_ros.study import engine, store
from drill_sim_ros.study.grid import Axis, MapSpec
from tests.study.helpers import FIG8A, SHORT, same_maps, small_spec

WAIT_S = 120.0


def test_interrupted_map_resumes_without_recomputing(tmp_path: Path) -> None:
    spec = small_spec()
    out = tmp_path / "map.nc"
    seen = []

    def stop_after_two(done: int, total: int, _s: float) -> None:
        seen.append(done)                          # the first call is the start (0 done)
        if len(seen) == 3:
            raise KeyboardInterrupt                # what Ctrl-C raises in the loop

    with engine.connect(workers=1) as client:
        first = engine.run_map(spec, out, client, progress=stop_after_two, batch=1)
        assert first.interrupted and first.computed == 2
        kept = store.load(out)
        assert int(kept["done"].sum()) == 2
        second = engine.run_map(spec, out, client, batch=1)
    assert not second.interrupted
    assert second.computed == spec.size - 2           # the done points were not rerun
    done_first = {int(i) for b in first.batches for i in b.indices}
    assert not done_first & {int(i) for b in second.batches for i in b.indices}
    with engine.connect(workers=1) as client:
        fresh = engine.run_map(spec, tmp_path / "fresh.nc", client)
    same_maps(store.load(out), fresh.dataset)


def test_other_map_in_out_is_refused(tmp_path: Path) -> None:
    out = tmp_path / "map.nc"
    store.save(store.new_dataset(small_spec()), out)
    other = MapSpec(FIG8A, (Axis("psi", (40.0, 60.0)),), SHORT)
    try:
        store.open_map(other, out)
    except DrillSimError as exc:
        assert "different map" in str(exc)
    else:
        raise AssertionError("a different map was accepted")


def _read_stderr(proc: subprocess.Popen, sink: list[str]) -> None:
    for chunk in iter(lambda: proc.stderr.read(64), ""):
        sink.append(chunk)


def test_ctrl_c_keeps_done_points_and_rerun_completes(tmp_path: Path) -> None:
    """SIGINT to `drill_sim map`: rc 130, the file holds the points done; the same
    command again computes only the rest."""
    out = tmp_path / "map.nc"
    cmd = [sys.executable, "-m", "drill_sim_ros.cli", "map", "--tau-end", "300",
           "--vary", "omega0=3:7:12", "--vary", "w0=6:8:3", "--out", str(out),
           "--workers", "1", "--batch", "1", "--progress"]
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    err: list[str] = []
    reader = threading.Thread(target=_read_stderr, args=(proc, err), daemon=True)
    reader.start()
    deadline = time.monotonic() + WAIT_S
    while time.monotonic() < deadline and not re.search(r" [2-9]/36 points", "".join(err)):
        time.sleep(0.1)
    assert re.search(r" [2-9]/36 points", "".join(err)), "".join(err)[-500:]
    proc.send_signal(signal.SIGINT)
    proc.wait(timeout=WAIT_S)
    reader.join(timeout=WAIT_S)                  # stderr is the reader thread's alone
    stdout = proc.stdout.read()
    assert proc.returncode == 130, stdout + "".join(err)[-2000:]
    assert "interrupted" in "".join(err) and "interrupted" not in stdout     # on stderr
    assert not store.lock_path(out).exists()
    kept = store.load(out)
    done_before = int(kept["done"].sum())
    assert 2 <= done_before < 36
    rerun = subprocess.run(cmd[:-1], capture_output=True, text=True, timeout=WAIT_S * 3)
    assert rerun.returncode == 0, rerun.stderr
    assert f"({36 - done_before} computed now" in rerun.stdout
    final = store.load(out)
    assert int(final["done"].sum()) == 36
    mask = kept["done"].values == 1
    np.testing.assert_array_equal(final["kappa"].values[mask], kept["kappa"].values[mask])


def test_map_of_other_model_code_is_refused(tmp_path: Path) -> None:
    out = tmp_path / "map.nc"
    ds = store.new_dataset(small_spec())
    assert ds.attrs["model_fingerprint"] == store.model_fingerprint()
    ds.attrs["model_fingerprint"] = "0" * 16          # as written before a kernel change
    store.save(ds, out)
    try:
        store.open_map(small_spec(), out)
    except DrillSimError as exc:
        assert "another version of the model" in str(exc)
    else:
        raise AssertionError("a map of other model code was resumed")
