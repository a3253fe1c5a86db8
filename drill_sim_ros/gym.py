"""A Gymnasium environment of the rig: ``DrillStickSlip-v0`` (registered on import).

One step is one control period of the closed-loop bench
(:class:`~drill_sim_ros.control.bench.Bench`, the same stepper as ``drill_sim closed-loop``),
so a policy that computes what a controller commands, over the action's scale, gets the
bench's run of that controller given the same commands rounded through a x scale (bit for
bit; the rounding is in the last bit of each command).

* Observation (float64, shape (7,), :data:`OBSERVATION`): what the rig measures at the
  surface and the driller's setpoints, never downhole truth, each divided by a scale of the
  rig fixed for the episode (:class:`EpisodeScales`), so that it is O(1): the drive's measured
  speed and the operator's speed setpoint by omega_0 (the setpoint at t = 0), the motor
  torque and the string torque at the quill by the steady-drilling bit torque of the
  preset, the hook load by the string's submerged weight, and the applied-WOB estimate and
  the WOB setpoint by the WOB setpoint at t = 0; each is clipped to +-``OBSERVATION_LIMIT``
  (1000 of its scale, far beyond a drilling state: the space is bounded, as Gymnasium's
  checker asks). The sensors' noise, quantisation and delay are the scenario's.
  ``info["measurement"]`` holds the same sample unscaled (the
  :class:`~drill_sim_ros.control.command.SurfaceMeasurement` a controller reads).
* Action (float64, shape (1,)), normalised: in ``speed`` mode a in [0, 1], the speed
  setpoint a x the rpm limit; in ``torque`` mode a in [-1, 1], the motor torque a x the
  drive's torque limit (x 10 steady bit torques if it has none). The WOB follows the
  scenario's schedule. Out-of-range values are clamped as sim_node clamps a command; a NaN
  action commands nothing (the drive keeps its last command).
* Reward of a step (the period's end sample), three terms with constructor weights:
  ``-speed_weight ((omega_bit - omega_0) / omega_0)^2`` (0 when the bit turns at the
  setpoint, -speed_weight when it is stuck; omega_0 the operator's setpoint at the
  sample's time), ``- torque_rate_weight ((tau_k - tau_k-1) / tau_ref)^2`` (tau the motor
  torque, tau_ref the drive's torque limit, 10 steady bit torques if it has none) and
  ``+ rop_weight ROP / ROP_0`` (ROP_0 the ROP of the t = 0 state). Defaults 1, 1, 0.1.
* Episode: the scenario's duration, ``scenario.periods`` steps of one control period. The
  step that reaches its end returns ``truncated`` (a time limit: the rig's state is not
  terminal, so a value estimate may bootstrap from it); ``terminated`` only when the model
  meets a numerical fault (``info["fault"]``, reward 0), after which the episode cannot go
  on. The info of the step that ends it carries the episode's scorecard (``info["score"]``:
  :func:`~drill_sim_ros.control.scorecard.score`, the keys of ``SCORE_FIELDS``, as
  ``drill_sim closed-loop --json`` gives them, with the status and the motor's effort:
  ``motor_torque_std_nm``, ``motor_torque_rate_mean_knm_s``, ``motor_energy_in_mj``).

Options (constructor or ``reset(options=...)``): ``scenario`` (a name of config/scenarios, a
YAML path or a :class:`~drill_sim_ros.control.scenario.Scenario`), ``preset``, ``mode``;
the reward's weights ``speed_weight``, ``torque_rate_weight``, ``rop_weight`` (constructor;
each finite and >= 0). ``reset(seed=s)`` seeds the sensors' noise with ``s`` (else the
scenario's seed): the same seed gives the same episode for the same actions.

Example::

    import gymnasium, drill_sim_ros.gym
    env = gymnasium.make("DrillStickSlip-v0", scenario="field_60rpm")
    obs, info = env.reset(seed=0)
    for _ in range(1000):
        obs, reward, terminated, truncated, info = env.step(env.action_space.sample())
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any, ClassVar

import gymnasium
import numpy as np
from gymnasium import spaces

from drill_sim_ros.control.bench import Bench
from drill_sim_ros.control.command import Command
from drill_sim_ros.control.scenario import Scenario, load_scenario, scenario_path
from drill_sim_ros.control.scorecard import score
from drill_sim_ros.model.errors import NumericalFault, ParameterError
from drill_sim_ros.model.params import RPM_PER_RAD_S
from drill_sim_ros.model.telemetry import TELEMETRY_INDEX as F

ENV_ID = "DrillStickSlip-v0"
OBSERVATION = ("drive_speed", "motor_torque", "string_torque", "hook_load",
               "applied_wob_estimate", "speed_setpoint", "wob_setpoint")
OBSERVATION_LIMIT = 1e3      # the observation's bound, in its scales
REWARD_WEIGHTS = {"speed_weight": 1.0, "torque_rate_weight": 1.0, "rop_weight": 0.1}
_BIT_RPM, _MOTOR, _ROP = F["bit_rpm"], F["motor_torque_nm"], F["rop_m_s"]


@dataclass(frozen=True)
class EpisodeScales:
    """The rig's own scales, fixed for an episode, that the observation is divided by and
    an action of 1 is multiplied by (SI; module doc)."""

    speed_rad_s: float     # omega_0, the speed setpoint at t = 0 (the rpm limit if it is 0)
    torque_nm: float       # the steady-drilling bit torque of the preset's operating point
    hook_load_n: float     # the string's submerged weight (the WOB scale if it has none)
    wob_n: float           # the WOB setpoint at t = 0 (the submerged weight if it is 0)
    action: float          # an action of 1: the rpm limit (rad/s) or tau_ref (N m)
    torque_ref_nm: float   # tau_ref: the drive's torque limit, 10 steady torques if none

    def observation_divisors(self) -> np.ndarray:
        """The divisors of the observation's values, in :data:`OBSERVATION` order."""
        return np.array((self.speed_rad_s, self.torque_nm, self.torque_nm, self.hook_load_n,
                         self.wob_n, self.speed_rad_s, self.wob_n))


