"""A closed-loop scenario: preset, duration, setpoints, controller, switch-on, sensors.

ROS-free. A scenario YAML file (every key optional but ``controller`` where the command line
does not give it)::

    preset: field_8p5in_shale     # physical preset (name or YAML path)
    duration_s: 180               # simulated seconds
    control_rate_hz: 100          # the control period = the sim's publish period
    mode: speed                   # speed: the controller sends the drive's speed setpoint;
                                  # torque: it closes its own speed loop, sends motor torque
    controller: soft_torque       # none | stiff | soft_torque | z_torque | package.module:Class
    params: {impedance_factor: 2.0}  # the controller's parameters (defaults from the physics)
    enable_at_s: 60               # switch-on time; before it the drive runs on the setpoint
    schedule:                     # steps (ramp_s 0) and ramps of surface rpm and WOB
      - {t_s: 0, rpm: 60, wob_n: 60000}
      - {t_s: 120, rpm: 80, ramp_s: 10}
    sensors:                      # model.measurement: per signal noise_std, quantum,
      seed: 0                     # delay_periods; the noise seed
      string_torque_nm: {noise_std: 50.0}
    description: a short text     # shown in the suite's report
    overrides:                    # changes to the preset's own sections (in process only)
      string: {sections: [{outer_radius_m: 0.0635, inner_radius_m: 0.0543, length_m: 4000},
                          {outer_radius_m: 0.0857, inner_radius_m: 0.0357, length_m: 200}]}
    drive:                        # the drive and the command path (sim_node's parameters)
      accel_rpm_s: 10             # speed ramp limit, rev/min per s (limits.top_drive_accel_rpm_s)
      wob_rate_n_s: 2000          # applied-WOB rate limit, N/s (limits.wob_rate_n_s)
      max_torque_nm: 20000        # motor torque limit, N m (top_drive.max_torque_nm)
      command_delay_s: 0.004      # command transport delay, s, also < a period
                                  # (commands.delay_s)
      motor_lag_s: 0.05           # first-order motor torque lag, s (top_drive.motor_lag_s)
      max_torque_rate_nm_s: 2.0e6 # motor torque rate limit, N m/s, 0: none
                                  # (top_drive.max_torque_rate_nm_s)
    formation:                    # rock layers by depth below the start (model.formation)
      - {top_m: 0.2, intrinsic_specific_energy_pa: 460e6, mu_gamma: 0.6}
    needs: [distributed_string]   # model features the scenario needs (see MODEL_FEATURES)

A scenario that uses a feature the model core does not have yet (``formation``,
``drive.motor_lag_s``, a ``needs`` entry not in :data:`MODEL_FEATURES`) parses, lists it in
:meth:`Scenario.unsupported`, and refuses to run with one line naming it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import yaml

from drill_sim_ros.control.scenario_check import (
    DEFAULT_DURATION_S,
    check_scenario_mapping,
    check_scenario_size,
)
from drill_sim_ros.control.schedule import Schedule, schedule_from_list
from drill_sim_ros.model.checks import as_number, shown
from drill_sim_ros.model.errors import ParameterError
from drill_sim_ros.model.measurement import SIGNALS, RigSensors, SignalSpec
from drill_sim_ros.model.presets import (
    DEFAULT_PRESET,
    Preset,
    config_dirs,
    load_preset,
    preset_from_dict,
    preset_path,
    read_preset_data,
)
from drill_sim_ros.model.top_drive import limit_of_setting
from drill_sim_ros.model.yaml_input import load_yaml

SCENARIO_KEYS = ("preset", "duration_s", "control_rate_hz", "mode", "controller", "params",
                 "enable_at_s", "schedule", "sensors", "description", "overrides", "drive",
                 "formation", "needs")
DRIVE_KEYS = ("accel_rpm_s", "wob_rate_n_s", "max_torque_nm", "command_delay_s",
              "motor_lag_s", "max_torque_rate_nm_s")
MOTOR_KEYS = ("max_torque_nm", "motor_lag_s", "max_torque_rate_nm_s")   # the drive's own
# what this model core can run beyond the keys above; the lead's kernel adds the others
MODEL_FEATURES: frozenset[str] = frozenset(
    ("formation_layers", "motor_lag", "distributed_string"))
FEATURES = ("formation_layers", "motor_lag", "distributed_string")


@dataclass(frozen=True)
class Scenario:
    """One closed-loop experiment (SI)."""

    preset: str = DEFAULT_PRESET
    duration_s: float = DEFAULT_DURATION_S
    control_rate_hz: float = 100.0
    mode: str = "speed"
    controller: str = "stiff"
    params: dict[str, float] = field(default_factory=dict)
    enable_at_s: float = 60.0
    schedule: tuple[dict[str, Any], ...] = ()
    sensors: dict[str, Any] = field(default_factory=dict)
    description: str = ""
    overrides: dict[str, Any] = field(default_factory=dict)
    drive: dict[str, float] = field(default_factory=dict)
    formation: tuple[dict[str, Any], ...] = ()
    needs: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        for name, low in (("duration_s", 0.0), ("control_rate_hz", 0.0)):
            value = getattr(self, name)
            number = as_number(value)
            if not (number is not None and math.isfinite(number) and number > low):
                raise ParameterError(f"scenario: '{name}' = {value!r} must be a number > 0")
        check_scenario_size(self.duration_s, self.control_rate_hz)
        if not (math.isfinite(self.enable_at_s) and 0.0 <= self.enable_at_s <= self.duration_s):
            raise ParameterError(f"scenario: 'enable_at_s' = {self.enable_at_s!r} must lie in "
                                 f"[0, duration_s = {self.duration_s:g}]")
        if self.mode not in ("speed", "torque"):
            raise ParameterError(f"scenario: 'mode' = {self.mode!r} must be speed or torque")
        if not isinstance(self.params, dict):
            raise ParameterError(f"scenario: 'params' must be a mapping, got {self.params!r}")
        _check_drive(self.drive)
        for need in self.needs:
            if need not in FEATURES:
                raise ParameterError(f"scenario: needs {need!r} is not one of {list(FEATURES)}")
        if not isinstance(self.overrides, dict) or not all(
                isinstance(v, dict) for v in self.overrides.values()):
            raise ParameterError("scenario: 'overrides' maps preset sections (physical, "
                                 "top_drive, numerics) to mappings of their keys")

    def unsupported(self) -> list[str]:
        """The model features this scenario needs that the model core does not have."""
        wanted = set(self.needs)
        if self.formation:
            wanted.add("formation_layers")
        if self.drive.get("motor_lag_s"):
            wanted.add("motor_lag")
        return sorted(wanted - MODEL_FEATURES)

    def check_supported(self) -> None:
        """ParameterError naming what the model core cannot run yet."""
        missing = self.unsupported()
        if missing:
            raise ParameterError(f"scenario needs {', '.join(missing)}: not yet supported by "
                                 "this model core (issue 23: the model core's formation layers "
                                 "and motor lag, issue 21: the distributed string)")

    def with_(self, **changes: Any) -> Scenario:
        return replace(self, **{k: v for k, v in changes.items() if v is not None})

    @property
    def periods(self) -> int:
        return round(self.duration_s * self.control_rate_hz)

    @property
    def period_s(self) -> float:
        return 1.0 / self.control_rate_hz

    def load_preset(self) -> Preset:
        """The preset with the scenario's ``overrides``, its drive with the scenario's
        ``drive.max_torque_nm``, ``motor_lag_s`` and ``max_torque_rate_nm_s`` (0: none,
        ``top_drive.limit_of_setting``, as sim_node reads its ``top_drive.*``): the drive
        sim_node runs and the controllers are tuned from (``rig_physics``)."""
        preset = self._overridden_preset()
        motor = {key: float(self.drive[key]) for key in MOTOR_KEYS if key in self.drive}
        if "max_torque_rate_nm_s" in motor:
            motor["max_torque_rate_nm_s"] = limit_of_setting(motor["max_torque_rate_nm_s"])
        if not motor:
            return preset
        return replace(preset, drive=replace(preset.drive, **motor))

    def _overridden_preset(self) -> Preset:
        """The preset with the scenario's ``overrides`` of its sections."""
        overrides = {section: dict(values) for section, values in self.overrides.items()}
        if not overrides:
            return load_preset(self.preset)
        path = preset_path(self.preset)
        data = read_preset_data(path) or {}
        for section, values in overrides.items():
            if not isinstance(data.get(section, {}), dict):
                raise ParameterError(f"scenario: overrides.{section}: the preset's {section} "
                                     "is not a mapping")
            data[section] = {**(data.get(section) or {}), **values}
        try:
            return preset_from_dict(path.stem, data)
        except (ParameterError, TypeError) as exc:
            raise ParameterError(f"scenario: overrides of preset {self.preset!r}: {exc}"
                                 ) from exc

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
                "sensors": dict(self.sensors), "description": self.description,
                "overrides": {k: dict(v) for k, v in self.overrides.items()},
                "drive": dict(self.drive), "formation": [dict(x) for x in self.formation],
                "needs": list(self.needs)}


