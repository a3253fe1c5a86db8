"""The Gymnasium environment: Gymnasium's own checker, and a policy rollout that equals the
bench's run of the same law bit for bit (the environment steps the same Bench)."""

from __future__ import annotations

import math

import gymnasium
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import drill_sim_ros.gym as drill_gym
from drill_sim_ros.control.bench import build_controller, run_in_process
from drill_sim_ros.control.command import Command
from drill_sim_ros.control.rig import rig_physics
from drill_sim_ros.control.scorecard import SCORE_FIELDS, score
from drill_sim_ros.model.params import RPM_PER_RAD_S
from drill_sim_ros.model.telemetry import TELEMETRY_INDEX as F

SHORT = drill_gym.resolve_scenario("noisy_delayed_sensors").with_(duration_s=20.0,
                                                                    enable_at_s=5.0)


def test_passes_gymnasiums_checker() -> None:
    env = gymnasium.make(drill_gym.ENV_ID, scenario=SHORT).unwrapped
    check_env(env, skip_render_check=True)


def action_of(command: Command, mode: str) -> np.ndarray:
    value = command.speed_rad_s if mode == "speed" else command.motor_torque_nm
    return np.array([math.nan if value is None else value])


@pytest.mark.parametrize(("controller", "mode"), [("soft_torque", "speed"),
                                                  ("z_torque", "torque")])
def test_a_policy_rollout_is_the_bench_run_bit_for_bit(controller: str, mode: str) -> None:
    scenario = SHORT.with_(controller=controller, mode=mode)
    env = gymnasium.make(drill_gym.ENV_ID, scenario=scenario)
    obs, info = env.reset(seed=scenario.sensors["seed"])
    law = build_controller(scenario, env.unwrapped.bench.preset)
    command, steps, done = law.update(info["measurement"]), 0, False   # answers t = 0
    while not done:
        obs, reward, terminated, truncated, info = env.step(action_of(command, mode))
        assert env.observation_space.contains(obs) and math.isfinite(reward)
        done, steps = terminated or truncated, steps + 1
        command = law.update(info["measurement"])
    assert steps == scenario.periods and not terminated
    rows = run_in_process(scenario).rows
    assert np.array_equal(env.unwrapped.bench.rows, rows)
    # the last step's info carries the episode's scorecard, the bench run's
    preset = scenario.load_preset()
    assert list(info["score"]) == list(SCORE_FIELDS)
    assert info["score"] == score(rows, scenario.enable_at_s, scenario.setpoints(preset),
                                  rig_physics(preset), scenario.period_s)
    # the observation is the last sample's surface measurement, not the truth
    assert obs[0] == rows[-1, F["drive_speed_measured_rad_s"]] != \
        rows[-1, F["surface_rpm"]] / RPM_PER_RAD_S


def test_reset_with_a_seed_repeats_the_episode() -> None:
    env = gymnasium.make(drill_gym.ENV_ID, scenario=SHORT)
    def episode(seed: int) -> np.ndarray:
        first, _ = env.reset(seed=seed)
        return np.vstack([first, *(env.step(np.array([6.0]))[0] for _ in range(300))])
    three = episode(3)
    assert np.array_equal(three, episode(3))
    assert not np.array_equal(three, episode(4))     # the sensors' noise follows the seed


def test_reward_by_its_definition_on_a_stuck_bit() -> None:
    """A bit at rest: the speed term is -1; no torque change, no ROP: the reward is -1."""
    env = drill_gym.DrillStickSlipEnv(scenario=SHORT, torque_rate_weight=1.0, rop_weight=0.1)
    env.reset(seed=0)
    row = env.bench.row.copy()
    row[F["bit_rpm"]], row[F["rop_m_s"]] = 0.0, 0.0
    env._last_torque = float(row[F["motor_torque_nm"]])
    assert env._reward(row) == pytest.approx(-1.0, rel=1e-12)
