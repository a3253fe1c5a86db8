"""One point of a controlled map: the closed-loop bench at that point's surface rpm and WOB.

The point is a :class:`~drill_sim_ros.control.scenario.Scenario` of the map's preset with one
setpoint (the point's rpm and WOB from t = 0), the map's controller, mode and switch-on, and
a duration of ``tau_end`` t*; :func:`~drill_sim_ros.control.bench.run_in_process` runs it
(sim_node's session, drive and limits, 100 Hz control period) and its figures come from the
same functions as elsewhere, over the window [average_from, tau_end] t*:

* ``ssi``, ``utr``, ``stick_fraction``, ``rop_m_h``: the scorecard
  (:func:`~drill_sim_ros.control.scorecard.score`, window start as its statistics start):
  the mean SSI of whole 20 s windows, UTR against the setpoint, the share of control-period
  samples stuck, the mean ROP;
* ``kappa``, ``eta``, means, E, S: :func:`analysis.cycle_averages` of the kernel's running
  sums over the window (every step, as in an open-loop map);
* ``first_stick_tau``, ``bounce_tau``: the kernel's, whole run;
* ``omega_min``, ``omega_max``, ``torsional_period``, ``axial_amplitude``: from the telemetry
  sampled every control period (0.0135 t* on the field preset);
* ``regime``: :func:`regime.classify` of those.

The bench's numerics are sim_node's (the preset's Δτ and nodes, perturbation v₀ + 1e-3):
the map's ``--dtau``, ``--nodes`` and ``--perturb-v`` do not apply to a controlled map.
"""

from __future__ import annotations

import math

import numpy as np

from drill_sim_ros.control.bench import ClosedLoopRun, run_in_process
from drill_sim_ros.control.scenario import Scenario
from drill_sim_ros.model import analysis
from drill_sim_ros.model import kernel as k
from drill_sim_ros.model.defaults import PERTURB_V
from drill_sim_ros.model.errors import NumericalFault
from drill_sim_ros.model.params import DimensionlessParams, Scales
from drill_sim_ros.model.telemetry import TELEMETRY_INDEX as F
from drill_sim_ros.study.grid import MapSpec
from drill_sim_ros.study.point import N_VARS, row_of, torsional_period
from drill_sim_ros.study.regime import classify, trivial_kappa

CONTROL_RATE_HZ = 100.0          # the bench's (and sim_node's) control period: 10 ms
# running sums of the kernel (differences over a window are window sums)
_SUMS = [k.A_COUNT, k.A_WF, k.A_TOB, k.A_DOC, k.A_WOB, k.A_OMEGA, k.A_T_PIPE, k.A_V, k.A_STUCK]


def point_setpoints(spec: MapSpec, flat: int) -> tuple[float, float]:
    """(surface rpm, applied WOB in N) of point ``flat``: its axes, else the base case."""
    p, sc = spec.point(flat), spec.scales
    assert sc is not None
    return sc.rpm(p.omega0), sc.wob_n(p.w0)


def scenario_for(spec: MapSpec, flat: int) -> Scenario:
    """The closed-loop scenario of point ``flat`` of a controlled map."""
    assert spec.control is not None and spec.scales is not None
    rpm, wob_n = point_setpoints(spec, flat)
    c = spec.control
    return Scenario(preset=spec.preset, duration_s=spec.numerics.tau_end * spec.scales.time_s,
                    control_rate_hz=CONTROL_RATE_HZ, mode=c.mode, controller=c.controller,
                    enable_at_s=c.enable_at_s,
                    schedule=({"t_s": 0.0, "rpm": rpm, "wob_n": wob_n},))


def window_start_s(spec: MapSpec, scenario: Scenario) -> float:
    """Start of the statistics window in s, on the control period grid."""
    assert spec.scales is not None
    return window_periods(spec, scenario) * scenario.period_s


def window_periods(spec: MapSpec, scenario: Scenario) -> int:
    assert spec.scales is not None
    start = round(spec.numerics.average_from * spec.scales.time_s * scenario.control_rate_hz)
    return min(start, scenario.periods - 1)


def evaluate_closed_point(spec: MapSpec, flat: int) -> np.ndarray:
    """Run point ``flat`` closed-loop; the :data:`point.VARIABLES` (NaN where undefined)."""
    scenario = scenario_for(spec, flat)
    try:
        run = run_in_process(scenario, snapshot_after=window_periods(spec, scenario))
    except NumericalFault:
        return np.full(N_VARS, math.nan)
    with np.errstate(divide="ignore", invalid="ignore"):
        return closed_loop_figures(spec, spec.point(flat), run)


def closed_loop_figures(spec: MapSpec, p: DimensionlessParams,
                        run: ClosedLoopRun) -> np.ndarray:
    """The map variables of a finished closed-loop ``run`` of point ``p`` (module doc)."""
    scenario, sc = run.scenario, spec.scales
    assert sc is not None and run.accumulators is not None and run.snapshot is not None
    start_s = window_start_s(spec, scenario)
    card = run.score(start_s)
    acc = run.accumulators.copy()
    acc[_SUMS] -= run.snapshot[_SUMS]
    avg = analysis.cycle_averages(p, acc)
    window = run.rows[run.rows[:, F["sim_time_s"]] > start_s]
    tau, omega, v = _window_signals(window, sc)
    stick, bounce = analysis.first_event_tau(run.accumulators)
    amplitude = 0.5 * float(v.max() - v.min()) if v.size else math.nan
    bounce_tau = math.nan if bounce is None else bounce
    values = {
        "kappa": avg.kappa,
        "kappa_from_depth": analysis.kappa_from_depth(
            avg.mean_depth_of_cut, analysis.trivial_solution(p).depth_of_cut, p.lam),
        "eta": avg.eta, "mean_depth_of_cut": avg.mean_depth_of_cut,
        "mean_torque": avg.mean_torque, "mean_wob": avg.mean_wob,
        "specific_energy": avg.specific_energy, "drilling_strength": avg.drilling_strength,
        "ssi": _number(card["ssi_mean"]), "utr": _number(card["utr"]),
        "omega_min": float(omega.min()), "omega_max": float(omega.max()),
        "stick_fraction": card["stick_fraction"],
        "first_stick_tau": math.nan if stick is None else stick, "bounce_tau": bounce_tau,
        "torsional_period": torsional_period(tau, omega), "axial_amplitude": amplitude,
        "rop_m_h": card["rop_m_h"],
        "regime": classify(card["stick_fraction"], bounce_tau, avg.kappa, amplitude,
                           PERTURB_V, trivial_kappa(p.w0, p.lam)),
    }
    return row_of(values)


def _window_signals(rows: np.ndarray,
                    sc: Scales) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(tau, omega, v) in model units from SI telemetry rows (the inverse of the telemetry's
    factors: time / t*, rpm by ``omega_from_rpm``, ROP / (L*/t*))."""
    tau = rows[:, F["sim_time_s"]] / sc.time_s
    omega = sc.omega_from_rpm(rows[:, F["bit_rpm"]])
    v = rows[:, F["rop_m_s"]] / sc.rop_m_s(1.0)
    return tau, omega, v


def _number(value: float | None) -> float:
    return math.nan if value is None else float(value)
