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
import itertools
import logging
import math
import os
import signal
import threading
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
from drill_sim_ros.study.scheduler_probe import check_scheduler

TASKS_PER_WORKER = 8      # enough tasks for balance and a live progress bar
TASKS_IN_FLIGHT = 4       # tasks queued per worker at a time
CONNECT_TIMEOUT_S = 30.0
POLL_S = 0.02             # how often the loop looks for a finished task (and for Ctrl-C)
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
    error: str | None = None  # why the point after the last of ``indices`` failed


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
        try:
            values[row] = evaluate_spec_point(spec, int(flat))
        except Exception as exc:  # (returned, not raised: one line on the client, no log)
            why = str(exc) if isinstance(exc, DrillSimError) else \
                f"{type(exc).__name__}: {' '.join(str(exc).split())[:300]}"
            return BatchResult(np.asarray(indices[:row]), values[:row], os.getpid(), cold,
                               time.perf_counter() - t0, f"map point {int(flat)}: {why}")
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
    """A distributed Client: to ``scheduler`` if given (checked first by
    :func:`~drill_sim_ros.study.scheduler_probe.check_scheduler`, so a wrong address or a
    silent server is one line within its timeout), else to a LocalCluster of ``workers``
    single-threaded processes (default: one per core), all bound to 127.0.0.1 (the HTTP
    endpoints on ephemeral loopback ports)."""
    from distributed import Client, LocalCluster
    if scheduler:
        address = check_scheduler(scheduler)
        try:
            client = Client(address, timeout=CONNECT_TIMEOUT_S)
        except (OSError, TimeoutError) as exc:
            raise DrillSimError(f"--scheduler {scheduler}: cannot connect ({exc})") from exc
        with client:
            yield client
        return
    n = workers or os.cpu_count() or 1
    if not 1 <= n <= 1024:
        raise DrillSimError(f"--workers = {n} must be in [1, 1024]")
    # silence_logs: CRITICAL, since a worker whose heartbeat meets the scheduler closing (after
    # Ctrl-C) logs a traceback at ERROR; a point's failure reaches the user in its result
    with _deferred_interrupt() as interrupted:      # a half-started cluster cannot close
        cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True,
                               host=LOOPBACK, dashboard_address=f"{LOOPBACK}:0",
                               worker_dashboard_address=f"{LOOPBACK}:0",
                               silence_logs=logging.CRITICAL)
    with cluster, Client(cluster) as client:
        if interrupted:
            raise KeyboardInterrupt
        yield client


@contextlib.contextmanager
def _deferred_interrupt() -> Iterator[list[int]]:
    """Hold Ctrl-C (SIGINT) back while the block runs; the list is non-empty after it if
    one came. Outside the main thread, a plain block."""
    if threading.current_thread() is not threading.main_thread():
        yield []
        return
    received: list[int] = []
    previous = signal.signal(signal.SIGINT, lambda signum, _frame: received.append(signum))
    try:
        yield received
    finally:
        signal.signal(signal.SIGINT, previous)


def run_map(spec: MapSpec, out: Path, client: object,
            progress: Callable[[int, int, float], None] | None = None,
            checkpoint_s: float = 10.0, batch: int | None = None,
            log: Callable[[str], None] | None = None) -> MapRun:
    """Compute the points of ``spec`` not yet in ``out`` on ``client``; save to ``out``.

    At most TASKS_IN_FLIGHT tasks per worker are queued at a time (the scheduler's memory
    stays bounded whatever the map's size). ``log`` gets one line with the map's size
    before the work and one with the rate measured over the first tasks and the time left;
    ``progress`` gets (points done, total, seconds) from the start, so its rate is the real
    one. A file that did not exist is only written once a point is computed.
    """
    existed = out.exists()
    ds = store.open_map(spec, out)
    todo = store.pending(ds)
    if todo.size == 0:
        store.save(ds, out)
        return MapRun(ds, 0, spec.size, 0.0, False, ())
    n_workers = max(1, len(client.scheduler_info(n_workers=-1)["workers"]))
    size = batch or batch_size(todo.size, n_workers)
    _say(log, size_line(spec, todo.size, size, n_workers))
    # Ctrl-C ends the loop between results (a KeyboardInterrupt raised inside distributed's
    # calls makes it log tracebacks); the rate is measured from the kernel loaded
    with _deferred_interrupt() as sigint:
        client.run(warm_up)
        tally = _Tally(ds, out, spec.size - todo.size, spec.size, todo.size, n_workers, size,
                       progress, log, checkpoint_s)
        tasks = _Tasks(client, spec, todo, size)
        interrupted = False
        try:
            tasks.submit(TASKS_IN_FLIGHT * n_workers)
            interrupted = _collect(tasks, tally, sigint)
        except KeyboardInterrupt:
            interrupted = True
        finally:
            client.cancel(tasks.futures)
            if tally.computed or existed:
                store.save(ds, out)
    return MapRun(ds, tally.computed, spec.size, tally.elapsed_s(), interrupted,
                  tuple(tally.results))


