"""A closed-loop scenario: preset, duration, setpoints, controller, switch-on, sensors.

ROS-free. A scenario YAML file (every key optional but ``controller`` where the command line
does not give it)::

    preset: field_8p5in_shale     # physical preset (name or YAML path)
    duration_s: 180               # simulated seconds
    control_rate_hz: 100          # the control period = the sim's publish period
    mode: speed                   # speed: the controller sends the drive's speed setpoint;
                                  # torque: it closes its own speed loop, sends motor torque
    controller: soft_torque       # none | stiff | soft_torque | z_torque | package.module:Class
    params: {damping_ratio: 0.5}  # the controller's parameters (defaults from the physics)
    enable_at_s: 60               # switch-on time; before it the drive runs on the setpoint
    schedule:                     # steps (ramp_s 0) and ramps of surface rpm and WOB
      - {t_s: 0, rpm: 60, wob_n: 60000}
      - {t_s: 120, rpm: 80, ramp_s: 10}
    sensors:                      # model.measurement: per signal noise_std, quantum,
      seed: 0                     # delay_periods; the noise seed
      string_torque_nm: {noise_std: 50.0}
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import yaml

from drill_sim_ros.control.scenario_check import check_scenario_mapping, check_scenario_size
from drill_sim_ros.control.schedule import Schedule, schedule_from_list
from drill_sim_ros.model.errors import ParameterError
from drill_sim_ros.model.measurement import SIGNALS, RigSensors, SignalSpec
from drill_sim_ros.model.presets import DEFAULT_PRESET, Preset
from drill_sim_ros.model.validate_input import load_checked_preset

SCENARIO_KEYS = ("preset", "duration_s", "control_rate_hz", "mode", "controller", "params",
                 "enable_at_s", "schedule", "sensors")


@dataclass(frozen=True)
class Scenario:
    """One closed-loop experiment (SI)."""

    preset: str = DEFAULT_PRESET
    duration_s: float = 180.0
    control_rate_hz: float = 100.0
    mode: str = "speed"
    controller: str = "stiff"
    params: dict[str, float] = field(default_factory=dict)
    enable_at_s: float = 60.0
    schedule: tuple[dict[str, Any], ...] = ()
    sensors: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        for name, low in (("duration_s", 0.0), ("control_rate_hz", 0.0)):
            value = getattr(self, name)
            if not (isinstance(value, (int, float)) and math.isfinite(value) and value > low):
                raise ParameterError(f"scenario: '{name}' = {value!r} must be a number > 0")
        check_scenario_size(self.duration_s, self.control_rate_hz)
        if not (math.isfinite(self.enable_at_s) and 0.0 <= self.enable_at_s <= self.duration_s):
            raise ParameterError(f"scenario: 'enable_at_s' = {self.enable_at_s!r} must lie in "
                                 f"[0, duration_s = {self.duration_s:g}]")
        if self.mode not in ("speed", "torque"):
            raise ParameterError(f"scenario: 'mode' = {self.mode!r} must be speed or torque")
        if not isinstance(self.params, dict):
            raise ParameterError(f"scenario: 'params' must be a mapping, got {self.params!r}")

    def with_(self, **changes: Any) -> Scenario:
        return replace(self, **{k: v for k, v in changes.items() if v is not None})

    @property
    def periods(self) -> int:
        return round(self.duration_s * self.control_rate_hz)

    @property
    def period_s(self) -> float:
        return 1.0 / self.control_rate_hz

    def load_preset(self) -> Preset:
        return load_checked_preset(self.preset)

    def setpoints(self, preset: Preset) -> Schedule:
        """The schedule, starting from the preset's rpm and WOB where it does not say."""
        phys = preset.physical
        rpm0 = phys.surface_rpm if phys else preset.scales.rpm(preset.params.omega0)
        wob0 = phys.applied_wob_n if phys else preset.scales.wob_n(preset.params.w0)
        return schedule_from_list(list(self.schedule), rpm0, wob0)

    def rig_sensors(self) -> RigSensors:
        specs = {}
        for name, spec in self.sensors.items():
            if name == "seed":
                continue
            if name not in SIGNALS or not isinstance(spec, dict):
                raise ParameterError(f"scenario: sensors.{name} is not one of {list(SIGNALS)} "
                                     "with a mapping of noise_std, quantum, delay_periods")
            specs[name] = SignalSpec(**spec)
        return RigSensors(specs, seed=int(self.sensors.get("seed", 0)))

    def to_dict(self) -> dict[str, Any]:
        return {"preset": self.preset, "duration_s": self.duration_s,
                "control_rate_hz": self.control_rate_hz, "mode": self.mode,
                "controller": self.controller, "params": dict(self.params),
                "enable_at_s": self.enable_at_s, "schedule": [dict(p) for p in self.schedule],
                "sensors": dict(self.sensors)}


def scenario_from_dict(data: dict[str, Any]) -> Scenario:
    """A :class:`Scenario` from a parsed mapping; unknown keys are named."""
    if not isinstance(data, dict):
        raise ParameterError("scenario: the file must hold a mapping")
    unknown = sorted(set(data) - set(SCENARIO_KEYS))
    if unknown:
        raise ParameterError(f"scenario: unknown key(s) {unknown}; known: {list(SCENARIO_KEYS)}")
    return Scenario(**check_scenario_mapping(data))


def load_scenario(path: str | Path) -> Scenario:
    """A scenario YAML file; ParameterError naming the file when it cannot be read."""
    path = Path(path)
    try:
        data = yaml.safe_load(path.read_text())
    except OSError as exc:
        raise ParameterError(f"scenario file {path}: {exc.strerror}") from exc
    except yaml.YAMLError as exc:
        raise ParameterError(f"scenario file {path} is not valid YAML: {exc}") from exc
    try:
        return scenario_from_dict(data)
    except ParameterError as exc:
        raise ParameterError(f"{path}: {exc}") from exc


def save_scenario(scenario: Scenario, path: str | Path) -> None:
    Path(path).write_text(yaml.safe_dump(scenario.to_dict(), sort_keys=False))
