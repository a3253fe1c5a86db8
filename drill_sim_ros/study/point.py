"""One point of a map: a run of the Simulator and its figures (those of ``drill_sim run``).

Averages are over [average_from, tau_end], stick phases included, from the kernel's
accumulators (:func:`analysis.cycle_averages`, eqs. 42-48). The bit speed and axial
velocity are also sampled in that window (every ``SAMPLE_DTAU``) for the period of the
torsional cycle and the axial amplitude.
"""

from __future__ import annotations

import math

import numpy as np

from drill_sim_ros.model import analysis
from drill_sim_ros.model import kernel as k
from drill_sim_ros.model.errors import NumericalFault
from drill_sim_ros.model.params import DimensionlessParams
from drill_sim_ros.model.simulator import SimConfig, Simulator
from drill_sim_ros.study.grid import Numerics
from drill_sim_ros.study.regime import classify, trivial_kappa

SAMPLE_DTAU = 0.01        # window sampling of omega and v (axial periods are >= ~0.1)
CHUNK_STEPS = 500_000
SCHMITT_FRACTION = 0.25   # hysteresis of the period detector, of the half range of omega

# name: (units, description). The order is the column order of evaluate_point's output.
VARIABLES: dict[str, tuple[str, str]] = {
    "regime": ("1", "0 trivial, 1 axial vibration only, 2 stick-slip, 3 bit bouncing"),
    "kappa": ("1", "intermittent loss of contact, eq. 42: 1 - <W_f>/lambda"),
    "kappa_from_depth": ("1", "kappa from the mean depth of cut, eq. 45a: "
                              "(<delta> - delta0)/lambda"),
    "eta": ("1", "drilling efficiency, eq. 43"),
    "mean_depth_of_cut": ("L*", "<delta>, time average"),
    "mean_torque": ("C", "<T>, time average (torque on bit)"),
    "mean_wob": ("zeta eps a L*", "<W>, time average (weight on bit)"),
    "specific_energy": ("1", "E = <T>/<delta>, eq. 48"),
    "drilling_strength": ("1", "S = <W>/<delta>, eq. 48"),
    "ssi": ("1", "stick-slip severity (max - min)/(2 mean) of the bit speed"),
    "utr": ("1", "under-torque ratio (omega0 - min)/omega0 of the bit speed"),
    "omega_min": ("1/t*", "minimum bit speed in the window"),
    "omega_max": ("1/t*", "maximum bit speed in the window"),
    "stick_fraction": ("1", "fraction of the window spent stuck"),
    "first_stick_tau": ("t*", "time of the first stick (NaN: none), tau_sk of Fig. 9"),
    "bounce_tau": ("t*", "time the bit first left the rock (NaN: never)"),
    "torsional_period": ("t*", "period of the bit-speed cycle in the window (NaN: < 2 cycles)"),
    "axial_amplitude": ("L*/t*", "half the range of the axial velocity in the window"),
    "rop_m_h": ("m/h", "mean rate of penetration (controlled maps; NaN in open-loop maps)"),
}
N_VARS = len(VARIABLES)
COLUMN = {name: i for i, name in enumerate(VARIABLES)}


def evaluate_point(params: DimensionlessParams, num: Numerics) -> np.ndarray:
    """Run one point; returns the :data:`VARIABLES` as float64 (NaN where undefined)."""
    sim = Simulator(params, SimConfig(dtau=num.dtau, n_nodes=num.n_nodes, method=num.method,
                                      tau_avg=num.average_from),
                    perturb_v=num.perturb_v, perturb_omega=num.perturb_omega)
    try:
        tau, omega, v = _run(sim, num)
    except NumericalFault:
        return np.full(N_VARS, math.nan)
    with np.errstate(divide="ignore", invalid="ignore"):   # <delta> = 0: E, S infinite
        return _figures(params, num, sim.accumulators, tau, omega, v)


def _run(sim: Simulator, num: Numerics) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Step to tau_end; sample (tau, omega, v) every SAMPLE_DTAU inside the window."""
    total = sim.steps_for(num.tau_end)
    before = min(total, math.ceil(num.average_from / num.dtau))
    every = max(1, round(SAMPLE_DTAU / num.dtau))
    _advance(sim, before, 0)
    rows = _advance(sim, total - before, every)
    return rows[:, k.C_TAU], rows[:, k.C_OMEGA], rows[:, k.C_V]


def _advance(sim: Simulator, steps: int, every: int) -> np.ndarray:
    parts = []
    while steps > 0:
        n = min(steps, CHUNK_STEPS)
        parts.append(sim.advance(n, every=every).data)
        steps -= n
    return np.concatenate(parts) if parts else np.empty((0, k.N_COLS))


def _figures(p: DimensionlessParams, num: Numerics, acc: np.ndarray, tau: np.ndarray,
             omega: np.ndarray, v: np.ndarray) -> np.ndarray:
    avg = analysis.cycle_averages(p, acc)
    sev = analysis.severity_of(avg.omega_min, avg.omega_max, avg.mean_omega, p.omega0)
    stick, bounce = analysis.first_event_tau(acc)
    delta0 = analysis.trivial_solution(p).depth_of_cut
    amplitude = 0.5 * float(v.max() - v.min()) if v.size else math.nan
    values = {
        "kappa": avg.kappa,
        "kappa_from_depth": analysis.kappa_from_depth(avg.mean_depth_of_cut, delta0, p.lam),
        "eta": avg.eta, "mean_depth_of_cut": avg.mean_depth_of_cut,
        "mean_torque": avg.mean_torque, "mean_wob": avg.mean_wob,
        "specific_energy": avg.specific_energy, "drilling_strength": avg.drilling_strength,
        "ssi": sev.ssi if math.isfinite(sev.ssi) else math.nan, "utr": sev.utr,
        "omega_min": avg.omega_min, "omega_max": avg.omega_max,
        "stick_fraction": avg.stick_fraction,
        "first_stick_tau": math.nan if stick is None else stick,
        "bounce_tau": math.nan if bounce is None else bounce,
        "torsional_period": torsional_period(tau, omega),
        "axial_amplitude": amplitude,
    }
    values["regime"] = classify(avg.stick_fraction, values["bounce_tau"], avg.kappa,
                                amplitude, num.perturb_v, trivial_kappa(p.w0, p.lam))
    return row_of(values)


def row_of(values: dict[str, float]) -> np.ndarray:
    """A row in :data:`VARIABLES` order; NaN for the variables not in ``values``."""
    out = np.full(N_VARS, math.nan)
    for name, value in values.items():
        out[COLUMN[name]] = value
    return out


def torsional_period(tau: np.ndarray, omega: np.ndarray) -> float:
    """Mean time between upward crossings of the bit speed through the middle of its
    range, with hysteresis (a crossing counts from below mid - h to above mid + h,
    h = SCHMITT_FRACTION * half range; the middle, not the mean, so cycles that stick most
    of the time count too); NaN with fewer than two whole cycles or no oscillation."""
    if omega.size < 3:
        return math.nan
    lo, hi = float(omega.min()), float(omega.max())
    mid, half_range = 0.5 * (lo + hi), 0.5 * (hi - lo)
    if not half_range > 1e-12 * max(1.0, abs(mid)):
        return math.nan
    h = SCHMITT_FRACTION * half_range
    below, above = omega < mid - h, omega > mid + h
    events = np.flatnonzero(below | above)
    kind = above[events]
    ups = events[np.flatnonzero(kind[1:] & ~kind[:-1]) + 1]
    if ups.size < 3:
        return math.nan
    return float(tau[ups[-1]] - tau[ups[0]]) / (ups.size - 1)