def size_line(spec: MapSpec, todo: int, size: int, n_workers: int) -> str:
    """The line before the work: the map's size and how it is shared out."""
    return (f"drill_sim map: {spec.size:,} points ({' x '.join(map(str, spec.shape))}), "
            f"{todo:,} to compute in tasks of {size} on {n_workers} workers")


class _Tasks:
    """The map's tasks on ``client``: ``size`` points of ``todo`` each, submitted a few at
    a time; ``queue`` yields them as they finish."""

    def __init__(self, client: object, spec: MapSpec, todo: np.ndarray, size: int) -> None:
        from distributed import as_completed
        self._client, self._spec = client, spec
        self._chunks = (todo[i:i + size] for i in range(0, todo.size, size))
        self.queue = as_completed()
        self.futures: list[object] = []

    def submit(self, count: int) -> None:
        """Queue up to ``count`` more tasks (fewer at the end)."""
        for chunk in itertools.islice(self._chunks, count):
            self.futures.append(self._client.submit(evaluate_batch, self._spec, chunk,
                                                    pure=False))
            self.queue.add(self.futures[-1])


def _collect(tasks: _Tasks, tally: _Tally, sigint: list[int]) -> bool:
    """Take the results as they come, one new task per result, until all are in (False) or
    Ctrl-C came (True)."""
    while not tasks.queue.is_empty() and not sigint:
        if not tasks.queue.has_ready():
            time.sleep(POLL_S)
            continue
        res = _result(next(tasks.queue))
        tasks.submit(1)
        tally.take(res)
    return bool(sigint)


class _Tally:
    """The results so far: written into ``ds`` as they come, saved to ``out`` every
    ``checkpoint_s``, told to ``progress`` and, after the first round of tasks, ``log``."""

    def __init__(self, ds: xr.Dataset, out: Path, done0: int, total: int, todo: int,
                 n_workers: int, size: int,
                 progress: Callable[[int, int, float], None] | None,
                 log: Callable[[str], None] | None, checkpoint_s: float) -> None:
        self.ds, self.out, self.done0, self.total, self.todo = ds, out, done0, total, todo
        self.progress, self.log, self.checkpoint_s = progress, log, checkpoint_s
        self.first_round = min(n_workers, math.ceil(todo / size))
        self.results: list[BatchResult] = []
        self.computed = 0
        self.start = time.perf_counter()
        self.last_save = time.monotonic()
        if progress:
            progress(done0, total, 0.0)

    def elapsed_s(self) -> float:
        return time.perf_counter() - self.start

    def take(self, res: BatchResult) -> None:
        """Store ``res`` (its points before a failing one); DrillSimError if one failed."""
        store.store_results(self.ds, res.indices, res.values)
        self.results.append(res)
        self.computed += len(res.indices)
        if res.error is not None:
            raise DrillSimError(res.error)
        elapsed = self.elapsed_s()
        if self.progress:
            self.progress(self.done0 + self.computed, self.total, elapsed)
        if len(self.results) == self.first_round:
            _say(self.log, estimate_line(self.computed, self.todo, elapsed))
        if time.monotonic() - self.last_save > self.checkpoint_s:
            store.save(self.ds, self.out)
            self.last_save = time.monotonic()


def estimate_line(computed: int, todo: int, elapsed_s: float) -> str:
    """The rate measured over the first points and the time the rest will take."""
    rate = computed / elapsed_s if elapsed_s > 0 else math.inf
    left_s = (todo - computed) / rate if rate > 0 else math.inf
    return (f"drill_sim map: the first {computed:,} points took {elapsed_s:.1f} s "
            f"({rate:.3g} points/s): about {_duration(left_s)} for the other "
            f"{todo - computed:,} (Ctrl-C keeps the points done; the same command resumes)")


def _duration(seconds: float) -> str:
    if not math.isfinite(seconds):
        return "an unknown time"
    for unit, size in (("days", 86400.0), ("h", 3600.0), ("min", 60.0)):
        if seconds >= 2 * size:
            return f"{seconds / size:.1f} {unit}"
    return f"{seconds:.0f} s"


def _say(log: Callable[[str], None] | None, line: str) -> None:
    if log is not None:
        log(line)


def _result(future: object) -> BatchResult:
    """A task's result; a failure on a worker is one DrillSimError line."""
    try:
        return future.result()
    except DrillSimError:
        raise
    except Exception as exc:  # (a worker's failure: any type reaches here)
        text = " ".join(str(exc).split())[:300]
        raise DrillSimError(f"a map task failed on a worker: {type(exc).__name__}: "
                            f"{text}") from None
