"""Running (sliding-window) averages: stick-slip severity and the E-S state point.

Per sample, over the last ``window_s`` seconds of sim time:

* SSI = (max - min) / (2 mean) of the bit rpm and the stick fraction (time stuck), as in
  :func:`drill_sim_ros.model.analysis.severity`;
* E = <T>/<delta> and S = <W>/<delta> (RGD07 eq. 48) in the paper's dimensionless
  variables; in SI this is E = 2<T>/(eps a^2 <d>) and S = <W>/(zeta eps a <d>).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from drill_sim_ros.model.analysis import stick_slip_index
from drill_sim_ros.topics import MODE_NAMES
from drill_sim_ros.viz.paper_units import PaperUnits
from drill_sim_ros.viz.telemetry import TelemetryBatch
from drill_sim_ros.viz.windows import SlidingWindow

MODE_STUCK = float(MODE_NAMES.index("stuck"))
CHANNELS = ("bit_rpm", "stuck", "tob_nm", "wob_n", "depth_of_cut_m")
_RPM, _STUCK, _TOB, _WOB, _DOC = range(len(CHANNELS))


@dataclass(frozen=True)
class RunningStats:
    """Window statistics per sample, shape (n,) each; NaN where undefined."""

    ssi: np.ndarray
    stick_fraction: np.ndarray
    specific_energy: np.ndarray   # E (eq. 48), NaN when <delta> <= 0
    drilling_strength: np.ndarray  # S (eq. 48), NaN when <delta> <= 0


def default_window_s(units: PaperUnits) -> float:
    """Twenty t*: a bit over three natural torsional periods (2 pi t*)."""
    return 20.0 * units.scales.time_s


def new_window(window_s: float) -> SlidingWindow:
    return SlidingWindow(window_s, len(CHANNELS))


def _channels(batch: TelemetryBatch) -> np.ndarray:
    cols = [batch.column(name) for name in ("bit_rpm", "mode", "tob_nm", "wob_n",
                                              "depth_of_cut_m")]
    cols[_STUCK] = (cols[_STUCK] == MODE_STUCK).astype(np.float64)
    return np.column_stack(cols)


def _ratio(num: np.ndarray, den: np.ndarray) -> np.ndarray:
    out = np.full(num.shape, np.nan)
    np.divide(num, den, out=out, where=den > 0.0)
    return out


def running_stats(window: SlidingWindow, batch: TelemetryBatch,
                  units: PaperUnits) -> RunningStats:
    """Extend ``window`` with ``batch`` (sim time non-decreasing) and compute the stats."""
    w = window.extend(batch.sim_time_s, _channels(batch))
    ssi = stick_slip_index(w.minimum(_RPM), w.maximum(_RPM), w.mean(_RPM))
    doc = units.depth_of_cut(w.mean(_DOC))
    return RunningStats(
        ssi=ssi,
        stick_fraction=w.mean(_STUCK),
        specific_energy=_ratio(units.torque(w.mean(_TOB)), doc),
        drilling_strength=_ratio(units.weight(w.mean(_WOB)), doc),
    )
