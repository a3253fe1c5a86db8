"""The scorecard of a closed-loop run: how much stick-slip is left, and at what cost.

ROS-free; from telemetry rows (``TELEMETRY_FIELDS``, SI) of a run, after the switch-on:

* stick-slip is judged on the bit speed low-passed at the rig's cut-off
  (``RigPhysics.cutoff_hz``, twice the string's third torsional mode;
  ``model.analysis.lowpass``, zero-phase): on a distributed string the collars ring at the
  bit an order of magnitude faster (high-frequency torsional oscillation, HFTO), and a
  ring that touches zero is no stick phase. A sample is stuck when the low-passed bit
  speed is below ``STUCK_RPM``;
* SSI over whole 20 s windows (``model.analysis.stick_slip_index``, the one SSI:
  (max - min) / (2 mean) of the low-passed bit rpm), mean and max, that of the last window
  (settled), and the mean before the switch-on;
* stick fraction (share of samples stuck), UTR = (omega_0 - min) / omega_0 of the raw bit
  speed (``model.analysis.severity_of``, omega_0 the mean setpoint of the schedule);
* time to suppress: from the switch-on to the last stuck sample (0 if none; None when the
  bit still sticks in the last 20 s, or when the quiet end is no longer than the longest
  spell the bit turned between two sticks after the switch-on: an intermittent stick-slip
  is not ended by one quiet window);
* period: the dominant period of the low-passed bit speed (its spectral peak above
  ``PERIOD_MIN_HZ``; None when it is flat: no spectral line of ``MIN_OSCILLATION_RMS_RPM``);
* HFTO: the RMS of the bit speed above the cut-off (raw minus low-passed), its dominant
  frequency (None below ``MIN_OSCILLATION_RMS_RPM``), and the cut-off used;
* mean ROP (m/h); mechanical specific energy at the bit (Teale 1965: <WOB>/A +
  <TOB omega_bit>/(A <ROP>), MPa);
* peak and RMS string torque at the quill (N m), motor energy (the motor's work
  sum tau_m omega_drive P, MJ), saturation count (samples at the motor torque limit or with
  the speed setpoint at 0 or at the rpm limit) and saturation fraction (share of samples
  with the motor torque at its limit, alone);
* status: ``stalled`` when the bit is stuck for good (stuck without a break for the last
  ``STALL_S`` seconds or more of the run; ``stall_time_s`` is when that span began),
  else ``stick-slip`` when the stick-slip is not suppressed (time to suppress None), else
  ``ok``. (A run that ends in a numerical fault has no rows to score: its runner reports
  ``fault``.)
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from drill_sim_ros.control.rig import RigPhysics
from drill_sim_ros.control.schedule import Schedule
from drill_sim_ros.model import analysis, defaults
from drill_sim_ros.model.errors import ParameterError
from drill_sim_ros.model.params import RPM_PER_RAD_S
from drill_sim_ros.model.telemetry import TELEMETRY_INDEX

F = TELEMETRY_INDEX
STUCK_RPM = 1.0           # low-passed bit speed below this: stuck (on the lumped twin the
                          # raw stuck share 0.208 reads 0.211 by this rule)
MIN_OSCILLATION_RMS_RPM = 0.1   # below this RMS a component has no frequency (flat)
PERIOD_MIN_HZ = 0.02      # the slowest stick-slip the period looks for (50 s)
WINDOW_S = defaults.WINDOW_S  # the severity window of sim_node's /diagnostics
STALL_S = 10.0            # stuck this long at the end of a run: stalled (a stick phase of
                          # the field case's stick-slip lasts 2-4 s)
SCORE_FIELDS = ("ssi_before_mean", "ssi_mean", "ssi_max", "ssi_last", "stick_fraction", "utr",
                "time_to_suppress_s", "rop_m_h", "mse_mpa", "quill_torque_peak_nm",
                "quill_torque_rms_nm", "motor_energy_mj", "saturation_count",
                "saturation_fraction", "period_s", "hfto_rms_rpm", "hfto_hz", "cutoff_hz",
                "status", "stall_time_s")
STATUSES = ("ok", "stick-slip", "stalled", "fault")


def window_ssi(time_s: np.ndarray, bit_rpm: np.ndarray, start_s: float, end_s: float,
               window_s: float = WINDOW_S) -> np.ndarray:
    """SSI of each whole window [start + k w, start + (k + 1) w) within [start, end]; the
    span itself when no whole window fits."""
    count = math.floor((end_s - start_s) / window_s + 1e-9)
    edges = [(start_s + k * window_s, start_s + (k + 1) * window_s) for k in range(count)]
    edges = edges or [(start_s, end_s)]
    lo, hi, mean = [], [], []
    for a, b in edges:
        part = bit_rpm[(time_s > a) & (time_s <= b + 1e-9)]
        if part.size:
            lo.append(part.min())
            hi.append(part.max())
            mean.append(part.mean())
    return analysis.stick_slip_index(lo, hi, mean)


def _mean(values: np.ndarray) -> float | None:
    return float(np.mean(values)) if values.size and np.isfinite(values).all() else None


def score(rows: np.ndarray, enable_at_s: float, schedule: Schedule, rig: RigPhysics,
          period_s: float) -> dict[str, Any]:
    """The scorecard of ``rows`` (see the module doc); None where a figure is undefined."""
    rows = rows[rows[:, F["sim_time_s"]] > 0.0]          # the t = 0 sample is no period
    t = rows[:, F["sim_time_s"]]
    end_s = float(t[-1])
    slow_all = lowpassed_bit_rpm(rows, rig.cutoff_hz)
    is_after = t > enable_at_s
    if not is_after.any():
        raise ParameterError(f"scorecard: the switch-on at {enable_at_s:g} s leaves nothing to "
                             f"score; the run ends at {end_s:g} s (enable_at_s must come "
                             "before the end)")
    after, slow = rows[is_after], slow_all[is_after]
    ta = after[:, F["sim_time_s"]]
    bit = after[:, F["bit_rpm"]]
    stuck = slow < STUCK_RPM
    ssi = window_ssi(ta, slow, enable_at_s, end_s)
    before = window_ssi(t, slow_all, 0.0, enable_at_s) if enable_at_s >= WINDOW_S else \
        np.array([])
    omega0_rpm = float(np.mean([schedule.rpm_at(x) for x in ta]))
    sev = analysis.severity_of(float(bit.min()), float(bit.max()), float(bit.mean()),
                               omega0_rpm)
    suppress_s = _time_to_suppress(ta, stuck, enable_at_s, end_s)
    stall_s = stall_time_s(t, slow_all < STUCK_RPM)
    status = "stalled" if stall_s is not None else "stick-slip" if suppress_s is None \
        else "ok"
    return {
        "ssi_before_mean": _mean(before), "ssi_mean": _mean(ssi),
        "ssi_max": float(np.max(ssi)) if np.isfinite(ssi).all() else None,
        "ssi_last": float(ssi[-1]) if np.isfinite(ssi[-1]) else None,
        "stick_fraction": float(stuck.mean()), "utr": sev.utr,
        "time_to_suppress_s": suppress_s,
        **_costs(after, rig, period_s),
        "period_s": _period_s(slow, sample_period_s(rows)),
        **_hfto(bit - slow, sample_period_s(rows), rig.cutoff_hz),
        "status": status, "stall_time_s": stall_s,
    }


def _costs(after: np.ndarray, rig: RigPhysics, period_s: float) -> dict[str, Any]:
    """ROP, specific energy, quill torque, motor energy and saturation of ``after``."""
    rop = after[:, F["rop_m_s"]]
    quill = after[:, F["surface_torque_nm"]]
    motor = after[:, F["motor_torque_nm"]]
    drive_rad_s = after[:, F["surface_rpm"]] / RPM_PER_RAD_S
    bit_power_w = after[:, F["tob_nm"]] * after[:, F["bit_rpm"]] / RPM_PER_RAD_S
    mse_pa = (after[:, F["wob_n"]].mean() + bit_power_w.mean() / rop.mean()) / rig.bit_area_m2 \
        if rop.mean() > 0 else math.nan
    return {
        "rop_m_h": float(rop.mean() * 3600.0),
        "mse_mpa": mse_pa * 1e-6 if math.isfinite(mse_pa) else None,
        "quill_torque_peak_nm": float(np.max(np.abs(quill))),
        "quill_torque_rms_nm": float(np.sqrt(np.mean(quill**2))),
        "motor_energy_mj": float(np.sum(motor * drive_rad_s) * period_s * 1e-6),
        "saturation_count": int(saturated(after, rig).sum()),
        "saturation_fraction": float(at_torque_limit(after, rig).mean()),
    }


def sample_period_s(rows: np.ndarray) -> float:
    """The sampling period of ``rows`` (s): the median step of their time (1 if one row)."""
    t = rows[:, F["sim_time_s"]]
    return float(np.median(np.diff(t))) if t.size > 1 else 1.0


def lowpassed_bit_rpm(rows: np.ndarray, cutoff_hz: float) -> np.ndarray:
    """The bit speed of ``rows`` (uniformly sampled) below ``cutoff_hz``: what stick-slip is
    judged on (rpm, shape (rows,))."""
    return analysis.lowpass(rows[:, F["bit_rpm"]], sample_period_s(rows), cutoff_hz)


def at_torque_limit(rows: np.ndarray, rig: RigPhysics) -> np.ndarray:
    """Samples with the motor torque at the drive's limit (either sign)."""
    return np.abs(rows[:, F["motor_torque_nm"]]) >= rig.max_torque_nm * (1 - 1e-9)