def scales_of(bench: Bench) -> EpisodeScales:
    """The scales of the bench's rig and scenario (module doc)."""
    rig, preset, schedule = bench.rig, bench.preset, bench.schedule
    top_rad_s = rig.max_surface_rpm / RPM_PER_RAD_S
    speed = schedule.rpm_at(0.0) / RPM_PER_RAD_S
    steady_nm = preset.scales.tob_nm(bench.session.sim.trivial.torque)   # the bit law's
    torque_ref = rig.max_torque_nm if math.isfinite(rig.max_torque_nm) else 10.0 * steady_nm
    weight_n, wob_n = bench.session.submerged_weight_n, schedule.wob_at(0.0)
    wob_scale = wob_n if wob_n > 0 else weight_n
    return EpisodeScales(speed_rad_s=speed if speed > 0 else top_rad_s,
                  torque_nm=steady_nm if steady_nm > 0 else torque_ref,
                  hook_load_n=weight_n if weight_n > 0 else wob_scale, wob_n=wob_scale,
                  action=top_rad_s if bench.scenario.mode == "speed" else torque_ref,
                  torque_ref_nm=torque_ref)


def _weights(weights: dict[str, float]) -> dict[str, float]:
    for name, value in weights.items():
        if not (isinstance(value, (int, float)) and math.isfinite(value) and value >= 0):
            raise ParameterError(f"reward weight {name} = {value!r} must be finite and >= 0")
    return {name: float(value) for name, value in weights.items()}


def resolve_scenario(scenario: str | Path | Scenario | None, preset: str | None = None,
                     mode: str | None = None) -> Scenario:
    """The environment's scenario from its options (default: config/scenarios/field_60rpm)."""
    if scenario is None:
        scenario = "field_60rpm"
    if not isinstance(scenario, Scenario):
        scenario = load_scenario(scenario_path(scenario))
    return scenario.with_(preset=preset, mode=mode)


