"""The scorecard from hand-made telemetry: each figure against its definition, and its SSI
against model.analysis on the same samples (one SSI implementation); stick-slip told from
the collars' ringing by the rig's cut-off."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from drill_sim_ros.control.bench import run_in_process
from drill_sim_ros.control.rig import rig_physics
from drill_sim_ros.control.scenario import Scenario
from drill_sim_ros.control.schedule import Schedule
from drill_sim_ros.control.scorecard import (
    SSI_MAX,
    SSI_OK,
    STICK_FRACTION_OK,
    lowpassed_bit_rpm,
    score,
    status_of,
    window_ssi,
)
from drill_sim_ros.model import analysis
from drill_sim_ros.model.params import RPM_PER_RAD_S
from drill_sim_ros.model.presets import load_preset
from drill_sim_ros.model.string import analytic_modes_hz
from drill_sim_ros.model.telemetry import N_FIELDS, TELEMETRY_INDEX

F = TELEMETRY_INDEX
PRESET = load_preset("field_8p5in_shale_lumped")
RIG = rig_physics(PRESET)
PERIOD_S = 0.01
EDGE_S = 2.0 / RIG.cutoff_hz    # the low-pass blurs and rings a step of the bit speed
                                # (e.g. 60 rpm to 0) over about this


def synthetic(duration_s: float = 100.0) -> np.ndarray:
    """Rows at 100 Hz: bit rpm 60 + 30 sin(2 pi t / 5), stuck (rpm 0, mode 2) for
    t in (40, 45], constant WOB, TOB, ROP, quill and motor torque."""
    t = np.arange(0, round(duration_s / PERIOD_S) + 1) * PERIOD_S
    rows = np.zeros((t.size, N_FIELDS))
    rows[:, F["sim_time_s"]] = t
    rows[:, F["bit_rpm"]] = 60.0 + 30.0 * np.sin(2 * np.pi * t / 5.0)
    stuck = (t > 40.0) & (t <= 45.0)
    rows[stuck, F["bit_rpm"]] = 0.0
    rows[stuck, F["mode"]] = 2
    rows[:, F["wob_n"]] = 60e3
    rows[:, F["tob_nm"]] = 3000.0
    rows[:, F["rop_m_s"]] = 10.0 / 3600
    rows[:, F["surface_torque_nm"]] = 3000.0 + 1000.0 * np.cos(t)
    rows[:, F["motor_torque_nm"]] = 4000.0
    rows[:, F["surface_rpm"]] = 60.0
    rows[:, F["speed_setpoint_rpm"]] = 60.0
    return rows


def test_figures_by_their_definitions() -> None:
    rows = synthetic()
    card = score(rows, 20.0, Schedule(60.0, 60e3), RIG, PERIOD_S)
    after = rows[rows[:, 0] > 20.0]
    # stuck for (40, 45]: 500 samples, give or take the low-pass's blur at the two edges
    assert card["stick_fraction"] * after.shape[0] == pytest.approx(500, abs=2 * EDGE_S / PERIOD_S)
    assert card["time_to_suppress_s"] == pytest.approx(45.0 - 20.0, abs=EDGE_S)
    assert card["utr"] == pytest.approx(1.0)  # (60 - 0) / 60
    assert card["rop_m_h"] == pytest.approx(10.0)
    bit_rad_s = after[:, F["bit_rpm"]] / RPM_PER_RAD_S
    mse = (60e3 + np.mean(3000.0 * bit_rad_s) / (10.0 / 3600)) / (math.pi * 0.108**2)
    assert card["mse_mpa"] == pytest.approx(mse * 1e-6, rel=1e-9)
    quill = after[:, F["surface_torque_nm"]]
    assert card["quill_torque_peak_nm"] == pytest.approx(quill.max())
    assert card["quill_torque_rms_nm"] == pytest.approx(np.sqrt(np.mean(quill**2)))
    motor_j = 4000.0 * 60.0 / RPM_PER_RAD_S * after.shape[0] * PERIOD_S
    assert card["motor_energy_mj"] == pytest.approx(motor_j * 1e-6, rel=1e-12)
    assert card["saturation_count"] == 0 and card["saturation_fraction"] == 0.0
    assert card["period_s"] == pytest.approx(5.0, rel=1.0 / 80)   # the sine's, 80 s scored
    assert card["cutoff_hz"] == RIG.cutoff_hz


def test_saturation_fraction_counts_the_torque_limit_alone() -> None:
    rows = synthetic()
    t = rows[:, F["sim_time_s"]]
    rows[(t > 50.0) & (t <= 52.0), F["motor_torque_nm"]] = -RIG.max_torque_nm   # 200 samples
    rows[(t > 60.0) & (t <= 61.0), F["speed_setpoint_rpm"]] = 0.0               # 100 samples
    # clamped to the rpm limit, as the telemetry reads it back through a preset's t* (the
    # default preset's: one ulp below the limit)
    at_limit = np.nextafter(RIG.max_surface_rpm, 0.0)
    rows[(t > 70.0) & (t <= 70.5), F["speed_setpoint_rpm"]] = at_limit         # 50 samples
    card = score(rows, 20.0, Schedule(60.0, 60e3), RIG, PERIOD_S)
    after = np.count_nonzero(t > 20.0)
    assert card["saturation_count"] == 350
    assert card["saturation_fraction"] == pytest.approx(200 / after, rel=1e-12)


def test_the_cutoff_is_twice_the_third_mode_of_the_same_geometry() -> None:
    """The lumped twin takes its sections from pipe_* / bha_*: the modes of the distributed
    preset's sections with a free bit (the twin has no lumped bit inertia to carry). Two
    sections of one material, fixed top and free bit: a mode satisfies
    tan(k L1) tan(k L2) = J1 / J2 (continuity of twist and torque). The distributed preset's
    own modes have its bit inertia, and its cut-off is twice its own third mode."""
    distributed = load_preset("field_8p5in_shale")
    free_bit = dataclasses.replace(distributed.string, bit_inertia_kg_m2=0.0)
    assert RIG.torsional_modes_hz == pytest.approx(analytic_modes_hz(free_bit, 3), rel=1e-9)
    assert RIG.cutoff_hz == pytest.approx(2.0 * RIG.torsional_modes_hz[2], rel=1e-12)
    pipe, bha = distributed.string.sections
    for f_hz in RIG.torsional_modes_hz:
        k = 2 * np.pi * f_hz / pipe.torsional_speed_m_s
        ratio = np.tan(k * pipe.length_m) * np.tan(k * bha.length_m)
        assert ratio == pytest.approx(pipe.polar_moment_m4 / bha.polar_moment_m4, rel=1e-6)
    rig = rig_physics(distributed)     # an inertia added at the free end lowers every mode
    assert np.all(np.array(rig.torsional_modes_hz) < np.array(RIG.torsional_modes_hz))
    assert rig.cutoff_hz == pytest.approx(2.0 * rig.torsional_modes_hz[2], rel=1e-12)


def stick_slip_with_a_ring(ring_rpm: float, duration_s: float = 100.0) -> np.ndarray:
    """``synthetic`` rows whose bit speed is a 0.2 Hz sawtooth stick-slip (per 5 s: stuck
    1.5 s, up to 171 rpm in 0.5 s, down to 0 in 3 s; mean 60 rpm) plus a 16 Hz sine of
    ``ring_rpm``; the raw speed crosses zero in every stick phase."""
    rows = synthetic(duration_s)
    t = rows[:, F["sim_time_s"]]
    phase_s = t % 5.0
    saw = np.interp(phase_s, [0.0, 1.5, 2.0, 5.0], [0.0, 0.0, 171.0, 0.0])
    rows[:, F["bit_rpm"]] = saw + ring_rpm * np.sin(2 * np.pi * 16.0 * t)
    rows[:, F["mode"]] = np.where(phase_s < 1.5, 2, 0)
    return rows


def test_stick_slip_under_a_ring_is_stick_slip_with_both_read_apart() -> None:
    ring_rpm, scored_s = 40.0, 80.0
    card = score(stick_slip_with_a_ring(ring_rpm), 20.0, Schedule(60.0, 60e3), RIG, PERIOD_S)
    assert card["status"] == "stick-slip" and card["time_to_suppress_s"] is None
    assert card["stick_fraction"] == pytest.approx(0.3, abs=2 * EDGE_S / 5.0)
    bin_hz = 1.0 / scored_s
    assert abs(1.0 / card["period_s"] - 0.2) <= bin_hz
    assert card["ring_hz"] == pytest.approx(16.0, abs=bin_hz)
    # the sawtooth's kinks put under 2 rpm RMS above the cut-off (a piecewise-linear wave's
    # harmonic k has an amplitude under 2 sum|slope jumps| / (T (2 pi k / T)^2) = 202/k^2
    # rpm), under 0.3 % of the sine's RMS added in quadrature
    assert card["ring_rms_rpm"] == pytest.approx(ring_rpm / math.sqrt(2), rel=0.01)


def test_a_ring_alone_that_touches_zero_is_no_stick() -> None:
    """60 rpm with a 16 Hz ring of 65 rpm, clipped at 0 where the sim would call the bit
    stuck: the old rule (one stuck sample) would call it stick-slip."""
    rows = synthetic()
    t = rows[:, F["sim_time_s"]]
    bit = np.maximum(60.0 + 65.0 * np.sin(2 * np.pi * 16.0 * t), 0.0)
    rows[:, F["bit_rpm"]] = bit
    rows[:, F["mode"]] = np.where(bit <= 0.0, 2, 0)
    assert (rows[t > 80.0, F["mode"]] == 2).any()
    card = score(rows, 20.0, Schedule(60.0, 60e3), RIG, PERIOD_S)
    assert card["status"] == "ok" and card["stick_fraction"] == 0.0
    assert card["time_to_suppress_s"] == 0.0 and card["period_s"] is None
    assert card["ring_hz"] == pytest.approx(16.0, abs=1.0 / 80)
    # the raw speed's SSI is 125 / (2 x 60.4) = 1.03; what is left (0.016) is the
    # low-pass's end effect on the last window, where the mirror padding kinks the ring
    assert card["ssi_mean"] < 0.05


def test_stick_in_the_last_window_means_not_suppressed() -> None:
    rows = synthetic(60.0)
    assert score(rows, 20.0, Schedule(60.0, 60e3), RIG, PERIOD_S)["time_to_suppress_s"] is None


def intermittent(stick_starts_s: list[float], duration_s: float,
                 stick_s: float | list[float] = 3.0) -> np.ndarray:
    """``synthetic`` rows turning at 60 rpm, stuck for ``stick_s`` (one for all or one per
    stick) from each of ``stick_starts_s``."""
    rows = synthetic(duration_s)
    t = rows[:, F["sim_time_s"]]
    rows[:, F["bit_rpm"]] = 60.0
    rows[:, F["mode"]] = 0
    lengths = np.broadcast_to(stick_s, (len(stick_starts_s),))
    for start, length in zip(stick_starts_s, lengths, strict=True):
        stuck = (t > start) & (t <= start + length)
        rows[stuck, F["bit_rpm"]] = 0.0
        rows[stuck, F["mode"]] = 2
    return rows


def test_a_quiet_end_shorter_than_the_runs_own_gaps_is_not_suppressed() -> None:
    """Sticks 27 s apart (24 s turning between them), the last one ending 22 s before the
    end: quiet for the 20 s window, but for less than the run's own spells between sticks,
    so not suppressed. Sticks of 2 s 8 s apart (6 s turning; stuck 6 s of 89, under the
    10 % that is never ok) and the same quiet end: suppressed at the last stick's end."""
    apart = score(intermittent([30.0, 57.0, 84.0], 109.0), 20.0, Schedule(60.0, 60e3), RIG,
                  PERIOD_S)
    assert apart["status"] == "stick-slip" and apart["time_to_suppress_s"] is None
    close = score(intermittent([68.0, 76.0, 84.0], 109.0, 2.0), 20.0, Schedule(60.0, 60e3),
                  RIG, PERIOD_S)
    assert close["status"] == "ok"
    assert close["time_to_suppress_s"] == pytest.approx(86.0 - 20.0, abs=EDGE_S)