def saturated(rows: np.ndarray, rig: RigPhysics) -> np.ndarray:
    """Samples where the drive is saturated: the motor torque at its limit, or the speed
    setpoint at 0 or at the rpm limit (to the same relative 1e-9 as the torque: a setpoint
    clamped to the limit comes back through the kernel's time scale an ulp off)."""
    setpoint = rows[:, F["speed_setpoint_rpm"]]
    return at_torque_limit(rows, rig) | (setpoint <= 0.0) \
        | (setpoint >= rig.max_surface_rpm * (1 - 1e-9))


def _period_s(slow_rpm: np.ndarray, sample_period_s: float) -> float | None:
    """The dominant period of the low-passed bit speed; None when it is flat: no line of
    its spectrum above PERIOD_MIN_HZ is a sine of MIN_OSCILLATION_RMS_RPM (a transient at
    the record's ends, where the low-pass is least sure, makes no line)."""
    peak = analysis.spectral_peak(slow_rpm, sample_period_s, PERIOD_MIN_HZ)
    if peak is None or peak[1] < math.sqrt(2.0) * MIN_OSCILLATION_RMS_RPM:
        return None
    return 1.0 / peak[0]


def _hfto(fast_rpm: np.ndarray, sample_period_s: float, cutoff_hz: float) -> dict[str, Any]:
    """RMS and dominant frequency of the bit speed above the cut-off, and the cut-off."""
    rms = float(np.sqrt(np.mean(fast_rpm**2)))
    peak = analysis.spectral_peak(fast_rpm, sample_period_s, cutoff_hz) \
        if rms >= MIN_OSCILLATION_RMS_RPM else None
    return {"hfto_rms_rpm": rms, "hfto_hz": None if peak is None else peak[0],
            "cutoff_hz": cutoff_hz if math.isfinite(cutoff_hz) else None}


