"""The Gymnasium environment: Gymnasium's own checker without a warning, a policy rollout that
equals the bench's run of the same law bit for bit (the environment steps the same Bench),
observations scaled by the rig's own scales, and the reward by its definition."""

from __future__ import annotations

import math
import warnings

import gymnasium
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import drill_sim_ros.gym as drill_gym
from drill_sim_ros.control.bench import Bench, build_controller
from drill_sim_ros.control.command import Command
from drill_sim_ros.control.rig import rig_physics
from drill_sim_ros.control.scorecard import SCORE_FIELDS, score
from drill_sim_ros.model.errors import ParameterError
from drill_sim_ros.model.params import RPM_PER_RAD_S
from drill_sim_ros.model.telemetry import TELEMETRY_INDEX as F

SHORT = drill_gym.resolve_scenario("noisy_delayed_sensors").with_(duration_s=20.0,
                                                                    enable_at_s=5.0)


@pytest.mark.parametrize("mode", ["speed", "torque"])
def test_passes_gymnasiums_checker_without_a_warning(mode: str) -> None:
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        env = gymnasium.make(drill_gym.ENV_ID, scenario=SHORT, mode=mode)
        check_env(env.unwrapped, skip_render_check=True)
        env.reset(seed=1)                                  # and the passive checker's
        env.step(env.action_space.sample())


def action_of(command: Command, mode: str, scale: float) -> np.ndarray:
    value = command.speed_rad_s if mode == "speed" else command.motor_torque_nm
    return np.array([math.nan if value is None else value / scale])


def as_applied(command: Command, scale: float) -> Command:
    """The command the environment sends for the action ``command / scale``."""
    def rounded(value: float | None) -> float | None:
        return None if value is None else value / scale * scale
    return Command(rounded(command.speed_rad_s), rounded(command.motor_torque_nm),
                   command.wob_n)


@pytest.mark.parametrize(("controller", "mode"), [("soft_torque", "speed"),
                                                  ("z_torque", "torque")])
def test_a_policy_rollout_is_the_bench_run_bit_for_bit(controller: str, mode: str) -> None:
    """A policy acting the controller's command over the action scale; the bench stepped
    with the controller's commands as the environment applies them (a x scale)."""
    scenario = SHORT.with_(controller=controller, mode=mode)
    env = gymnasium.make(drill_gym.ENV_ID, scenario=scenario)
    obs, info = env.reset(seed=scenario.sensors["seed"])
    scale = env.unwrapped.scales.action
    law = build_controller(scenario, env.unwrapped.bench.preset)
    command, steps, done = law.update(info["measurement"]), 0, False   # answers t = 0
    while not done:
        obs, reward, terminated, truncated, info = env.step(action_of(command, mode, scale))
        assert env.observation_space.contains(obs) and math.isfinite(reward)
        done, steps = terminated or truncated, steps + 1
        command = law.update(info["measurement"])
    assert steps == scenario.periods and truncated and not terminated
    bench, law = Bench(scenario), build_controller(scenario, env.unwrapped.bench.preset)
    command = law.update(bench.measurement())
    while not bench.done:
        bench.step(as_applied(command, scale))
        command = law.update(bench.measurement())
    assert np.array_equal(env.unwrapped.bench.rows, bench.rows)
    # the last step's info carries the episode's scorecard, the bench run's
    preset = scenario.load_preset()
    assert list(info["score"]) == list(SCORE_FIELDS)
    assert info["score"] == score(bench.rows, scenario.enable_at_s,
                                  scenario.setpoints(preset), rig_physics(preset),
                                  scenario.period_s)


def test_observations_are_the_measurement_over_the_rigs_scales() -> None:
    """At t = 0 of the field case at 60 rpm and 60 kN: the drive turns at the setpoint
    (1), the setpoints read 1, and the hook load over the string's submerged weight (the
    preset's, `presets.submerged_string_weight_n`) is 1 - WOB / weight, give or take the
    string's axial vibration in the force it leans on the hook with (0.1 kN measured)."""
    from drill_sim_ros.model.presets import load_preset, submerged_string_weight_n
    env = drill_gym.DrillStickSlipEnv(scenario="field_60rpm")
    obs, info = env.reset(seed=0)
    m = info["measurement"]
    omega_0 = 60.0 / RPM_PER_RAD_S
    weight_n = submerged_string_weight_n(load_preset("field_8p5in_shale"))
    assert obs[0] == pytest.approx(m.drive_speed_rad_s / omega_0, rel=1e-12)
    assert obs[5] == pytest.approx(1.0, rel=1e-12) and obs[6] == pytest.approx(1.0, rel=1e-12)
    assert obs[3] == pytest.approx(m.hook_load_n / weight_n, rel=1e-12)
    assert obs[3] == pytest.approx(1.0 - 60e3 / weight_n, abs=1e-3)
    assert obs[4] == pytest.approx(m.applied_wob_estimate_n / 60e3, rel=1e-12)
    assert obs[1] == pytest.approx(m.motor_torque_nm / env.scales.torque_nm, rel=1e-12)


def test_observations_stay_of_order_one_through_stick_slip() -> None:
    """The drive at the setpoint through the first 20 s of the default case (a stick, then a
    slip to 106 rpm at the bit): every value of the observation stays within 10 of its
    scale, and each reaches at least a tenth of it."""
    env = drill_gym.DrillStickSlipEnv(scenario=SHORT)
    env.reset(seed=0)
    action = np.array([SHORT.setpoints(env.bench.preset).rpm_at(0.0)
                       / RPM_PER_RAD_S / env.scales.action])
    obs = np.array([env.step(action)[0] for _ in range(SHORT.periods)])
    assert np.abs(obs).max() < 10.0
    assert np.abs(obs).max(axis=0).min() > 0.1


def test_reset_with_a_seed_repeats_the_episode() -> None:
    env = gymnasium.make(drill_gym.ENV_ID, scenario=SHORT)
    def episode(seed: int) -> np.ndarray:
        first, _ = env.reset(seed=seed)
        return np.vstack([first, *(env.step(np.array([0.2]))[0] for _ in range(300))])
    three = episode(3)
    assert np.array_equal(three, episode(3))
    assert not np.array_equal(three, episode(4))     # the sensors' noise follows the seed


def test_reward_by_its_definition_on_a_stuck_bit() -> None:
    """A bit at rest: the speed term is -speed_weight; no torque change, no ROP."""
    env = drill_gym.DrillStickSlipEnv(scenario=SHORT, speed_weight=2.5, torque_rate_weight=1.0,
                                      rop_weight=0.1)
    env.reset(seed=0)
    row = env.bench.row.copy()
    row[F["bit_rpm"]], row[F["rop_m_s"]] = 0.0, 0.0
    env._last_torque = float(row[F["motor_torque_nm"]])
    assert env._reward(row) == pytest.approx(-2.5, rel=1e-12)
    # a torque step of the drive's whole limit costs torque_rate_weight
    env._last_torque = float(row[F["motor_torque_nm"]]) - env.bench.rig.max_torque_nm
    assert env._reward(row) == pytest.approx(-3.5, rel=1e-12)


@pytest.mark.parametrize("weight", [-1.0, math.inf, math.nan])
def test_a_bad_reward_weight_is_refused(weight: float) -> None:
    with pytest.raises(ParameterError, match="rop_weight"):
        drill_gym.DrillStickSlipEnv(scenario=SHORT, rop_weight=weight)
