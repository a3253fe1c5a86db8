"""The scorecard of a closed-loop run: how much stick-slip is left, and at what cost.

ROS-free; from telemetry rows (``TELEMETRY_FIELDS``, SI) of a run, after the switch-on:

* stick-slip is judged on the bit speed low-passed at the rig's cut-off
  (``RigPhysics.cutoff_hz``, twice the string's third torsional mode;
  ``model.analysis.lowpass``, zero-phase): on a distributed string the collars ring at the
  bit an order of magnitude faster (7-16 Hz on the field string: the "ring" figures
  below; not the 50-400 Hz HFTO of field logs, which this model does not carry), and a
  ring that touches zero is no stick phase. A sample is stuck when the low-passed bit
  speed is below ``STUCK_RPM``; a stick (phase) is a span of consecutive stuck samples;
* SSI over whole 20 s windows (``model.analysis.stick_slip_index``, the one SSI:
  (max - min) / (2 mean) of the low-passed bit rpm), mean and max, that of the last window
  (settled), and the mean before the switch-on (None when no whole window precedes it).
  The SSI of a window grows without bound as its mean speed falls to 0; it is clipped at
  ``SSI_MAX``, and a window whose mean is below ``STUCK_RPM`` (the bit stuck nearly
  throughout) reads ``SSI_MAX``: a run stuck throughout has the largest SSI;
* stick fraction (share of samples stuck), the longest stick, UTR = (omega_0 - min) /
  omega_0 and the maximum of the raw bit speed (``model.analysis.severity_of``, omega_0 the
  mean setpoint of the schedule);
* time to suppress: from the switch-on to the last stuck sample (0 if none; None when the
  bit still sticks in the last 20 s, or when the quiet end is no longer than the longest
  spell the bit turned between two sticks after the switch-on: an intermittent stick-slip
  is not ended by one quiet window);
* period: the dominant period of the low-passed bit speed (its spectral peak above
  ``PERIOD_MIN_HZ``; None when it is flat: no spectral line of ``MIN_OSCILLATION_RMS_RPM``);
* ring: the RMS of the bit speed above the cut-off (raw minus low-passed), its dominant
  frequency (None below ``MIN_OSCILLATION_RMS_RPM``), and the cut-off used;
* the bit's axial state: the share of samples with the bit above the rock (bounce) and the
  WOB at the bit's RMS about its mean (N);
* mean ROP (m/h); mechanical specific energy at the bit (Teale 1965: <WOB>/A +
  <TOB omega_bit>/(A <ROP>), MPa);
* peak and RMS string torque at the quill (N m);
* the actuator's effort: the motor torque's RMS about its mean (its standard deviation,
  N m), its mean absolute rate between consecutive samples (kN m/s), the motor's net work
  sum tau_m omega_drive P and its positive work sum max(tau_m omega_drive, 0) P (MJ: what
  a drive that cannot regenerate draws; its braking is burnt), saturation count (samples at
  the motor torque limit or with the speed setpoint at 0 or at the rpm limit) and
  saturation fraction (share of samples with the motor torque at its limit, alone);
* status, by :func:`status_of` (one rule, in this order):

  1. ``stalled`` when the bit got stuck and stayed stuck: stuck without a break for the
     last ``STALL_S`` seconds or more of the run, and that last stick already lasts
     ``STALL_FACTOR`` times the longest stick the bit broke out of after the switch-on
     (any length when it broke out of none). A stick-slip that happens to end inside one
     of its stick phases is not a stall. ``stall_time_s`` is when that last stick began;
  2. else ``stick-slip`` when the bit was stuck ``STICK_FRACTION_OK`` (10 %) of the time
     after the switch-on or more, or the stick-slip is not suppressed (time to suppress
     None), or the SSI of the last window is ``SSI_OK`` (1) or more;
  3. else ``ok``.

  (A run that ends in a numerical fault has no rows to score: its runner reports
  ``fault``.)
"""

from __future__ import annotations

import itertools
import math
from typing import Any

import numpy as np

from drill_sim_ros.control.rig import RigPhysics
from drill_sim_ros.control.schedule import Schedule
from drill_sim_ros.model import analysis, defaults
from drill_sim_ros.model.errors import ParameterError
from drill_sim_ros.model.params import RPM_PER_RAD_S
from drill_sim_ros.model.telemetry import MODE_NAMES, TELEMETRY_INDEX

F = TELEMETRY_INDEX
OFF_BOTTOM_MODE = MODE_NAMES.index("off_bottom")   # the telemetry's mode of a bit above rock
STUCK_RPM = 1.0           # low-passed bit speed below this: stuck (on the lumped twin the
                          # raw stuck share 0.208 reads 0.211 by this rule)
