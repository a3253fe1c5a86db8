"""The scorecard from hand-made telemetry: each figure against its definition, and its SSI
against model.analysis on the same samples (one SSI implementation)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from drill_sim_ros.control.bench import run_in_process
from drill_sim_ros.control.rig import rig_physics
from drill_sim_ros.control.scenario import Scenario
from drill_sim_ros.control.schedule import Schedule
from drill_sim_ros.control.scorecard import score, window_ssi
from drill_sim_ros.model import analysis
from drill_sim_ros.model.params import RPM_PER_RAD_S
from drill_sim_ros.model.presets import load_preset
from drill_sim_ros.model.telemetry import N_FIELDS, TELEMETRY_INDEX

F = TELEMETRY_INDEX
PRESET = load_preset("field_8p5in_shale_lumped")
RIG = rig_physics(PRESET)
PERIOD_S = 0.01


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
    assert card["stick_fraction"] == pytest.approx(500 / after.shape[0], rel=1e-12)
    assert card["time_to_suppress_s"] == pytest.approx(45.0 - 20.0)
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
    assert card["saturation_count"] == 0


def test_stick_in_the_last_window_means_not_suppressed() -> None:
    rows = synthetic(60.0)
    assert score(rows, 20.0, Schedule(60.0, 60e3), RIG, PERIOD_S)["time_to_suppress_s"] is None


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
    t, bit = rows[:, F["sim_time_s"]], rows[:, F["bit_rpm"]]
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
    assert card["stall_time_s"] == pytest.approx(80.01)
    short = synthetic(100.0)
    short[t > 95.0, F["mode"]] = 2  # a 5 s stick at the end: a stick phase
    card = score(short, 20.0, Schedule(60.0, 60e3), RIG, PERIOD_S)
    assert card["status"] == "stick-slip" and card["stall_time_s"] is None
    assert (
        score(synthetic(100.0), 20.0, Schedule(60.0, 60e3), RIG, PERIOD_S)["status"] == "ok"
    )  # last stick at 45 s
