"""The map engine on real Dask: a LocalCluster with 1 and 2 workers, and `dask scheduler`
plus `dask worker` processes started here, all on 127.0.0.1, give identical maps."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import time
from pathlib import Path

import pytest

from drill_sim_ros.study import engine, store
from tests.study.helpers import listening, same_maps, small_spec

DASK = str(Path(sys.executable).with_name("dask"))
START_TIMEOUT_S = 60.0


def _local(out: Path, workers: int, batch: int | None = None) -> engine.MapRun:
    with engine.connect(workers=workers) as client:
        return engine.run_map(small_spec(), out, client, batch=batch)


def test_one_and_two_workers_identical_and_warm(tmp_path: Path) -> None:
    one = _local(tmp_path / "one.nc", 1, batch=4)
    two = _local(tmp_path / "two.nc", 2, batch=1)
    same_maps(one.dataset, two.dataset)
    same_maps(store.load(tmp_path / "one.nc"), two.dataset)      # what was written
    assert len({b.pid for b in two.batches}) <= 2
    # every task found the compiled kernel already loaded in its worker (no per-task
    # compilation: one load per process, before the tasks)
    assert not any(b.cold for b in one.batches + two.batches)
    assert len(two.batches) == small_spec().size                   # batch = 1 point


def test_local_cluster_listens_on_loopback_only() -> None:
    with engine.connect(workers=2) as client:
        client.run(os.getpid)
        found = listening([os.getpid()])
    assert len(found) >= 3, found                  # scheduler and two workers at least
    assert {ip for _, ip, _ in found} == {"127.0.0.1"}, found


@pytest.fixture
def dask_cluster(tmp_path: Path):
    """A real `dask scheduler` and `dask worker` (2 processes) on 127.0.0.1."""
    info = tmp_path / "scheduler.json"
    procs = [subprocess.Popen([DASK, "scheduler", "--host", "127.0.0.1", "--port", "0",
                               "--dashboard-address", "127.0.0.1:0",
                               "--scheduler-file", str(info)],
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)]
    try:
        deadline = time.monotonic() + START_TIMEOUT_S
        while not info.exists() and time.monotonic() < deadline:
            time.sleep(0.2)
        assert info.exists(), "dask scheduler did not start"
        address = json.loads(info.read_text())["address"]
        procs.append(subprocess.Popen([DASK, "worker", address, "--host", "127.0.0.1",
                                       "--dashboard-address", "127.0.0.1:0", "--nworkers",
                                       "2", "--nthreads", "1"],
                                      stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL))
        yield address, [p.pid for p in procs]
    finally:
        for proc in reversed(procs):
            proc.terminate()
            try:
                proc.wait(timeout=30)
            except subprocess.TimeoutExpired:
                proc.kill()
                proc.wait(timeout=10)


def test_external_scheduler_identical_and_loopback(dask_cluster, tmp_path: Path) -> None:
    address, pids = dask_cluster
    with engine.connect(address) as client:
        client.wait_for_workers(2, timeout=START_TIMEOUT_S)
        found = listening(pids)
        remote = engine.run_map(small_spec(), tmp_path / "remote.nc", client)
    local = _local(tmp_path / "local.nc", 1)
    same_maps(remote.dataset, local.dataset)
    assert len({b.pid for b in remote.batches}) <= 2
    assert all(pid not in (os.getpid(),) for pid in {b.pid for b in remote.batches})
    assert len(found) >= 3, found
    assert {ip for _, ip, _ in found} == {"127.0.0.1"}, found