def test_ssi_is_model_analysis_on_the_same_windows() -> None:
    rows = run_in_process(
        Scenario(
            preset="field_8p5in_shale_lumped",
            controller="soft_torque",
            duration_s=100.0,
            enable_at_s=20.0,
        )
    ).rows
    card = score(rows, 20.0, Schedule(60.0, 60e3), RIG, PERIOD_S)
    rows = rows[1:]                           # the scorecard's: the t = 0 sample is no period
    t, bit = rows[:, F["sim_time_s"]], lowpassed_bit_rpm(rows, RIG.cutoff_hz)
    by_hand, by_analysis = [], []
    for start in (20.0, 40.0, 60.0, 80.0):
        part = bit[(t > start) & (t <= start + 20.0 + 1e-9)]
        by_hand.append((part.max() - part.min()) / (2 * part.mean()))
        by_analysis.append(analysis.severity(part, 60.0).ssi)
    np.testing.assert_allclose(window_ssi(t, bit, 20.0, 100.0), by_hand, rtol=1e-12)
    assert card["ssi_mean"] == pytest.approx(np.mean(by_analysis), rel=1e-12)
    assert card["ssi_max"] == pytest.approx(np.max(by_analysis), rel=1e-12)
    assert card["ssi_last"] == pytest.approx(by_analysis[-1], rel=1e-12)


