"""The start of rotation off bottom: how the bit breaks away, and whether it then sticks.

ROS-free, SI in and out. The string hangs off bottom at rest and untwisted, the hook fixed
(:meth:`Simulator.start_at_rest`); the drive's own speed loop (the preset's gains, limit and
inertia) ramps its setpoint linearly from 0 to ``rpm`` in ``ramp_s`` (0: a step). With a
deviated ``well:`` block the wall's Coulomb friction holds the string until the twist the
drive winds in overcomes it; without one the bit follows at once.

Definitions of :func:`startup_scores` (the bit speed in rev/min, judged below the cut-off
between stick-slip and ringing, twice the string's third torsional mode, zero-phase:
:func:`judged_rpm`; ``bit_rpm_max`` is the raw speed's):

* the bit *turns* above ``TURNING_RPM`` (1 rpm); it is *stuck* while |bit speed| is below it;
* the bit *slips* above ``SLIP_RPM`` (30 rpm);
* a *stick* is a run of consecutive stuck samples; it lasts from its first stuck sample to
  the first sample after it;
* the *slip after a stick* is the first sample above ``SLIP_RPM`` after the stick ends and
  before the next stick of at least ``MIN_STICK_S``: a shorter dip below ``TURNING_RPM``, as
  a bit that creeps before it breaks free makes, does not end the search;
* *stick-slip* (in the second half of the run): at least one stick of at least
  ``MIN_STICK_S`` (0.5 s) followed by a slip there; ``period_s`` is the mean time between
  such slips (null with fewer than two).

The second half is the samples at t >= (t_first + t_last) / 2, taken on its own (a stick
that began before it counts from its start).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from drill_sim_ros.model import kernel as k
from drill_sim_ros.model.analysis import MODE_COUNT, cutoff_of, lowpass
from drill_sim_ros.model.checks import number_in
from drill_sim_ros.model.defaults import MAX_SURFACE_RPM
from drill_sim_ros.model.errors import ParameterError
from drill_sim_ros.model.params import RPM_PER_RAD_S
from drill_sim_ros.model.presets import Preset
from drill_sim_ros.model.simulator import Samples, SimConfig, Simulator
from drill_sim_ros.model.string import analytic_modes_hz

TURNING_RPM = 1.0        # the bit turns above this; |bit speed| below it: stuck
SLIP_RPM = 30.0          # the bit slips above this
MIN_STICK_S = 0.5        # the shortest stick that counts towards stick-slip
TIME_TOLERANCE_S = 1e-9  # sample times are sums of steps: 0.5 s may read 0.4999999
MAX_SECONDS = 3600.0     # the longest run, s of simulated time
MAX_RAMP_S = 3600.0      # the longest ramp, s
SAMPLE_HZ_RANGE = (1.0, 10_000.0)
CHUNK_STEPS = 500_000    # steps between progress reports (rounded to whole samples)
RAD_PER_TURN = 2.0 * math.pi


@dataclass(frozen=True)
class StartupRun:
    """The start-up's samples in SI, each of shape (samples,): time s; bit, drive and the
    speed loop's setpoint in rev/min; motor torque and string torque at the top (the torque
    sub's) in N m; the string's twist (PHI_S - PHI) / 2 pi and the drive's turns since the
    start PHI_S / 2 pi."""

    t_s: np.ndarray
    bit_rpm: np.ndarray
    drive_rpm: np.ndarray
    setpoint_rpm: np.ndarray
    motor_torque_nm: np.ndarray
    surface_torque_nm: np.ndarray
    twist_turns: np.ndarray
    drive_turns: np.ndarray
    cutoff_hz: float = math.inf      # what the stick and slip are judged below (inf: raw)


def require_startup_preset(preset: Preset) -> None:
    """A physical preset with a distributed string (the hook and the wall need one)."""
    if not preset.is_physical:
        raise ParameterError(f"preset '{preset.name}' is dimensionless; a start-up needs a "
                             "physical preset with 'string: {model: distributed}'")
    if not preset.string.distributed:
        raise ParameterError(f"preset '{preset.name}' has a lumped string; a start-up needs "
                             "'string: {model: distributed}' (the string hangs off bottom)")


def startup_simulator(preset: Preset, rpm: float, ramp_s: float) -> Simulator:
    """The string of ``preset`` at rest off bottom, the speed loop's target ``rpm`` reached
    through a linear ramp of ``ramp_s`` (module doc)."""
    require_startup_preset(preset)
    rpm = number_in("rpm", rpm, 0.0, MAX_SURFACE_RPM, low_open=True)
    ramp_s = number_in("ramp_s", ramp_s, 0.0, MAX_RAMP_S)
    sc = preset.scales
    omega = sc.omega_from_rpm(rpm)
    rate = omega / (ramp_s / sc.time_s) if ramp_s > 0.0 else math.inf
    drive = preset.top_drive
    if drive.mode != "speed":
        drive = drive.with_(mode="speed")
    sim = Simulator(preset.params, SimConfig(dtau=preset.dtau, n_nodes=64, omega_rate=rate),
                    top_drive=drive, scales=sc, string=preset.kernel_string,
                    bit_law=preset.bit_law)
    sim.start_at_rest()
    sim.set_inputs(omega_s=omega)
    return sim


def run_startup(preset: Preset, rpm: float, ramp_s: float, seconds: float,
                sample_hz: float = 100.0,
                on_progress: Callable[[float], None] | None = None) -> StartupRun:
    """Start ``preset``'s string from rest off bottom (module doc) and sample it for
    ``seconds`` of simulated time, at about ``sample_hz`` (a whole number of steps apart),
    from t = 0 to t = ``seconds``. ``on_progress(fraction done)`` is called between chunks."""
    seconds = number_in("seconds", seconds, 0.0, MAX_SECONDS, low_open=True)
    sample_hz = number_in("sample_hz", sample_hz, *SAMPLE_HZ_RANGE)
    sim = startup_simulator(preset, rpm, ramp_s)
    step_s = preset.dtau * preset.scales.time_s
    every = max(1, round(1.0 / (sample_hz * step_s)))
    total = every * max(1, round(seconds / (every * step_s)))
    chunk = every * max(1, CHUNK_STEPS // every)
    blocks, done = [], 0
    while done < total:
        n = min(chunk, total - done)
        blocks.append(sim.advance(n, every))
        done += n
        if on_progress is not None:
            on_progress(done / total)
    blocks.append(sim.advance(0, every))           # the state at the end
    return startup_series(blocks, preset)


def startup_series(blocks: list[Samples], preset: Preset) -> StartupRun:
    """The blocks' samples in SI (:class:`StartupRun`)."""
    sc = preset.scales

    def col(index: int) -> np.ndarray:
        return np.concatenate([b.column(index) for b in blocks])

    def rpm(index: int) -> np.ndarray:
        return col(index) / sc.time_s * RPM_PER_RAD_S

    phi_s = col(k.C_PHI_S)
    cutoff_hz = cutoff_of(tuple(analytic_modes_hz(preset.string, MODE_COUNT)))
    return StartupRun(t_s=col(k.C_TAU) * sc.time_s, bit_rpm=rpm(k.C_OMEGA),
                      drive_rpm=rpm(k.C_OMEGA_S), setpoint_rpm=rpm(k.C_OMEGA_REF),
                      motor_torque_nm=col(k.C_MOTOR_TORQUE) * sc.torque_nm,
                      surface_torque_nm=col(k.C_T_PIPE) * sc.torque_nm,
                      twist_turns=(phi_s - col(k.C_PHI)) / RAD_PER_TURN,
                      drive_turns=(phi_s - phi_s[0]) / RAD_PER_TURN, cutoff_hz=cutoff_hz)


