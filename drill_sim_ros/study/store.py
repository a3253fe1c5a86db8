"""A map as an xarray Dataset in NetCDF-4 (h5netcdf engine), and resuming one.

One data variable per :data:`point.VARIABLES` entry, over the map's axes (coordinates in
their units), plus ``done`` (1 where the point was computed). The attributes hold the spec
(``spec_json``) and a fingerprint of the model code (``model_fingerprint``), both
compared on resume, the numerics, the package version and the regime
codes. Files are replaced atomically (written beside, then renamed), so an interrupted
write never leaves a broken map.
"""

from __future__ import annotations

import contextlib
import fcntl
import hashlib
import json
import os
from collections.abc import Iterator
from datetime import UTC, datetime
from pathlib import Path
from typing import IO

import numpy as np
import xarray as xr

from drill_sim_ros import __version__
from drill_sim_ros.model.errors import DrillSimError
from drill_sim_ros.study.grid import AXIS_LABELS, Axis, MapSpec
from drill_sim_ros.study.point import VARIABLES
from drill_sim_ros.study.regime import REGIME_NAMES

ENGINE = "h5netcdf"
# The sources whose change changes a point's figures: a map computed by other ones is not
# resumed (the figures would mix two models).
_MODEL_SOURCES = ("model/kernel.py", "model/simulator.py", "model/analysis.py",
                  "study/point.py", "study/regime.py", "study/grid.py")
# and, for a controlled map, the bench, the controllers and the session they step
_CONTROL_SOURCES = ("study/closed_loop.py", "model/session.py", "model/top_drive.py",
                    "model/telemetry.py", "control/bench.py", "control/command.py",
                    "control/controllers.py", "control/registry.py", "control/rig.py",
                    "control/scenario.py", "control/schedule.py", "control/scorecard.py")
# what a controlled map leaves undefined, and what it computes otherwise (attributes)
CONTROLLED_NOTE = ("closed loop (control/bench.py run_in_process at each point's rpm and WOB; "
                   "the bench's numerics, not --dtau/--nodes/--perturb-v): ssi, utr, "
                   "stick_fraction, rop_m_h from the scorecard over the window (ssi: mean of "
                   "whole 20 s windows, each clipped at 10, which a window stuck throughout "
                   "reads; stick_fraction: share of 10 ms samples); kappa, eta "
                   "and the means from the kernel's sums over the window; omega_min/max, "
                   "torsional_period, axial_amplitude from the 10 ms telemetry; every "
                   "variable is defined")
OPEN_LOOP_NOTE = "open loop (constant surface speed): rop_m_h is not computed (NaN)"


def model_fingerprint(controlled: bool = False) -> str:
    """Short SHA-256 of the model and per-point sources (and the closed loop's)."""
    root = Path(__file__).resolve().parents[1]
    digest = hashlib.sha256()
    for name in _MODEL_SOURCES + (_CONTROL_SOURCES if controlled else ()):
        digest.update((root / name).read_bytes())
    return digest.hexdigest()[:16]


def new_dataset(spec: MapSpec) -> xr.Dataset:
    """An empty map: every variable NaN, ``done`` all 0."""
    dims = tuple(a.name for a in spec.axes)
    coords = {a.name: (a.name, _axis_values(a), {"units": a.units,
                                                 "long_name": AXIS_LABELS[a.name]})
              for a in spec.axes}
    data = {name: (dims, np.full(spec.shape, np.nan), {"units": units, "long_name": text})
            for name, (units, text) in VARIABLES.items()}
    data["done"] = (dims, np.zeros(spec.shape, dtype=np.int8),
                    {"units": "1", "long_name": "1 where the point was computed"})
    num = spec.numerics
    attrs = {
        "title": "drill_sim regime map (Richard, Germay & Detournay 2007 model)",
        "spec_json": spec.to_json(), "preset": spec.preset,
        "model_fingerprint": model_fingerprint(spec.control is not None),
        "package": "drill_sim_ros", "package_version": __version__,
        "created_utc": datetime.now(UTC).isoformat(timespec="seconds"),
        "tau_end": num.tau_end, "average_from": num.average_from, "dtau": num.dtau,
        "n_nodes": num.n_nodes, "method": num.method, "perturb_v": num.perturb_v,
        "perturb_omega": num.perturb_omega,
        "regime_codes": json.dumps(dict(enumerate(REGIME_NAMES))),
        "base_params": json.dumps({g: getattr(spec.base, g) for g in
                                   ("n", "psi", "beta", "lam", "w0", "omega0")}),
        "averages": "time averages over [average_from, tau_end], stick phases included",
        "controller": "" if spec.control is None else spec.control.controller,
        "loop": OPEN_LOOP_NOTE if spec.control is None else CONTROLLED_NOTE,
    }
    if spec.control is not None:
        attrs.update(control_mode=spec.control.mode, enable_at_s=spec.control.enable_at_s)
    if spec.scales is not None:
        attrs.update(t_star_s=spec.scales.time_s, l_star_m=spec.scales.length_m,
                     force_unit_n=spec.scales.force_n, torque_unit_nm=spec.scales.torque_nm)
    return xr.Dataset(data, coords=coords, attrs=attrs)