def test_status_stalled_with_its_time_never_null() -> None:
    rows = synthetic(100.0)
    t = rows[:, F["sim_time_s"]]
    end_stuck = t > 80.0  # stuck from 80.01 s to the end: 20 s
    rows[end_stuck, F["bit_rpm"]] = 0.0
    rows[end_stuck, F["mode"]] = 2
    card = score(rows, 20.0, Schedule(60.0, 60e3), RIG, PERIOD_S)
    assert card["status"] == "stalled"
    assert card["stall_time_s"] == pytest.approx(80.01, abs=EDGE_S)
    short = synthetic(100.0)
    short[t > 95.0, F["mode"]] = 2  # a 5 s stick at the end: a stick phase
    short[t > 95.0, F["bit_rpm"]] = 0.0
    card = score(short, 20.0, Schedule(60.0, 60e3), RIG, PERIOD_S)
    assert card["status"] == "stick-slip" and card["stall_time_s"] is None
    assert (
        score(synthetic(100.0), 20.0, Schedule(60.0, 60e3), RIG, PERIOD_S)["status"] == "ok"
    )  # last stick at 45 s


def test_a_switch_on_at_the_end_is_one_error_not_a_crash() -> None:
    """A scenario may switch on at its very end; then nothing is left to score, and the
    scorecard says so in one ParameterError (it used to fail inside numpy)."""
    from drill_sim_ros.model.errors import ParameterError
    scenario = Scenario(preset="field_8p5in_shale_lumped", duration_s=2.0, enable_at_s=2.0)
    preset = scenario.load_preset()
    rows = run_in_process(scenario).rows
    with pytest.raises(ParameterError, match="leaves nothing to score"):
        score(rows, scenario.enable_at_s, scenario.setpoints(preset), rig_physics(preset),
              scenario.period_s)