# ---- scores -------------------------------------------------------------------------------
def startup_scores(run: StartupRun) -> dict[str, Any]:
    """The start-up's figures (module doc for the definitions), JSON-ready; None where an
    event never happens. Over the whole run: ``breakaway_s`` (the bit first above 1 rpm),
    the drive's turns ``breakaway_turns`` and the string torque at the top
    ``breakaway_torque_nm`` then, ``first_slip_s`` (first above 30 rpm),
    ``peak_motor_torque_nm`` (max |motor torque|). Over the second half: ``stick_slip``,
    ``period_s``, ``stick_fraction``, ``bit_rpm_max``, and the mean, min and max of
    ``motor_torque_nm`` and ``twist_turns``."""
    t, bit = run.t_s, judged_rpm(run)
    turning = _first_index(bit > TURNING_RPM)
    slip = _first_index(bit > SLIP_RPM)
    half = t >= 0.5 * (t[0] + t[-1])
    onsets = slip_onsets(t[half], bit[half])
    return {
        "breakaway_s": _at(t, turning),
        "breakaway_turns": _at(run.drive_turns, turning),
        "breakaway_torque_nm": _at(run.surface_torque_nm, turning),
        "first_slip_s": _at(t, slip),
        "peak_motor_torque_nm": float(np.max(np.abs(run.motor_torque_nm))),
        "stick_slip": bool(onsets),
        "period_s": float(np.mean(np.diff(onsets))) if len(onsets) >= 2 else None,
        "stick_fraction": float(np.mean(np.abs(bit[half]) < TURNING_RPM)),
        "bit_rpm_max": float(np.max(run.bit_rpm[half])),
        "motor_torque_nm": _spread(run.motor_torque_nm[half]),
        "twist_turns": _spread(run.twist_turns[half]),
        "cutoff_hz": run.cutoff_hz if math.isfinite(run.cutoff_hz) else None,
    }