MIN_OSCILLATION_RMS_RPM = 0.1   # below this RMS a component has no frequency (flat)
PERIOD_MIN_HZ = 0.02      # the slowest stick-slip the period looks for (50 s)
WINDOW_S = defaults.WINDOW_S  # the severity window of sim_node's /diagnostics
STALL_S = 10.0            # stuck this long at the end of a run: a stall candidate (the
                          # default's first-mode sticks last about 1.2 s; the sharp bit's of
                          # the default until 2026-12-06 8-17 s, so STALL_FACTOR decides there)
STALL_FACTOR = 2.0        # ... and this many times the longest stick it broke out of: a
                          # chaotic stick-slip's sticks vary by tens of percent (the sharp
                          # bit: 8.1-9.7 s uncontrolled, 9.6-14.6 s with z_torque), twice the
                          # longest is outside that spread
STICK_FRACTION_OK = 0.10  # stuck this share of the time after the switch-on: never ok
SSI_OK = 1.0              # a last window's SSI this high is stick-slip: a symmetric
                          # oscillation of SSI 1 reaches zero speed at its trough
SSI_MAX = 10.0            # the SSI of a window is clipped here, and a window whose mean is
                          # below STUCK_RPM reads it: the SSI of a square-wave stick-slip
                          # stuck a share s of the time is 1 / (2 (1 - s)); 10 is s = 0.95,
                          # over twice any window the sharp bit's reference runs turned
                          # through (at most 4.7; the default's first-mode cycle: 1.2)
SCORE_FIELDS = ("ssi_before_mean", "ssi_mean", "ssi_max", "ssi_last", "stick_fraction",
                "stick_longest_s", "utr", "bit_rpm_max", "time_to_suppress_s", "rop_m_h",
                "mse_mpa", "quill_torque_peak_nm", "quill_torque_rms_nm",
                "motor_torque_std_nm", "motor_torque_rate_mean_knm_s", "motor_energy_mj",
                "motor_energy_in_mj", "saturation_count", "saturation_fraction", "period_s",
                "ring_rms_rpm", "ring_hz", "cutoff_hz", "off_bottom_fraction", "wob_rms_n",
                "status", "stall_time_s")
STATUSES = ("ok", "stick-slip", "stalled", "fault")


def window_ssi(time_s: np.ndarray, bit_rpm: np.ndarray, start_s: float, end_s: float,
               window_s: float = WINDOW_S) -> np.ndarray:
    """SSI of each whole window [start + k w, start + (k + 1) w) within [start, end]; the
    span itself when no whole window fits. Clipped at ``SSI_MAX``, which a window whose
    mean is below ``STUCK_RPM`` reads (module doc)."""
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
    ssi = analysis.stick_slip_index(lo, hi, mean)
    return np.where(np.asarray(mean) < STUCK_RPM, SSI_MAX, np.minimum(ssi, SSI_MAX))


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
    card = {
        "ssi_before_mean": _mean(before), "ssi_mean": float(np.mean(ssi)),
        "ssi_max": float(np.max(ssi)), "ssi_last": float(ssi[-1]),
        "stick_fraction": float(stuck.mean()),
        "stick_longest_s": max((b - a for a, b in stick_spans_s(ta, stuck)), default=0.0),
        "utr": sev.utr, "bit_rpm_max": sev.omega_max,
        "time_to_suppress_s": _time_to_suppress(ta, stuck, enable_at_s, end_s),
        **_costs(after, rig, period_s),
        "period_s": _period_s(slow, sample_period_s(rows)),
        **_ring(bit - slow, sample_period_s(rows), rig.cutoff_hz),
        **axial_state(after),
    }
    stall_s = stall_time_s(t, slow_all < STUCK_RPM, enable_at_s)
    return {**card, "status": status_of(card, stall_s), "stall_time_s": stall_s}


def status_of(card: dict[str, Any], stall_s: float | None) -> str:
    """The status of a scorecard (module doc, rule 1-3): ``stalled`` when the run ends in a
    stall (``stall_s``, :func:`stall_time_s`, not None), else ``stick-slip`` or ``ok`` from
    the stick fraction, the suppression and the last window's SSI."""
    if stall_s is not None:
        return "stalled"
    if card["stick_fraction"] >= STICK_FRACTION_OK or card["time_to_suppress_s"] is None \
            or card["ssi_last"] >= SSI_OK:
        return "stick-slip"
    return "ok"


def _costs(after: np.ndarray, rig: RigPhysics, period_s: float) -> dict[str, Any]:
    """ROP, specific energy, quill torque, the motor's effort and saturation of ``after``."""
    rop = after[:, F["rop_m_s"]]
    quill = after[:, F["surface_torque_nm"]]
    bit_power_w = after[:, F["tob_nm"]] * after[:, F["bit_rpm"]] / RPM_PER_RAD_S
    mse_pa = (after[:, F["wob_n"]].mean() + bit_power_w.mean() / rop.mean()) / rig.bit_area_m2 \
        if rop.mean() > 0 else math.nan
    return {
        "rop_m_h": float(rop.mean() * 3600.0),
        "mse_mpa": mse_pa * 1e-6 if math.isfinite(mse_pa) else None,
        "quill_torque_peak_nm": float(np.max(np.abs(quill))),
        "quill_torque_rms_nm": float(np.sqrt(np.mean(quill**2))),
        **motor_effort(after, period_s),
        "saturation_count": int(saturated(after, rig).sum()),
        "saturation_fraction": float(at_torque_limit(after, rig).mean()),
    }