# ---- the status rule (scorecard module doc) on the cases of issue 48 ---------------------------
SWITCH_ON_S, END_S = 60.0, 180.0
SCHEDULE = Schedule(60.0, 60e3)


def judged(rows: np.ndarray) -> dict:
    return score(rows, SWITCH_ON_S, SCHEDULE, RIG, PERIOD_S)


def test_the_uncontrolled_default_stuck_23_percent_is_never_ok() -> None:
    """The default case without control: sticks of 9.7, 8.6, 8.1 and 1.6 s after the
    switch-on (28 s of 120: 23 %), then 37 s quiet, longer than any spell it turned
    between them (25 s). Suppressed by the quiet end, but stuck 10 % or more: stick-slip
    (the old rule read ok)."""
    card = judged(intermittent([60.0, 81.4, 107.7, 141.0], END_S, [9.7, 8.6, 8.1, 1.6]))
    assert card["stick_fraction"] == pytest.approx(28.0 / 120.0, abs=8 * EDGE_S / 120.0)
    assert card["stick_longest_s"] == pytest.approx(9.7, abs=2 * EDGE_S)   # two edges
    assert card["time_to_suppress_s"] == pytest.approx(142.6 - 60.0, abs=EDGE_S)
    assert card["status"] == "stick-slip" and card["stall_time_s"] is None