class DrillStickSlipEnv(gymnasium.Env):
    """The rig as a Gymnasium environment (module doc)."""

    metadata: ClassVar[dict[str, Any]] = {"render_modes": []}

    def __init__(self, scenario: str | Path | Scenario | None = None,
                 preset: str | None = None, mode: str | None = None,
                 speed_weight: float = REWARD_WEIGHTS["speed_weight"],
                 torque_rate_weight: float = REWARD_WEIGHTS["torque_rate_weight"],
                 rop_weight: float = REWARD_WEIGHTS["rop_weight"]) -> None:
        self.weights = _weights({"speed_weight": speed_weight,
                                 "torque_rate_weight": torque_rate_weight,
                                 "rop_weight": rop_weight})
        self._options: dict[str, Any] = {"scenario": scenario, "preset": preset, "mode": mode}
        self._configure(resolve_scenario(scenario, preset, mode))
        self.observation_space = spaces.Box(-OBSERVATION_LIMIT, OBSERVATION_LIMIT,
                                            (len(OBSERVATION),), np.float64)

    def _configure(self, scenario: Scenario) -> None:
        self.scenario = scenario
        self.bench = Bench(scenario)
        self.scales = scales_of(self.bench)
        self._divisors = self.scales.observation_divisors()
        low = 0.0 if scenario.mode == "speed" else -1.0
        self.action_space = spaces.Box(low, 1.0, (1,), np.float64)

    def reset(self, *, seed: int | None = None,
              options: dict[str, Any] | None = None) -> tuple[np.ndarray, dict[str, Any]]:
        super().reset(seed=seed)
        if options:
            unknown = sorted(set(options) - set(self._options))
            if unknown:
                raise ParameterError(f"reset options {unknown}: known {sorted(self._options)}")
            self._options.update(options)
        scenario = resolve_scenario(**self._options)
        if seed is not None:
            scenario = scenario.with_(sensors={**scenario.sensors, "seed": int(seed)})
        self._configure(scenario)
        row = self.bench.row
        self._rop0 = max(float(row[_ROP]), 1e-12)
        self._last_torque = float(row[_MOTOR])
        return self._observe()

    def step(self, action: Any) -> tuple[np.ndarray, float, bool, bool, dict[str, Any]]:
        value = float(np.asarray(action, dtype=np.float64).reshape(-1)[0])
        try:
            row = self.bench.step(self._command(value))
        except NumericalFault as exc:
            obs, info = self._observe()
            info["fault"] = str(exc)
            return obs, 0.0, True, False, info
        obs, info = self._observe()
        if self.bench.done:
            bench = self.bench
            info["score"] = score(bench.rows, self.scenario.enable_at_s, bench.schedule,
                                  bench.rig, self.scenario.period_s)
        return obs, self._reward(row), False, self.bench.done, info

    def _command(self, value: float) -> Command:
        """The action (normalised) as the command of the newest sample (the WOB from the
        schedule)."""
        wob_n = self._wob_setpoint_n
        if math.isnan(value):
            return Command(wob_n=wob_n)
        if self.scenario.mode == "speed":
            return Command(speed_rad_s=value * self.scales.action, wob_n=wob_n)
        return Command(motor_torque_nm=value * self.scales.action, wob_n=wob_n)

    def _reward(self, row: np.ndarray) -> float:
        """The module doc's reward of the sample ``row`` at the end of a step (the newest;
        omega_0 is the setpoint :meth:`_observe` read at its time)."""
        omega0_rpm = self._rpm_setpoint
        speed = (float(row[_BIT_RPM]) - omega0_rpm) / omega0_rpm if omega0_rpm > 0 else 0.0
        torque = float(row[_MOTOR])
        rate = (torque - self._last_torque) / self.scales.torque_ref_nm
        self._last_torque = torque
        w = self.weights
        return -w["speed_weight"] * speed * speed - w["torque_rate_weight"] * rate * rate + \
            w["rop_weight"] * float(row[_ROP]) / self._rop0

    def _observe(self) -> tuple[np.ndarray, dict[str, Any]]:
        """The newest sample's observation (scaled) and info (its SurfaceMeasurement, what
        a controller reads); the operator's setpoints at its time, kept for the step."""
        bench = self.bench
        time_s = bench.stamp_ns / 1e9
        self._rpm_setpoint = bench.schedule.rpm_at(time_s)
        self._wob_setpoint_n = bench.schedule.wob_at(time_s)
        m = bench.measurement()
        obs = np.array((m.drive_speed_rad_s, m.motor_torque_nm, m.string_torque_nm,
                        m.hook_load_n, m.applied_wob_estimate_n,
                        self._rpm_setpoint / RPM_PER_RAD_S, self._wob_setpoint_n))
        obs /= self._divisors
        np.minimum(obs, OBSERVATION_LIMIT, out=obs)       # (np.clip costs twice as much)
        np.maximum(obs, -OBSERVATION_LIMIT, out=obs)
        return obs, {"measurement": m, "period": bench.period}


if ENV_ID not in gymnasium.registry:
    gymnasium.register(id=ENV_ID, entry_point="drill_sim_ros.gym:DrillStickSlipEnv")