def axial_state(rows: np.ndarray) -> dict[str, float]:
    """The bit's axial state over ``rows``: the share of samples with the bit above the rock
    (mode ``off_bottom``: bit bounce, or the bit picked up) and the RMS of the WOB at the
    bit about its mean (N)."""
    wob = rows[:, F["wob_n"]]
    return {"off_bottom_fraction": float(np.mean(rows[:, F["mode"]] == OFF_BOTTOM_MODE)),
            "wob_rms_n": float(np.std(wob))}


def motor_effort(rows: np.ndarray, period_s: float) -> dict[str, float]:
    """The motor's effort over ``rows`` (consecutive samples ``period_s`` apart): its
    torque's RMS about its mean (N m), the mean absolute rate of its torque between
    consecutive samples (kN m/s; 0 for one sample), its net work sum tau_m omega_drive P
    and its positive work sum max(tau_m omega_drive, 0) P (MJ)."""
    motor = rows[:, F["motor_torque_nm"]]
    power_w = motor * rows[:, F["surface_rpm"]] / RPM_PER_RAD_S
    rate = np.abs(np.diff(motor)) / period_s
    return {"motor_torque_std_nm": float(np.std(motor)),
            "motor_torque_rate_mean_knm_s": float(rate.mean() * 1e-3) if rate.size else 0.0,
            "motor_energy_mj": float(np.sum(power_w) * period_s * 1e-6),
            "motor_energy_in_mj": float(np.sum(np.maximum(power_w, 0.0)) * period_s * 1e-6)}


def time_step_s(t: np.ndarray, single: float) -> float:
    """The median step of the times ``t`` (s); ``single`` when there is one time or none."""
    return float(np.median(np.diff(t))) if t.size > 1 else single


def sample_period_s(rows: np.ndarray) -> float:
    """The sampling period of ``rows`` (s): the median step of their time (1 if one row)."""
    return time_step_s(rows[:, F["sim_time_s"]], 1.0)


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


def _ring(fast_rpm: np.ndarray, sample_period_s: float, cutoff_hz: float) -> dict[str, Any]:
    """RMS and dominant frequency of the bit speed above the cut-off, and the cut-off."""
    rms = float(np.sqrt(np.mean(fast_rpm**2)))
    peak = analysis.spectral_peak(fast_rpm, sample_period_s, cutoff_hz) \
        if rms >= MIN_OSCILLATION_RMS_RPM else None
    return {"ring_rms_rpm": rms, "ring_hz": None if peak is None else peak[0],
            "cutoff_hz": cutoff_hz if math.isfinite(cutoff_hz) else None}


def stick_spans_s(t: np.ndarray, stuck: np.ndarray) -> list[tuple[float, float]]:
    """Each stick of ``stuck`` (samples at times ``t``, P apart) as (start, end) in s: from
    its first stuck sample to one period after its last, so a stick of n samples lasts n P
    and the turning between two sticks is P per turning sample."""
    edges = np.diff(np.concatenate(([0], stuck.astype(np.int8), [0])))
    starts, ends = np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)
    step = time_step_s(t, 0.0)
    return [(float(t[a]), float(t[b - 1]) + step) for a, b in zip(starts, ends, strict=True)]


def stall_time_s(time_s: np.ndarray, stuck: np.ndarray, enable_at_s: float = 0.0,
                 stall_s: float = STALL_S) -> float | None:
    """When the bit got stuck for good (module doc, rule 1): the start of the stick that
    ends the run, if it lasts ``stall_s`` or more and ``STALL_FACTOR`` times the longest
    stick that ended after ``enable_at_s``; None otherwise."""
    spans = stick_spans_s(time_s, stuck)
    if not spans or not stuck[-1]:
        return None
    start_s, end_s = spans[-1]
    broke_out = [b - a for a, b in spans[:-1] if b > enable_at_s]
    lasts_s = end_s - start_s
    if lasts_s < stall_s or lasts_s < STALL_FACTOR * max(broke_out, default=0.0):
        return None
    return start_s


def longest_gap_s(t: np.ndarray, stuck: np.ndarray) -> float:
    """The longest time the bit turned between two of its sticks (0 with fewer than two):
    how long a quiet spell of this run's own stick-slip can last."""
    spans = stick_spans_s(t, stuck)
    return max((b[0] - a[1] for a, b in itertools.pairwise(spans)), default=0.0)


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
