"""Computing a map on Dask distributed: a LocalCluster on 127.0.0.1, or an existing
scheduler (``tcp://HOST:PORT``).

Points are batched into tasks (a task is :func:`evaluate_batch` over a few points), results
are written into the Dataset as they arrive and the NetCDF file is saved every
``checkpoint_s`` seconds and at the end. Ctrl-C cancels what is queued and saves what is
done; the same call with the same ``out`` resumes. Results do not depend on the workers
or the batching: each point is a deterministic run of its own.

Workers are long-lived processes: the compiled kernel is loaded once per process (from
numba's on-disk cache) and reused by every task it runs.
"""

from __future__ import annotations

import contextlib
import math
import os
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import xarray as xr

from drill_sim_ros.model import kernel as k
from drill_sim_ros.model.errors import DrillSimError
from drill_sim_ros.study import store
from drill_sim_ros.study.grid import MapSpec
from drill_sim_ros.study.point import N_VARS, evaluate_point

TASKS_PER_WORKER = 8      # enough tasks for balance and a live progress bar
MAX_BATCH = 64
LOOPBACK = "127.0.0.1"


@dataclass(frozen=True)
class BatchResult:
    """What a task returns: the points, their figures, and where/how it ran."""

    indices: np.ndarray
    values: np.ndarray        # (len(indices), N_VARS)
    pid: int
    cold: bool                # the kernel was not loaded in this process before the task
    seconds: float


@dataclass(frozen=True)
class MapRun:
    """Summary of :func:`run_map`."""

    dataset: xr.Dataset
    computed: int             # points computed by this call
    total: int
    seconds: float
    interrupted: bool
    batches: tuple[BatchResult, ...]


def evaluate_batch(spec: MapSpec, indices: np.ndarray) -> BatchResult:
    """Run the points ``indices`` of ``spec`` (a Dask task; also usable in-process)."""
    cold = not k.advance.signatures
    t0 = time.perf_counter()
    values = np.empty((len(indices), N_VARS))
    for row, flat in enumerate(indices):
        values[row] = evaluate_spec_point(spec, int(flat))
    return BatchResult(np.asarray(indices), values, os.getpid(), cold,
                       time.perf_counter() - t0)


def evaluate_spec_point(spec: MapSpec, flat: int) -> np.ndarray:
    """Point ``flat`` of ``spec``: open loop, or closed loop when the map has a controller."""
    if spec.control is not None:
        from drill_sim_ros.study.closed_loop import evaluate_closed_point
        return evaluate_closed_point(spec, flat)
    return evaluate_point(spec.point(flat), spec.numerics)


def warm_up() -> int:
    """Load the compiled kernel in this process (run on every worker before the tasks)."""
    from drill_sim_ros.model.params import DimensionlessParams
    from drill_sim_ros.study.grid import Numerics
    evaluate_point(DimensionlessParams(), Numerics(tau_end=0.01, average_from=0.0))
    return os.getpid()


def batch_size(n_points: int, n_workers: int) -> int:
    """Points per task: about TASKS_PER_WORKER tasks per worker, at most MAX_BATCH."""
    return max(1, min(MAX_BATCH, math.ceil(n_points / (TASKS_PER_WORKER * max(1, n_workers)))))


@contextlib.contextmanager
def connect(scheduler: str | None = None, workers: int | None = None) -> Iterator[object]:
    """A distributed Client: to ``scheduler`` if given, else to a LocalCluster of
    ``workers`` single-threaded processes (default: one per core), all bound to 127.0.0.1
    (the HTTP endpoints on ephemeral loopback ports)."""
    from distributed import Client, LocalCluster
    if scheduler:
        try:
            client = Client(scheduler, timeout=30)
        except (OSError, TimeoutError) as exc:
            raise DrillSimError(f"--scheduler {scheduler}: cannot connect ({exc})") from exc
        with client:
            yield client
        return
    n = workers or os.cpu_count() or 1
    if not 1 <= n <= 1024:
        raise DrillSimError(f"--workers = {n} must be in [1, 1024]")
    with LocalCluster(n_workers=n, threads_per_worker=1, processes=True, host=LOOPBACK,
                      dashboard_address=f"{LOOPBACK}:0",
                      worker_dashboard_address=f"{LOOPBACK}:0",
                      silence_logs=40) as cluster, Client(cluster) as client:
        yield client


def run_map(spec: MapSpec, out: Path, client: object,
            progress: Callable[[int, int, float], None] | None = None,
            checkpoint_s: float = 10.0, batch: int | None = None) -> MapRun:
    """Compute the points of ``spec`` not yet in ``out`` on ``client``; save to ``out``."""
    from distributed import as_completed
    ds = store.open_map(spec, out)
    todo = store.pending(ds)
    total, done0 = spec.size, spec.size - todo.size
    start = time.perf_counter()
    if todo.size == 0:
        store.save(ds, out)
        return MapRun(ds, 0, total, 0.0, False, ())
    n_workers = max(1, len(client.scheduler_info(n_workers=-1)["workers"]))
    client.run(warm_up)
    size = batch or batch_size(todo.size, n_workers)
    futures = [client.submit(evaluate_batch, spec, todo[i:i + size], pure=False)
               for i in range(0, todo.size, size)]
    results: list[BatchResult] = []
    computed, last_save, interrupted = 0, time.monotonic(), False
    try:
        for future in as_completed(futures):
            res: BatchResult = future.result()
            store.store_results(ds, res.indices, res.values)
            results.append(res)
            computed += len(res.indices)
            if progress:
                progress(done0 + computed, total, time.perf_counter() - start)
            if time.monotonic() - last_save > checkpoint_s:
                store.save(ds, out)
                last_save = time.monotonic()
    except KeyboardInterrupt:
        interrupted = True
        client.cancel(futures)
    finally:
        store.save(ds, out)
    return MapRun(ds, computed, total, time.perf_counter() - start, interrupted,
                  tuple(results))
