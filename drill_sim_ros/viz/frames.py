"""How the 2D views are framed: data ranges, ticks, and the map to stored coordinates.

rerun's 2D views have no axes and one scale for x and y, with y pointing down. Each view
therefore gets a :class:`Frame2D`: the data ranges it shows (rounded out to ticks), a scale per
axis so that the plot box has a readable shape, and the visual bounds stored in the blueprint
(the box plus room for the tick labels). Stored point = (x * x_scale, -y * y_scale).

Ranges come from :class:`Extents`: the preset's reference points (the trivial solution, eq. 34;
the cutting point of eq. 50) always, and the data when it is known beforehand (mcap_to_rerun
scans the file first); the live bridge uses the typical stick-slip ranges below.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from drill_sim_ros.viz.paper_units import PaperUnits

PHASE_ASPECT = 4.0 / 3.0       # plot box width / height
ES_ASPECT = 4.0 / 3.0
# Live runs (data unknown at start): omega reaches about 2 omega0 in stick-slip (Fig. 8a);
# v/v0 and delta/delta0 peaks of a few units, as in the paper's and the field preset's cycles.
TYPICAL_V_MAX, TYPICAL_OMEGA_MAX, TYPICAL_R_MAX = 10.0, 2.5, 2.5
ES_CAP = 3.0                   # E and S shown up to ES_CAP x the trivial point's (outliers cut)


def nice_step(span: float, ticks: int = 5) -> float:
    """1, 2 or 5 x 10^k, so that ``span`` holds about ``ticks`` intervals."""
    raw = max(span, 1e-12) / ticks
    power = 10.0 ** math.floor(math.log10(raw))
    return next(m * power for m in (1.0, 2.0, 5.0, 10.0) if m * power >= raw)


def rounded_range(lo: float, hi: float) -> tuple[float, float, float]:
    """(lo, hi) rounded out to whole ticks, and the tick step."""
    step = nice_step(hi - lo)
    return math.floor(lo / step + 1e-9) * step, math.ceil(hi / step - 1e-9) * step, step


@dataclass(frozen=True)
class Frame2D:
    """A 2D view's data box [x_lo, x_hi] x [y_lo, y_hi], its ticks and its scales."""

    x_range: tuple[float, float]
    y_range: tuple[float, float]
    x_step: float
    y_step: float
    x_scale: float
    y_scale: float
    tick_labels: bool = True      # room on the left and below for tick labels

    def stored(self, x: np.ndarray, y: np.ndarray) -> np.ndarray:
        """Plot values -> stored 2D positions (n, 2): y scaled and negated (y down)."""
        return np.column_stack((np.asarray(x) * self.x_scale, -np.asarray(y) * self.y_scale))

    def ticks(self, axis: str) -> np.ndarray:
        lo, hi = self.x_range if axis == "x" else self.y_range
        step = self.x_step if axis == "x" else self.y_step
        return np.arange(round((hi - lo) / step) + 1) * step + lo

    @property
    def height(self) -> float:
        """Height of the box in stored units."""
        return (self.y_range[1] - self.y_range[0]) * self.y_scale

    def bounds(self) -> tuple[tuple[float, float], tuple[float, float]]:
        """Stored (x_range, y_range) of the box plus room for tick and axis labels."""
        pad = 0.06 * self.height
        x_lo, x_hi = (v * self.x_scale for v in self.x_range)
        y_top, y_bottom = (-v * self.y_scale for v in reversed(self.y_range))
        left = 3.5 * pad if self.tick_labels else 1.0 * pad
        right = 1.5 * pad if self.tick_labels else 1.0 * pad
        return (x_lo - left, x_hi + right), (y_top - 2.0 * pad, y_bottom + 3.5 * pad)


def box_frame(x_lo: float, x_hi: float, y_lo: float, y_hi: float,
              aspect: float) -> Frame2D:
    """Ranges rounded to ticks; scales make the box 1 high and ``aspect`` wide."""
    x_lo, x_hi, x_step = rounded_range(x_lo, x_hi)
    y_lo, y_hi, y_step = rounded_range(y_lo, y_hi)
    return Frame2D((x_lo, x_hi), (y_lo, y_hi), x_step, y_step,
                   aspect / (x_hi - x_lo), 1.0 / (y_hi - y_lo))