def test_a_bit_held_stuck_then_let_go_is_not_ok_and_has_a_numeric_ssi() -> None:
    """A controller that holds the bit stuck from 60 to 150 s, then turns it at 60 rpm:
    stuck 3/4 of the time after the switch-on, so not ok; not stalled, it turned again.
    Its windows inside the stick read SSI_MAX, the SSI's ceiling, not None."""
    card = judged(intermittent([60.0], END_S, 90.0))
    assert card["stick_fraction"] == pytest.approx(0.75, abs=2 * EDGE_S / 120.0)
    assert card["status"] == "stick-slip" and card["stall_time_s"] is None
    assert card["time_to_suppress_s"] == pytest.approx(90.0, abs=EDGE_S)
    assert card["ssi_max"] == SSI_MAX
    # windows 60-80 .. 120-140 stuck (SSI_MAX), 140-160 turning from 150 s: (60 - 0) /
    # (2 x 30), the last window turning steadily: 0
    assert card["ssi_mean"] == pytest.approx((4 * SSI_MAX + 1.0) / 6, abs=0.05)
    assert card["ssi_last"] == pytest.approx(0.0, abs=0.01)


def test_a_stick_slip_ending_inside_a_stick_is_stick_slip_not_stalled() -> None:
    """Sticks of 12 s every 25 s (as long_string's, which read "stalled" when the run
    ended 13 s into one): the run ends 11 s into a stick, more than STALL_S but less than
    twice the sticks the bit broke out of. Judged by the record: stick-slip."""
    starts = [69.0 + 25.0 * k for k in range(5)]        # the last from 169 s to the end
    card = judged(intermittent(starts, END_S, 12.0))
    assert card["stick_longest_s"] == pytest.approx(12.0, abs=2 * EDGE_S)   # two edges
    assert card["status"] == "stick-slip" and card["stall_time_s"] is None


def test_a_bit_that_stuck_and_stayed_stuck_is_stalled() -> None:
    """Sticks of 3 s every 10 s, then stuck from 140 s to the end: 40 s, more than
    STALL_FACTOR times the longest stick it broke out of. Stalled at 140 s; its last
    windows read SSI_MAX."""
    rows = intermittent([*(65.0 + 10.0 * k for k in range(7)), 140.0], END_S,
                        [3.0] * 7 + [40.0])
    card = judged(rows)
    assert card["status"] == "stalled"
    assert card["stall_time_s"] == pytest.approx(140.0, abs=EDGE_S)
    assert card["ssi_last"] == SSI_MAX


def test_a_clean_suppression_is_ok() -> None:
    """Stick-slip before the switch-on (1 s sticks every 5 s, as lumped_first_mode), one
    1.4 s stick after it, then turning: stuck 1.2 % of the time, none in the last 20 s,
    SSI of the last window 0. ok."""
    card = judged(intermittent([*(21.0 + 5.0 * k for k in range(8)), 60.0], END_S,
                               [1.0] * 8 + [1.4]))
    assert card["stick_fraction"] == pytest.approx(1.4 / 120.0, abs=2 * EDGE_S / 120.0)
    assert card["time_to_suppress_s"] == pytest.approx(1.4, abs=EDGE_S)
    assert card["status"] == "ok" and card["ssi_last"] == pytest.approx(0.0, abs=0.01)