def judged_rpm(run: StartupRun) -> np.ndarray:
    """The bit speed the sticks and slips are judged on: below the run's cut-off (twice the
    string's third torsional mode, :func:`analysis.cutoff_of`, zero-phase), so the ringing of
    a free bit end between the wall's contacts, and a wave's blip through a stuck bit, do
    not split a stick or pass for a break-away (the closed-loop scorecard's rule)."""
    if not math.isfinite(run.cutoff_hz) or run.t_s.size < 2:
        return run.bit_rpm
    return lowpass(run.bit_rpm, float(np.median(np.diff(run.t_s))), run.cutoff_hz)


def _first_index(mask: np.ndarray) -> int | None:
    """The first index where ``mask`` holds (None: nowhere)."""
    return int(np.argmax(mask)) if mask.any() else None


def _at(values: np.ndarray, index: int | None) -> float | None:
    return None if index is None else float(values[index])


def _spread(values: np.ndarray) -> dict[str, float]:
    return {"mean": float(np.mean(values)), "min": float(np.min(values)),
            "max": float(np.max(values))}


def stuck_spans(bit_rpm: np.ndarray) -> list[tuple[int, int]]:
    """The sticks as index spans [start, end): runs of samples with |bit_rpm| below
    ``TURNING_RPM`` (``end`` = len at the end of the record)."""
    stuck = np.concatenate(([False], np.abs(bit_rpm) < TURNING_RPM, [False]))
    edges = np.flatnonzero(np.diff(stuck.astype(np.int8)))
    return [(int(a), int(b)) for a, b in zip(edges[::2], edges[1::2], strict=True)]


def slip_onsets(t_s: np.ndarray, bit_rpm: np.ndarray) -> list[float]:
    """The times of the slips that follow a stick of at least ``MIN_STICK_S`` (module doc):
    after each such stick, the first sample above ``SLIP_RPM`` before the next one."""
    spans = [(start, end) for start, end in stuck_spans(bit_rpm)
             if end < len(t_s) and t_s[end] - t_s[start] >= MIN_STICK_S - TIME_TOLERANCE_S]
    onsets = []                           # (a stick still going at the end has no slip)
    for i, (_, end) in enumerate(spans):
        stop = spans[i + 1][0] if i + 1 < len(spans) else len(t_s)
        slipping = np.flatnonzero(bit_rpm[end:stop] > SLIP_RPM)
        if slipping.size:
            onsets.append(float(t_s[end + slipping[0]]))
    return onsets
