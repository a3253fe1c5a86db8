"""Shared set-up for the study tests: small maps, the CLI as a user runs it, listeners."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import psutil
import xarray as xr

from drill_sim_ros.model.params import DimensionlessParams
from drill_sim_ros.study.grid import Axis, MapSpec, Numerics

FIG8A = DimensionlessParams(n=6, psi=50.0, beta=0.3, lam=5.0, w0=7.0, omega0=5.0)
SHORT = Numerics(tau_end=60.0, average_from=30.0, dtau=1e-4)


def small_spec() -> MapSpec:
    """2 x 3 points around Fig. 8a: beta both sides of 1, W0' three ways."""
    return MapSpec(FIG8A, (Axis("beta", (0.3, 1.3)), Axis("w0_ratio", (1.2, 1.4, 1.8))),
                   SHORT)


def drill_sim(*args: str, timeout: float = 300) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "drill_sim_ros.cli", *args],
                          capture_output=True, text=True, timeout=timeout)


def same_maps(a: xr.Dataset, b: xr.Dataset) -> None:
    """Every data variable identical (NaN where the other is NaN)."""
    assert set(a.data_vars) == set(b.data_vars)
    for name in a.data_vars:
        np.testing.assert_array_equal(a[name].values, b[name].values, err_msg=name)


def listening(pids: list[int]) -> list[tuple[int, str, int]]:
    """(pid, ip, port) of every TCP socket listening in the processes ``pids`` and their
    children."""
    procs = []
    for pid in pids:
        proc = psutil.Process(pid)
        procs += [proc, *proc.children(recursive=True)]
    found = []
    for proc in procs:
        try:
            conns = proc.net_connections(kind="inet")
        except (psutil.NoSuchProcess, psutil.AccessDenied):
            continue
        found += [(proc.pid, c.laddr.ip, c.laddr.port) for c in conns
                  if c.status == psutil.CONN_LISTEN]
    return found