def _check_drive(drive: Any) -> dict[str, float]:
    """The ``drive`` mapping's values as floats (YAML 1.1's ``2.0e6`` text too), each in
    its range; one ParameterError line naming the key otherwise."""
    if not isinstance(drive, dict):
        raise ParameterError(f"scenario: 'drive' must be a mapping of {list(DRIVE_KEYS)}")
    for key, value in drive.items():
        if key not in DRIVE_KEYS:
            raise ParameterError(f"scenario: drive.{key} is not one of {list(DRIVE_KEYS)}")
        delay = key in ("command_delay_s", "motor_lag_s")
        parsed = as_number(value)
        number = parsed is not None and math.isfinite(parsed)
        value = parsed if number else value
        if delay:
            ok, allowed = number and 0.0 <= value <= 60.0, "in [0, 60]"
        elif key == "max_torque_rate_nm_s":             # 0: none, as sim_node's parameter
            ok, allowed = number and value >= 0.0, ">= 0 (0: no limit)"
        else:
            ok, allowed = number and value > 0.0, "> 0"
        if not ok:
            raise ParameterError(f"scenario: drive.{key} = {shown(value)} must be a number "
                                 f"{allowed}")
    return {key: float(as_number(value) or 0.0) for key, value in drive.items()}


def scenario_from_dict(data: dict[str, Any]) -> Scenario:
    """A :class:`Scenario` from a parsed mapping; unknown keys are named."""
    if not isinstance(data, dict):
        raise ParameterError("scenario: the file must hold a mapping")
    unknown = sorted(set(data) - set(SCENARIO_KEYS))
    if unknown:
        raise ParameterError(f"scenario: unknown key(s) {unknown}; known: {list(SCENARIO_KEYS)}")
    values = check_scenario_mapping(data)
    values["overrides"] = dict(values.get("overrides") or {})
    values["drive"] = _check_drive(values.get("drive") or {})
    values["formation"] = tuple(values.get("formation") or ())
    values["needs"] = tuple(values.get("needs") or ())
    values["description"] = " ".join(str(values.get("description") or "").split())
    return Scenario(**values)