def polar_frame(r_max: float) -> Frame2D:
    """A square box of radius r_max (rounded out to a step), equal scales; the step (at
    least 1) is also the spacing of the reference circles."""
    step = 0.5 if r_max <= 3.0 else max(1.0, nice_step(r_max, ticks=4))
    r = math.ceil(r_max / step - 1e-9) * step
    return Frame2D((-r, r), (-r, r), step, step, 1.0 / (2.0 * r), 1.0 / (2.0 * r),
                   tick_labels=False)


@dataclass
class Extents:
    """Running min/max of what the 2D views plot, in the paper's variables."""

    v: list[float] = field(default_factory=lambda: [0.0, 1.0])        # v / v0
    omega: list[float] = field(default_factory=lambda: [0.0, 1.0])    # omega / omega0
    r_max: float = 2.0                                                 # delta / delta0
    s: list[float] = field(default_factory=lambda: [math.inf, -math.inf])   # S (eq. 48)
    e: list[float] = field(default_factory=lambda: [math.inf, -math.inf])   # E (eq. 48)

    @classmethod
    def typical(cls) -> Extents:
        return cls(v=[0.0, TYPICAL_V_MAX], omega=[0.0, TYPICAL_OMEGA_MAX], r_max=TYPICAL_R_MAX)

    @staticmethod
    def _grow(span: list[float], values: np.ndarray) -> None:
        values = values[np.isfinite(values)]
        if len(values):
            span[0], span[1] = min(span[0], float(values.min())), max(span[1],
                                                                        float(values.max()))

    def add(self, v: np.ndarray, omega: np.ndarray, r: np.ndarray, s: np.ndarray,
            e: np.ndarray) -> None:
        self._grow(self.v, v)
        self._grow(self.omega, omega)
        if np.isfinite(r).any():
            self.r_max = max(self.r_max, float(np.nanmax(r)))
        self._grow(self.s, s)
        self._grow(self.e, e)


@dataclass(frozen=True)
class ViewFrames:
    phase: Frame2D
    bottom_hole: Frame2D
    es: Frame2D


def es_reference(units: PaperUnits) -> np.ndarray:
    """(S, E) of the cutting point (1, 1) and of the trivial solution (eq. 34)."""
    if units.delta0 <= 0.0:
        return np.array([[1.0, 1.0]])
    return np.array([[1.0, 1.0], [units.w0 / units.delta0, units.t0 / units.delta0]])


def es_frame(units: PaperUnits, extents: Extents) -> Frame2D:
    """The reference points, the data (capped at ES_CAP x the references) and a margin."""
    ref = es_reference(units)
    s_cap, e_cap = ES_CAP * ref[:, 0].max(), ES_CAP * ref[:, 1].max()
    s_lo = min(ref[:, 0].min(), extents.s[0])
    s_hi = max(ref[:, 0].max(), min(extents.s[1], s_cap))
    e_lo = min(ref[:, 1].min(), extents.e[0])
    e_hi = max(ref[:, 1].max(), min(extents.e[1], e_cap))
    s_pad, e_pad = 0.08 * (s_hi - s_lo) + 1e-3, 0.08 * (e_hi - e_lo) + 1e-3
    return box_frame(s_lo - s_pad, s_hi + s_pad, e_lo - e_pad, e_hi + e_pad, ES_ASPECT)


def view_frames(units: PaperUnits, extents: Extents) -> ViewFrames:
    """The three 2D frames for these extents (always holding (0, 0) and the trivial state)."""
    phase = box_frame(min(0.0, extents.v[0]), max(1.0, extents.v[1]),
                      min(0.0, extents.omega[0]), max(1.0, extents.omega[1]), PHASE_ASPECT)
    return ViewFrames(phase=phase, bottom_hole=polar_frame(max(2.0, extents.r_max)),
                      es=es_frame(units, extents))
