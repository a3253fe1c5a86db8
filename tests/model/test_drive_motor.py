"""The drive's motor: its torque lag, then its torque rate limit (model/top_drive.py).

Expected values: the continuous step response of m' = min(r, (c - m) / lag) worked by hand
(a ramp at the rate r until the lag's own rate (c - m) / lag falls to r, then the lag's
exponential), and the limit itself: no step moves the motor torque by more than r dt.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from drill_sim_ros.model import kernel as k
from drill_sim_ros.model.errors import ParameterError
from drill_sim_ros.model.presets import load_preset
from drill_sim_ros.model.simulator import SimConfig, Simulator
from drill_sim_ros.model.top_drive import TopDrive, TopDrivePhysical

PRESET = load_preset("field_8p5in_shale_lumped")
DTAU = 1e-4


def simulator(**drive: float) -> Simulator:
    p = PRESET
    return Simulator(p.params, SimConfig(dtau=DTAU), perturb_v=1e-3,
                     top_drive=p.top_drive.with_(**drive), scales=p.scales)


def hand_step_response(t: np.ndarray, m0: float, step: float, lag: float,
                       rate: float) -> np.ndarray:
    """m(t) of m' = min(rate, (m0 + step - m) / lag), m(0) = m0, step > rate lag: the rate
    limit binds until t1 = (step - rate lag) / rate, the lag after it."""
    t1 = (step - rate * lag) / rate
    ramp = m0 + rate * t
    lagged = m0 + step - rate * lag * np.exp(-(t - t1) / lag)
    return np.where(t < t1, ramp, lagged)


def test_the_motor_torque_lags_then_ramps_no_faster_than_its_limit() -> None:
    lag, step = 0.01, 5.0                 # 100 steps of lag; a step of 5 C
    rate = step / lag / 5.0               # the lag alone would start 5 times faster
    sim = simulator(mode="torque", motor_lag=lag, max_torque_rate=rate)
    m0 = float(sim.state[k.S_MOTOR_TORQUE])
    sim.set_inputs(motor_torque=m0 + step)
    rows = sim.advance(sim.steps_for(8 * lag), every=1).data
    motor = rows[:, k.C_MOTOR_TORQUE]
    t = rows[:, k.C_TAU] - rows[0, k.C_TAU] + DTAU                  # after each step
    moves = np.diff(np.concatenate(([m0], motor)))
    assert np.all(np.abs(moves) <= rate * DTAU * (1 + 1e-12))     # never faster than r
    t1 = (step - rate * lag) / rate
    ramping = t < t1 - DTAU
    assert ramping.sum() > 300
    assert moves[ramping] == pytest.approx(rate * DTAU, rel=1e-9)   # at the limit, exactly
    expected = hand_step_response(t, m0, step, lag, rate)
    assert motor == pytest.approx(expected, abs=2 * rate * DTAU)    # O(dt) at the corner
    assert motor[-1] == pytest.approx(m0 + step - rate * lag * math.exp(-4.0), rel=1e-4)


def test_the_speed_loop_s_torque_keeps_within_the_rate_limit() -> None:
    rate = 50.0                                        # C per t*: binds on a speed step
    sim = simulator(mode="speed", motor_lag=0.0, max_torque_rate=rate)
    sim.advance(sim.steps_for(1.0))
    m0 = float(sim.state[k.S_MOTOR_TORQUE])
    sim.set_inputs(omega_s=2.0 * sim.targets[0])       # a speed step: kp e jumps
    motor = sim.advance(sim.steps_for(1.0), every=1).column(k.C_MOTOR_TORQUE)
    moves = np.diff(np.concatenate(([m0], motor)))
    assert np.max(np.abs(moves)) == pytest.approx(rate * DTAU, rel=1e-9)   # it binds
    assert np.all(np.abs(moves) <= rate * DTAU * (1 + 1e-12))


def test_no_lag_and_no_rate_limit_apply_the_command_exactly() -> None:
    sim = simulator(mode="torque", motor_lag=0.0, max_torque_rate=math.inf)
    m0 = float(sim.state[k.S_MOTOR_TORQUE])
    sim.set_inputs(motor_torque=m0 + 7.0)
    motor = sim.advance(10, every=1).column(k.C_MOTOR_TORQUE)
    assert np.all(motor == m0 + 7.0)


def test_the_rate_scales_as_torque_over_time() -> None:
    sc = PRESET.scales
    drive = TopDrivePhysical(max_torque_rate_nm_s=1.0e7)
    scaled = drive.scaled(sc)
    assert scaled.max_torque_rate == pytest.approx(1.0e7 * sc.time_s / sc.torque_nm,
                                                   rel=1e-15)
    assert scaled.physical(sc).max_torque_rate_nm_s == pytest.approx(1.0e7, rel=1e-14)
    assert math.isinf(TopDrivePhysical().scaled(sc).max_torque_rate)      # default: none


@pytest.mark.parametrize("value", [0.0, -1.0, math.nan])
def test_a_bad_rate_limit_is_one_line_naming_it(value: float) -> None:
    with pytest.raises(ParameterError, match=r"'top_drive\.max_torque_rate_nm_s' = .* > 0"):
        TopDrivePhysical(max_torque_rate_nm_s=value)
    with pytest.raises(ParameterError, match=r"'top_drive\.max_torque_rate' = .* > 0"):
        TopDrive(max_torque_rate=value)


def test_the_field_presets_carry_a_motor() -> None:
    for name in ("field_8p5in_shale", "field_8p5in_deviated", "field_8p5in_shale_lumped"):
        drive = load_preset(name).drive
        assert drive.motor_lag_s > 0.0 and math.isfinite(drive.max_torque_rate_nm_s), name
    for name in ("fig5_8a", "fig9"):                # the paper's kinematic drive: none
        drive = load_preset(name).drive
        assert drive.motor_lag_s == 0.0 and math.isinf(drive.max_torque_rate_nm_s), name