def load_scenario(path: str | Path) -> Scenario:
    """A scenario YAML file; ParameterError naming the file when it cannot be read."""
    path = Path(path)
    try:
        data = load_yaml(path.read_text())
    except OSError as exc:
        raise ParameterError(f"scenario file {path}: {exc.strerror}") from exc
    except yaml.YAMLError as exc:
        raise ParameterError(f"scenario file {path} is not valid YAML: {exc}") from exc
    try:
        return scenario_from_dict(data)
    except ParameterError as exc:
        raise ParameterError(f"{path}: {exc}") from exc


def scenario_dir() -> Path:
    """config/scenarios of the first config directory that has it."""
    for base in config_dirs():
        if (base / "scenarios").is_dir():
            return base / "scenarios"
    raise ParameterError("no config/scenarios directory found (set DRILL_SIM_CONFIG_DIR)")


def scenario_path(name_or_path: str | Path) -> Path:
    """A scenario by name (config/scenarios/<name>.yaml) or a YAML path; ParameterError
    naming the known scenarios otherwise."""
    path = Path(name_or_path)
    if path.suffix in (".yaml", ".yml") and path.exists():
        return path
    path = scenario_dir() / f"{name_or_path}.yaml"
    if not path.exists():
        known = ", ".join(p.stem for p in sorted(scenario_dir().glob("*.yaml")))
        raise ParameterError(f"scenario {str(name_or_path)!r}: no such file or scenario "
                             f"(known: {known})")
    return path


def save_scenario(scenario: Scenario, path: str | Path) -> None:
    Path(path).write_text(yaml.safe_dump(scenario.to_dict(), sort_keys=False))


# ---- ensembles: one case, independent realisations of its chaos ----------------------------
# member k of an ensemble runs with the bit's sigma l x (1 + k ENSEMBLE_STEP): no bit's wear is
# known to a part in 1e12, so every member is the same case, and a chaotic stick-slip grows
# the difference into an independent realisation (docs/league.md)
ENSEMBLE_STEP = 1e-12
ENSEMBLE_KEY = "contact_stress_times_wearflat_n_per_m"
MAX_ENSEMBLE = 64


def check_ensemble(members: Any) -> int:
    """``--ensemble N``: an integer in [1, MAX_ENSEMBLE]."""
    if isinstance(members, bool) or not isinstance(members, int) or \
            not 1 <= members <= MAX_ENSEMBLE:
        raise ParameterError(f"--ensemble {members!r} must be an integer in [1, "
                             f"{MAX_ENSEMBLE}]")
    return members


def ensemble_caption(members: int) -> str:
    """The line above an ensemble's table (suite, closed-loop, report.md)."""
    return (f"the ensemble of {members} members (member 0: the case as it is; member k: the "
            f"bit's sigma l x (1 + k {ENSEMBLE_STEP:g}), the same for every controller):")


def seeded(scenario: Scenario, member: int) -> Scenario:
    """Member ``member`` of an ensemble of ``scenario``: its preset's sigma l (after the
    scenario's own overrides) x (1 + member ENSEMBLE_STEP), as an override; member 0 is
    ``scenario`` itself."""
    if member == 0:
        return scenario
    physical = scenario.load_preset().physical
    if physical is None:
        raise ParameterError(f"--ensemble: preset {scenario.preset!r} is dimensionless; an "
                             "ensemble seeds the bit's sigma l of a physical preset")
    sigma_l = physical.contact_stress_times_wearflat_n_per_m * (1.0 + member * ENSEMBLE_STEP)
    own = dict(scenario.overrides.get("physical", {}))
    return scenario.with_(overrides={**scenario.overrides,
                                     "physical": {**own, ENSEMBLE_KEY: sigma_l}})