def test_a_run_stuck_throughout_has_the_largest_ssi() -> None:
    """Stuck from before the switch-on to the end: every window reads SSI_MAX, the
    largest any window can read (a turning window is clipped to it)."""
    card = judged(intermittent([10.0], END_S, 200.0))
    assert card["ssi_mean"] == card["ssi_max"] == card["ssi_last"] == SSI_MAX
    assert card["status"] == "stalled" and card["stall_time_s"] == pytest.approx(10.0, abs=EDGE_S)
    spike = window_ssi(np.arange(1, 2001) * PERIOD_S, np.r_[np.full(1990, 2.0),
                                                            np.full(10, 400.0)], 0.0, 20.0)
    assert spike[0] == SSI_MAX      # (400 - 2) / (2 x 3.99) = 50: clipped


def test_the_motor_effort_by_its_definitions() -> None:
    """A motor torque of 20 kN m sin(2 pi t / 2 s) at a steady 60 rpm: RMS about the mean
    A / sqrt(2); mean |d tau / dt| = 4 A f (the mean of |cos| is 2 / pi); net work 0 over
    whole periods, positive work A omega / pi per second. The bit's max speed is 90 rpm."""
    rows = synthetic(100.0)
    t = rows[:, F["sim_time_s"]]
    amplitude_nm, f_hz = 20e3, 0.5
    rows[:, F["motor_torque_nm"]] = amplitude_nm * np.sin(2 * np.pi * f_hz * t)
    card = score(rows, 20.0, SCHEDULE, RIG, PERIOD_S)
    omega = 60.0 / RPM_PER_RAD_S
    assert card["motor_torque_std_nm"] == pytest.approx(amplitude_nm / math.sqrt(2), rel=1e-3)
    assert card["motor_torque_rate_mean_knm_s"] == pytest.approx(4 * amplitude_nm * f_hz * 1e-3,
                                                                 rel=1e-3)
    assert card["motor_energy_mj"] == pytest.approx(0.0, abs=1e-3 * amplitude_nm * omega * 1e-6)
    assert card["motor_energy_in_mj"] == pytest.approx(amplitude_nm * omega / math.pi * 80.0
                                                       * 1e-6, rel=1e-3)
    assert card["bit_rpm_max"] == pytest.approx(90.0, rel=1e-6)


def test_the_rule_at_its_edges() -> None:
    """status_of on the figures alone: 10 % stuck is stick-slip even when suppressed and
    settled; an SSI of 1 in the last window is stick-slip without a stick; a stall wins."""
    settled = {"stick_fraction": 0.0999, "time_to_suppress_s": 50.0, "ssi_last": 0.99}
    assert status_of(settled, None) == "ok"
    assert status_of({**settled, "stick_fraction": STICK_FRACTION_OK}, None) == "stick-slip"
    assert status_of({**settled, "ssi_last": SSI_OK}, None) == "stick-slip"
    assert status_of({**settled, "time_to_suppress_s": None}, None) == "stick-slip"
    assert status_of(settled, 150.0) == "stalled"


def test_the_axial_state_by_its_definitions() -> None:
    """A bit above the rock (mode off_bottom, WOB 0) for 2 s in every 10 s after the
    switch-on at 20 s, else 60 kN: off the rock 0.2 of the time; the WOB's RMS about its
    mean 60 kN sqrt(0.2 x 0.8) (a two-level signal)."""
    rows = synthetic(100.0)
    t = rows[:, F["sim_time_s"]]
    bounce = (t % 10.0) >= 8.0
    rows[bounce, F["mode"]] = 3
    rows[bounce, F["wob_n"]] = 0.0
    card = score(rows, 20.0, SCHEDULE, RIG, PERIOD_S)
    share = float(np.mean(bounce[t > 20.0]))
    assert share == pytest.approx(0.2, abs=1e-3)
    assert card["off_bottom_fraction"] == pytest.approx(share, rel=1e-12)
    assert card["wob_rms_n"] == pytest.approx(60e3 * math.sqrt(share * (1 - share)), rel=1e-9)
