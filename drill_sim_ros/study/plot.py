"""Drawing maps: a regime map with labelled regions, or one variable in colour with contours.

matplotlib (Agg) only; every function takes the Axes to draw on.
"""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
import xarray as xr
from matplotlib.colors import BoundaryNorm, ListedColormap
from matplotlib.patches import Patch

from drill_sim_ros.model.errors import DrillSimError
from drill_sim_ros.study.grid import AXIS_LABELS
from drill_sim_ros.study.point import VARIABLES
from drill_sim_ros.study.regime import REGIME_COLORS, REGIME_NAMES

REGIME_CMAP = ListedColormap(REGIME_COLORS)
REGIME_NORM = BoundaryNorm(np.arange(-0.5, len(REGIME_NAMES)), len(REGIME_NAMES))


def axis_label(name: str) -> str:
    return AXIS_LABELS.get(name, name)


def select(ds: xr.Dataset, at: dict[str, float], keep: int = 2) -> xr.Dataset:
    """Reduce ``ds`` to at most ``keep`` axes: the axes named in ``at`` are taken at the
    nearest value; more than ``keep`` axes left is an error naming them."""
    unknown = set(at) - set(ds.dims)
    if unknown:
        raise DrillSimError(f"--at {sorted(unknown)}: not an axis of the map "
                            f"(axes: {', '.join(map(str, ds.dims))})")
    ds = ds.sel(at, method="nearest") if at else ds
    if len(ds.dims) > keep:
        raise DrillSimError(f"the map has axes {', '.join(map(str, ds.dims))}: choose the "
                            f"value of all but {keep} with --at NAME=VALUE")
    return ds


def draw_regime(ax: plt.Axes, da: xr.DataArray, labels: bool = True) -> None:
    """Regime codes as coloured cells, each region labelled at its median cell."""
    y, x = da.dims
    ax.pcolormesh(da[x].values, da[y].values, da.values, cmap=REGIME_CMAP, norm=REGIME_NORM,
                  shading="nearest")
    present = [int(c) for c in np.unique(da.values[np.isfinite(da.values)])]
    for code in present:
        if not labels:
            break
        r, c = _label_cell(da.values == code)
        ax.text(da[x].values[c], da[y].values[r], REGIME_NAMES[code], ha="center",
                va="center", fontsize=8, color="white" if code >= 2 else "black",
                bbox={"boxstyle": "round,pad=0.2", "fc": REGIME_COLORS[code], "ec": "none",
                      "alpha": 0.85})
    ax.legend(handles=[Patch(color=REGIME_COLORS[c], label=REGIME_NAMES[c]) for c in present],
              fontsize=7, loc="upper right", framealpha=0.9)
    ax.set_xlabel(axis_label(str(x)))
    ax.set_ylabel(axis_label(str(y)))


def _label_cell(mask: np.ndarray) -> tuple[int, int]:
    """The cell of ``mask`` nearest the middle of its region, kept off the edges when the
    region allows."""
    rows, cols = np.nonzero(mask)
    inner = (rows > 0) & (rows < mask.shape[0] - 1) & (cols > 0) & (cols < mask.shape[1] - 1)
    if inner.any():
        rows, cols = rows[inner], cols[inner]
    best = np.argmin((rows - rows.mean()) ** 2 + (cols - cols.mean()) ** 2)
    return int(rows[best]), int(cols[best])


def draw_variable(ax: plt.Axes, da: xr.DataArray, levels: int = 6, cmap: str = "viridis",
                  label: str | None = None, vmin: float | None = None,
                  vmax: float | None = None) -> None:
    """One variable in colour (limits ``vmin``, ``vmax``: default the data's), with
    labelled contours."""
    y, x = da.dims
    xs, ys, values = da[x].values, da[y].values, da.values
    mesh = ax.pcolormesh(xs, ys, values, shading="nearest", cmap=cmap, vmin=vmin, vmax=vmax)
    plt.colorbar(mesh, ax=ax, label=label or _var_label(str(da.name)))
    if np.isfinite(values).sum() >= 4 and np.nanmax(values) > np.nanmin(values):
        cs = ax.contour(xs, ys, values, levels=levels, colors="k", linewidths=0.6)
        ax.clabel(cs, fontsize=7, fmt="%.3g")
    ax.set_xlabel(axis_label(str(x)))
    ax.set_ylabel(axis_label(str(y)))


def _var_label(name: str) -> str:
    units, _ = VARIABLES.get(name, ("", ""))
    return f"{name} [{units}]" if units and units != "1" else name


def plot_file(ds: xr.Dataset, var: str, out: Path, at: dict[str, float]) -> None:
    """``drill_sim map-plot``: a 2-D map (regime or colour), or a line for one axis."""
    if var not in ds.data_vars or var == "done":
        allowed = ", ".join(v for v in ds.data_vars if v != "done")
        raise DrillSimError(f"--var {var!r}: not in the map; allowed: {allowed}")
    sub = select(ds, at)
    da = sub[var].where(sub["done"] == 1)
    fig, ax = plt.subplots(figsize=(7, 5))
    if len(da.dims) == 1:
        ax.plot(da[da.dims[0]].values, da.values, "o-")
        ax.set_xlabel(axis_label(str(da.dims[0])))
        ax.set_ylabel(_var_label(var))
    elif var == "regime":
        draw_regime(ax, da)
    else:
        draw_variable(ax, da)
    fixed = ", ".join(f"{k}={float(v.values):.4g}" for k, v in sub.coords.items()
                      if k not in da.dims)
    ax.set_title(f"{var}  ({ds.attrs.get('preset') or 'map'}; tau_end={ds.attrs['tau_end']:g}, "
                 f"dtau={ds.attrs['dtau']:g}{', ' + fixed if fixed else ''})", fontsize=9)
    fig.tight_layout()
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=120)
    plt.close(fig)
