"""A league of controllers: every controller x scenario on the bench, on Dask, resumable.

An entry is one scenario file run with one controller (the scenario's own controller and
parameters are replaced; its mode too, but ``none`` always runs the drive's speed loop).
Each entry is a task of its own (:func:`run_entry`, in process on a worker: the bench of
``control.bench``), and its result is written to ``DIR/runs/<scenario>__<controller>.npz``
as soon as it arrives (atomically): the scorecard with its status, and the columns the
picture needs. A re-run with the same ``DIR`` keeps every result whose scenario, controller
and model code (``study.store.model_fingerprint``) are the same and computes the rest.

A scenario that needs a feature the model core does not have yet is not run: its entries
carry the status ``needs <feature>``.

An ensemble (``drill_sim suite --ensemble N``) runs each entry N times, member k with the
bit's contact stress x wearflat sigma l scaled by 1 + k 1e-12 (``control.scenario.seeded``): a
change far below anything a bit's wear is known to, which a chaotic stick-slip amplifies
into an independent realisation, the same for every controller of a member. Member 0 is
the scenario itself, so its results are those of a plain suite (and shared with it).
"""

from __future__ import annotations

import json
import os
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
from functools import cached_property
from pathlib import Path
from typing import Any

import numpy as np

from drill_sim_ros.control.bench import Bench, build_controller
from drill_sim_ros.control.scenario import (
    Scenario,
    check_ensemble,
    load_scenario,
    scenario_dir,
    scenario_from_dict,
    scenario_path,
    seeded,
)
from drill_sim_ros.control.scorecard import score
from drill_sim_ros.model.errors import DrillSimError, NumericalFault, ParameterError
from drill_sim_ros.model.telemetry import N_FIELDS, TELEMETRY_INDEX

F = TELEMETRY_INDEX
DEFAULT_CONTROLLERS = ("none", "stiff", "soft_torque", "z_torque")
# the telemetry columns a result keeps (the picture's and the status's)
TRACE_FIELDS = ("sim_time_s", "bit_rpm", "surface_rpm", "speed_setpoint_rpm",
                "surface_torque_nm", "motor_torque_nm", "wob_n", "applied_wob_n", "mode")


@dataclass(frozen=True)
class Entry:
    """One run of the league: a scenario (its file's name) with a controller; ``member``
    of an ensemble (0: the scenario as it is)."""

    scenario_name: str
    scenario: Scenario
    controller: str
    member: int = 0

    @property
    def key(self) -> str:
        base = f"{self.scenario_name}__{self.controller.replace(':', '.')}"
        return f"{base}__m{self.member}" if self.member else base

    @cached_property
    def run_scenario(self) -> Scenario:
        """The scenario as this entry runs it (a seeded member reads its preset: once)."""
        return seeded(self.scenario.with_(controller=self.controller, params={}),
                      self.member)

    def fingerprint(self, code: str) -> str:
        return json.dumps({"scenario": self.run_scenario.to_dict(), "code": code},
                          sort_keys=True)


@dataclass
class EntryResult:
    """A finished entry: the scorecard (``status`` one of ok, stick-slip, stalled, fault,
    needs ...), seconds of wall time, and the kept trace (rows, len(TRACE_FIELDS))."""

    key: str
    card: dict[str, Any]
    wall_s: float
    trace: np.ndarray

    def rows(self) -> np.ndarray:
        """The trace as telemetry rows (N_FIELDS wide; the columns not kept are NaN)."""
        out = np.full((self.trace.shape[0], N_FIELDS), np.nan)
        out[:, [F[name] for name in TRACE_FIELDS]] = self.trace
        return out


def code_fingerprint() -> str:
    """The model and control code a result depends on (``store.model_fingerprint``), with
    the sensors and this module."""
    import hashlib

    from drill_sim_ros.study.store import model_fingerprint
    root = Path(__file__).resolve().parents[1]
    digest = hashlib.sha256(model_fingerprint(controlled=True).encode())
    for name in ("model/measurement.py", "study/suite.py"):
        digest.update((root / name).read_bytes())
    return digest.hexdigest()[:16]


def scenario_files(names: Sequence[str] = ()) -> list[Path]:
    """The named scenarios (names of config/scenarios or paths), default all, sorted."""
    if not names:
        return sorted(scenario_dir().glob("*.yaml"))
    return [scenario_path(name) for name in names]


def entries(paths: Sequence[Path], controllers: Sequence[str], mode: str) -> list[Entry]:
    """Every controller x scenario; ``none`` in speed mode (the drive's own loop)."""
    out = []
    for path in paths:
        base = load_scenario(path)
        for controller in controllers:
            scenario = base.with_(mode="speed" if controller == "none" else mode)
            out.append(Entry(path.stem, scenario, controller))
    return out


