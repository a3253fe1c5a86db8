"""A Gymnasium environment of the rig: ``DrillStickSlip-v0`` (registered on import).

One step is one control period of the closed-loop bench
(:class:`~drill_sim_ros.control.bench.Bench`, the same stepper as ``drill_sim closed-loop``),
so a policy that computes what a controller computes gets the bench's run of that controller
bit for bit.

* Observation (float64, shape (7,)): what the rig measures at the surface and the driller's
  setpoints, never downhole truth: the drive's measured speed (rad/s), its motor torque
  (N m), the string torque at the quill (N m), the hook load (N), the applied-WOB estimate
  (N), the operator's speed setpoint (rad/s) and WOB setpoint (N) at the sample's time.
  The sensors' noise, quantisation and delay are the scenario's.
* Action (float64, shape (1,)): in ``speed`` mode the drive's speed setpoint (rad/s, within
  [0, the rpm limit]); in ``torque`` mode the motor torque (N m, within +-the drive's limit).
  The WOB follows the scenario's schedule. Out-of-range values are clamped as sim_node
  clamps a command; a NaN action commands nothing (the drive keeps its last command).
* Reward of a step (the period's end sample): ``-((omega_bit - omega_0) / omega_0)^2
  - torque_rate_weight ((tau_k - tau_k-1) / tau_ref)^2 + rop_weight ROP / ROP_0`` with
  omega_0 the operator's speed setpoint, tau the motor torque, tau_ref the drive's torque
  limit (10 x the steady bit torque if it has none) and ROP_0 the ROP of the t = 0 state.
  The first term is 0 when the bit turns at the setpoint, 1 when it is stuck.
* An episode is the scenario's duration (truncated at its end); a numerical fault of the
  model terminates it (``info["fault"]``). The info of the step that ends it carries the
  episode's scorecard (``info["score"]``: :func:`~drill_sim_ros.control.scorecard.score`,
  the keys of ``SCORE_FIELDS``, as ``drill_sim closed-loop --json`` gives them, with the
  status and the motor's effort: ``motor_torque_std_nm``, ``motor_torque_rate_mean_knm_s``,
  ``motor_energy_in_mj``).

Options (constructor or ``reset(options=...)``): ``scenario`` (a name of config/scenarios, a
YAML path or a :class:`~drill_sim_ros.control.scenario.Scenario`), ``preset``, ``mode``.
``reset(seed=s)`` seeds the sensors' noise with ``s`` (else the scenario's seed): the same
seed gives the same episode for the same actions.

Example::

    import gymnasium, drill_sim_ros.gym
    env = gymnasium.make("DrillStickSlip-v0", scenario="field_60rpm")
    obs, info = env.reset(seed=0)
    for _ in range(1000):
        obs, reward, terminated, truncated, info = env.step(env.action_space.sample())
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any, ClassVar

import gymnasium
import numpy as np
from gymnasium import spaces

from drill_sim_ros.control.bench import Bench
from drill_sim_ros.control.command import Command
from drill_sim_ros.control.scenario import Scenario, load_scenario, scenario_path
from drill_sim_ros.control.scorecard import score
from drill_sim_ros.model import analysis
from drill_sim_ros.model.errors import NumericalFault, ParameterError
from drill_sim_ros.model.params import RPM_PER_RAD_S
from drill_sim_ros.model.telemetry import TELEMETRY_INDEX as F

ENV_ID = "DrillStickSlip-v0"
OBSERVATION = ("drive_speed_rad_s", "motor_torque_nm", "string_torque_nm", "hook_load_n",
               "applied_wob_estimate_n", "speed_setpoint_rad_s", "wob_setpoint_n")
_BIT_RPM, _MOTOR, _ROP = F["bit_rpm"], F["motor_torque_nm"], F["rop_m_s"]


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
                 torque_rate_weight: float = 1.0, rop_weight: float = 0.1) -> None:
        self.torque_rate_weight, self.rop_weight = float(torque_rate_weight), float(rop_weight)
        self._options: dict[str, Any] = {"scenario": scenario, "preset": preset, "mode": mode}
        self._configure(resolve_scenario(scenario, preset, mode))
        self.observation_space = spaces.Box(-np.inf, np.inf, (len(OBSERVATION),), np.float64)

    def _configure(self, scenario: Scenario) -> None:
        self.scenario = scenario
        self.bench = Bench(scenario)
        rig = self.bench.rig
        if scenario.mode == "speed":
            high = rig.max_surface_rpm / RPM_PER_RAD_S
            self.action_space = spaces.Box(0.0, high, (1,), np.float64)
        else:
            limit = rig.max_torque_nm
            self.action_space = spaces.Box(-limit, limit, (1,), np.float64)
        preset = self.bench.preset
        steady_nm = preset.scales.tob_nm(analysis.trivial_solution(preset.params).torque)
        self.torque_ref_nm = rig.max_torque_nm if math.isfinite(rig.max_torque_nm) else \
            10.0 * steady_nm

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
        """The action as the command of the newest sample (the WOB from the schedule)."""
        wob_n = self._wob_setpoint_n
        if math.isnan(value):
            return Command(wob_n=wob_n)
        if self.scenario.mode == "speed":
            return Command(speed_rad_s=value, wob_n=wob_n)
        return Command(motor_torque_nm=value, wob_n=wob_n)

    def _reward(self, row: np.ndarray) -> float:
        """The module doc's reward of the sample ``row`` at the end of a step (the newest;
        omega_0 is the setpoint :meth:`_observe` read at its time)."""
        omega0_rpm = self._rpm_setpoint
        speed = (float(row[_BIT_RPM]) - omega0_rpm) / omega0_rpm if omega0_rpm > 0 else 0.0
        torque = float(row[_MOTOR])
        rate = (torque - self._last_torque) / self.torque_ref_nm
        self._last_torque = torque
        return -speed * speed - self.torque_rate_weight * rate * rate + \
            self.rop_weight * float(row[_ROP]) / self._rop0

    def _observe(self) -> tuple[np.ndarray, dict[str, Any]]:
        """The newest sample's observation and info (its SurfaceMeasurement, what a
        controller reads); the operator's setpoints at its time, kept for the step."""
        bench = self.bench
        time_s = bench.stamp_ns / 1e9
        self._rpm_setpoint = bench.schedule.rpm_at(time_s)
        self._wob_setpoint_n = bench.schedule.wob_at(time_s)
        m = bench.measurement()
        obs = np.array((m.drive_speed_rad_s, m.motor_torque_nm, m.string_torque_nm,
                        m.hook_load_n, m.applied_wob_estimate_n,
                        self._rpm_setpoint / RPM_PER_RAD_S, self._wob_setpoint_n))
        return obs, {"measurement": m, "period": bench.period}


if ENV_ID not in gymnasium.registry:
    gymnasium.register(id=ENV_ID, entry_point="drill_sim_ros.gym:DrillStickSlipEnv")