def stall_time_s(time_s: np.ndarray, stuck: np.ndarray, stall_s: float = STALL_S
                 ) -> float | None:
    """When the bit got stuck for good: the start of the stuck span that ends the run, if it
    lasts ``stall_s`` or more; None otherwise."""
    if not stuck.size or not stuck[-1]:
        return None
    moving = np.flatnonzero(~stuck)
    first = int(moving[-1]) + 1 if moving.size else 0
    start_s = float(time_s[first])
    return start_s if float(time_s[-1]) - start_s >= stall_s else None


def longest_gap_s(t: np.ndarray, stuck: np.ndarray) -> float:
    """The longest time the bit turned between two of its stick phases (0 with fewer than
    two): how long a quiet spell of this run's own stick-slip can last."""
    edges = np.diff(stuck.astype(np.int8))
    ends, starts = np.flatnonzero(edges == -1), np.flatnonzero(edges == 1) + 1
    starts = starts[starts > ends[0]] if ends.size else starts
    gaps = t[starts[:ends.size]] - t[ends[:starts.size]]
    return float(gaps.max()) if gaps.size else 0.0


def _time_to_suppress(t: np.ndarray, stuck: np.ndarray, enable_at_s: float,
                      end_s: float) -> float | None:
    """From the switch-on to the last stuck sample; None unless the run ends quiet for the
    severity window and for longer than any spell it turned between sticks after the
    switch-on: intermittent stick-slip (the default case's sticks come 4-115 s apart) is
    not suppressed by one quiet window."""
    if not stuck.any():
        return 0.0
    last_s = float(t[stuck][-1])
    quiet_s = end_s - last_s
    if quiet_s < WINDOW_S or quiet_s <= longest_gap_s(t, stuck):
        return None
    return last_s - enable_at_s


def status_text(card: dict[str, Any]) -> str:
    """``ok``, ``stick-slip``, ``stalled at 42.1 s``, ``fault at 3.20 s`` or as given."""
    status = str(card.get("status", ""))
    if status == "stalled":
        return f"stalled at {card['stall_time_s']:.1f} s"
    if status == "fault":
        return f"fault at {card['fault_time_s']:.2f} s"
    return status


def summarize(cards: list[dict[str, Any]]) -> dict[str, str]:
    """Several scorecards of one case (an ensemble's members) in a few cells: the runs, how
    many read stick-slip / ok / stalled / other, and median (min-max) of the SSI after the
    switch-on, of the SSI of the last 20 s and of the stick fraction, and median (max) of
    the share at the torque limit; ``-`` where no card has a finite value."""
    kinds = [status_text(card).split(" ")[0] for card in cards]
    counts = [kinds.count(kind) for kind in ("stick-slip", "ok", "stalled")]
    counts.append(len(kinds) - sum(counts))
    limit = _finite(card.get("saturation_fraction") for card in cards)
    return {"runs": str(len(cards)), "counts": " / ".join(map(str, counts)),
            "ssi_mean": _spread(card.get("ssi_mean") for card in cards),
            "ssi_last": _spread(card.get("ssi_last") for card in cards),
            "stick_fraction": _spread(card.get("stick_fraction") for card in cards),
            "saturation_fraction": f"{np.median(limit):.1%} ({max(limit):.1%})" if limit
                                   else "-"}


def _finite(values: Any) -> list[float]:
    return [float(v) for v in values if isinstance(v, (int, float)) and math.isfinite(v)]


def _spread(values: Any) -> str:
    x = _finite(values)
    return f"{np.median(x):.2f} ({min(x):.2f}-{max(x):.2f})" if x else "-"