def ensemble(todo: Sequence[Entry], members: int) -> list[Entry]:
    """Every entry of ``todo`` as members 0 .. ``members`` - 1, member by member."""
    return [replace(entry, member=k) for k in range(check_ensemble(members)) for entry in todo]


def run_entry(scenario_data: dict[str, Any], key: str) -> EntryResult:
    """Run one entry in this process (a Dask task): its scorecard and trace. A numerical
    fault ends the run with status ``fault`` and the time it happened."""
    scenario = scenario_from_dict(scenario_data)
    start = time.perf_counter()
    bench = Bench(scenario)
    controller = build_controller(scenario, bench.preset)
    command, fault = controller.update(bench.measurement()), None   # answers t = 0
    try:
        while not bench.done:
            bench.step(command)
            if not bench.done:
                command = controller.update(bench.measurement())
    except NumericalFault as exc:
        fault = str(exc)
    rows = bench.rows[:bench.period + 1]
    wall_s = time.perf_counter() - start
    trace = rows[:, [F[name] for name in TRACE_FIELDS]].copy()
    if fault is not None:
        card = {"status": "fault", "fault": fault,
                "fault_time_s": float(rows[-1, F["sim_time_s"]])}
        return EntryResult(key, card, wall_s, trace)
    card = score(rows, scenario.enable_at_s, bench.schedule, bench.rig, scenario.period_s)
    return EntryResult(key, card, wall_s, trace)


def unsupported_result(entry: Entry) -> EntryResult:
    need = ", ".join(entry.scenario.unsupported())
    return EntryResult(entry.key, {"status": f"needs {need}"}, 0.0,
                       np.empty((0, len(TRACE_FIELDS))))


# ---- the results directory -----------------------------------------------------------------
def result_path(out: Path, entry: Entry) -> Path:
    return out / "runs" / f"{entry.key}.npz"


def save_result(out: Path, entry: Entry, result: EntryResult, fingerprint: str) -> None:
    """Write ``result`` atomically (written beside, then renamed)."""
    path = result_path(out, entry)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(path.name + ".partial.npz")
    meta = {"card": result.card, "wall_s": result.wall_s, "fingerprint": fingerprint}
    np.savez_compressed(tmp, trace=result.trace, meta=np.array(json.dumps(meta)))
    os.replace(tmp, path)


def load_result(out: Path, entry: Entry, fingerprint: str) -> EntryResult | None:
    """The stored result of ``entry`` if it was computed from the same inputs, else None."""
    path = result_path(out, entry)
    if not path.exists():
        return None
    try:
        with np.load(path) as data:
            meta = json.loads(str(data["meta"]))
            trace = data["trace"]
    except (OSError, ValueError, KeyError):
        return None
    if meta.get("fingerprint") != fingerprint:
        return None
    return EntryResult(entry.key, meta["card"], float(meta["wall_s"]), trace)


@dataclass(frozen=True)
class SuiteRun:
    """What :func:`run_suite` did: every entry's result, how many it computed now."""

    results: dict[str, EntryResult]
    computed: int
    seconds: float
    interrupted: bool


def run_suite(todo: Sequence[Entry], out: Path, client: Any, code: str,
              progress: Callable[[int, int], None] | None = None) -> SuiteRun:
    """Run the entries not yet in ``out`` on ``client`` (Dask), saving each as it arrives."""
    from distributed import as_completed

    from drill_sim_ros.study.engine import warm_up
    start = time.perf_counter()
    results: dict[str, EntryResult] = {}
    pending: list[Entry] = []
    for entry in todo:
        stored = load_result(out, entry, entry.fingerprint(code))
        if entry.scenario.unsupported():
            results[entry.key] = unsupported_result(entry)
        elif stored is not None:
            results[entry.key] = stored
        else:
            pending.append(entry)
    if not pending:
        return SuiteRun(results, 0, 0.0, False)
    by_key = {entry.key: entry for entry in pending}
    client.run(warm_up)
    futures = [client.submit(run_entry, entry.run_scenario.to_dict(), entry.key, pure=False)
               for entry in pending]
    computed, interrupted = 0, False
    try:
        for future in as_completed(futures):
            result: EntryResult = future.result()
            entry = by_key[result.key]
            save_result(out, entry, result, entry.fingerprint(code))
            results[result.key] = result
            computed += 1
            if progress:
                progress(len(results), len(todo))
    except KeyboardInterrupt:
        interrupted = True
        client.cancel(futures)
    except ParameterError as exc:          # e.g. a user controller that cannot be built
        client.cancel(futures)
        raise DrillSimError(str(exc)) from exc
    return SuiteRun(results, computed, time.perf_counter() - start, interrupted)