def _axis_values(axis: Axis) -> np.ndarray:
    if axis.name == "n":
        return np.array([round(v) for v in axis.values], dtype=np.int64)
    return np.array(axis.values, dtype=np.float64)


def open_map(spec: MapSpec, path: Path) -> xr.Dataset:
    """The map at ``path`` if it holds this spec (resume), else a new one. A file holding
    another map is refused, so nothing is overwritten by mistake."""
    if not path.exists():
        return new_dataset(spec)
    try:
        ds = xr.load_dataset(path, engine=ENGINE)
    except (OSError, ValueError) as exc:
        raise DrillSimError(f"--out {path}: not a readable map ({exc}); choose another "
                            "--out or delete the file") from exc
    if ds.attrs.get("spec_json") != spec.to_json():
        raise DrillSimError(f"--out {path} holds a different map (other axes, base case or "
                            "numerics); choose another --out or delete the file")
    if ds.attrs.get("model_fingerprint") != model_fingerprint(spec.control is not None):
        raise DrillSimError(f"--out {path} was computed by another version of the model "
                            "code; choose another --out or delete the file")
    return ds


def lock_path(path: Path) -> Path:
    return path.with_name(f".{path.name}.lock")


LOCK_ATTEMPTS = 10      # a lock file removed by its holder between our open and our lock


@contextlib.contextmanager
def map_lock(path: Path) -> Iterator[None]:
    """Hold ``path`` for one map run: a second run on it (same spec or not) is refused
    with one DrillSimError line, at its start. An advisory ``flock`` on a file beside the
    map, released by the kernel when the process ends however it ends; the file is removed
    when the block ends, normally or by an exception (Ctrl-C included)."""
    lock = lock_path(path)
    stream = _locked(lock, path)
    try:
        stream.seek(0)
        stream.truncate()
        stream.write(f"pid {os.getpid()}")
        stream.flush()
        yield
    finally:
        lock.unlink(missing_ok=True)        # while held: a waiting opener sees it gone
        stream.close()


def _locked(lock: Path, path: Path) -> IO[str]:
    """``lock`` opened and flocked, the file its name holds now (a holder removes the
    file before it lets go: a lock taken on a removed file is taken again on a new one)."""
    for _ in range(LOCK_ATTEMPTS):
        try:
            lock.parent.mkdir(parents=True, exist_ok=True)
            stream = open(lock, "a+")  # noqa: SIM115 (held for the run by map_lock)
        except OSError as exc:
            raise DrillSimError(f"--out {path}: cannot create {lock} "
                                f"({exc.strerror or exc})") from None
        try:
            fcntl.flock(stream, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            stream.seek(0)
            owner = stream.read().strip() or "another process"
            stream.close()
            raise DrillSimError(f"--out {path} is in use by another drill_sim map ({owner}); "
                                "wait for it to end or choose another --out") from None
        if _same_file(stream, lock):
            return stream
        stream.close()
    raise DrillSimError(f"--out {path}: {lock} keeps being replaced by other drill_sim maps; "
                        "wait for them to end or choose another --out")


def _same_file(stream: IO[str], lock: Path) -> bool:
    """``stream`` is the file ``lock`` names now."""
    try:
        return os.path.samestat(os.fstat(stream.fileno()), os.stat(lock))
    except FileNotFoundError:
        return False


def save(ds: xr.Dataset, path: Path) -> None:
    """Write ``ds`` to ``path`` atomically."""
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(path.name + ".partial")
    ds.attrs["saved_utc"] = datetime.now(UTC).isoformat(timespec="seconds")
    ds.to_netcdf(tmp, engine=ENGINE)
    os.replace(tmp, path)


def load(path: Path) -> xr.Dataset:
    """Read a map written by :func:`save` (into memory; the file is closed)."""
    if not path.exists():
        raise DrillSimError(f"map file {path} does not exist")
    try:
        return xr.load_dataset(path, engine=ENGINE)
    except (OSError, ValueError) as exc:
        raise DrillSimError(f"map file {path} is not a readable NetCDF map ({exc})") from exc


def store_results(ds: xr.Dataset, flat_indices: np.ndarray, results: np.ndarray) -> None:
    """Write rows of :func:`point.evaluate_point` output at ``flat_indices``; mark done."""
    for j, name in enumerate(VARIABLES):
        ds[name].values.reshape(-1)[flat_indices] = results[:, j]
    ds["done"].values.reshape(-1)[flat_indices] = 1


def pending(ds: xr.Dataset) -> np.ndarray:
    """Flat indices of the points not computed yet."""
    return np.flatnonzero(ds["done"].values.reshape(-1) == 0)
