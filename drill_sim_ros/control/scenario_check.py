"""Checks of a closed-loop scenario's values: types, ranges and the bounded size of a run.

ROS-free. :func:`check_scenario_mapping` checks a scenario file's parsed mapping key by key
(one :class:`ParameterError` line naming the key, the value and what is allowed);
:func:`check_scenario_size` bounds the run whatever its source (file, command line):
the control rate within sim_node's ``publish_rate_hz`` range and at most
:data:`MAX_PERIODS` periods, so a run never asks for memory it cannot have (a period's row
of telemetry is kept: N_FIELDS = 24 float64).
"""

from __future__ import annotations

import math
from typing import Any

from drill_sim_ros.control.schedule import check_points
from drill_sim_ros.model.checks import as_number, check_known_keys, shown
from drill_sim_ros.model.errors import ParameterError
from drill_sim_ros.model.measurement import MAX_DELAY_PERIODS, SIGNALS
from drill_sim_ros.model.validate_input import check_no_empty_block

CONTROL_RATE_RANGE_HZ = (1.0, 1000.0)      # sim_node's publish_rate_hz
MAX_PERIODS = 2_000_000                    # 2e6 rows x 24 float64 = 384 MB per run
SIGNAL_KEYS = ("noise_std", "quantum", "delay_periods")
_STRINGS = ("preset", "mode", "controller")
_NUMBERS = ("duration_s", "control_rate_hz", "enable_at_s")
_BLOCKS = ("params", "schedule", "sensors", "overrides", "drive", "formation", "needs")
DEFAULT_DURATION_S = 180.0                 # a scenario's duration_s when it gives none


def check_number(where: str, value: Any) -> float:
    """``value`` as a float if it is a finite number (not a bool; YAML 1.1's ``1.0e7`` is a
    string that is a number, ``abc`` is not)."""
    number = as_number(value)
    if number is None or not math.isfinite(number):
        raise ParameterError(f"scenario: '{where}' = {shown(value)} must be a finite number")
    return float(number)


def check_integer(where: str, value: Any, low: int, high: int) -> int:
    """``value`` if it is a whole number in [low, high]."""
    number = as_number(value)
    if number is None or not float(number).is_integer() or not low <= number <= high:
        raise ParameterError(f"scenario: '{where}' = {shown(value)} must be a whole number in "
                             f"[{low}, {high}]")
    return int(number)


def check_params(params: Any) -> dict[str, float]:
    """The controller's parameters: a mapping of names to finite numbers."""
    if not isinstance(params, dict):
        raise ParameterError(f"scenario: 'params' = {params!r} must be a mapping of "
                             "parameter names to numbers, e.g. {impedance_factor: 2.0}")
    return {str(k): check_number(f"params.{k}", v) for k, v in params.items()}


def check_schedule(schedule: Any, duration_s: float) -> tuple[dict[str, Any], ...]:
    """A list of mappings, their keys and values checked, each point before the run's end
    (:func:`~drill_sim_ros.control.schedule.check_points`)."""
    if not isinstance(schedule, list) or not all(isinstance(p, dict) for p in schedule):
        raise ParameterError(f"scenario: 'schedule' = {schedule!r} must be a list of "
                             "mappings, e.g. [{t_s: 0, rpm: 60}]")
    try:
        return check_points(schedule, duration_s)
    except ParameterError as exc:
        raise ParameterError(f"scenario: {exc}") from None


def check_sensors(sensors: Any) -> dict[str, Any]:
    """``seed`` (an integer) and, per signal of SIGNALS, a mapping of SIGNAL_KEYS."""
    if not isinstance(sensors, dict):
        raise ParameterError(f"scenario: 'sensors' = {sensors!r} must be a mapping")
    for name, spec in sensors.items():
        if name == "seed":
            check_integer("sensors.seed", spec, 0, 2**32 - 1)
            continue
        if name not in SIGNALS:
            raise ParameterError(f"scenario: unknown key 'sensors.{name}'; known: seed, "
                                 f"{', '.join(SIGNALS)}")
        if not isinstance(spec, dict):
            raise ParameterError(f"scenario: 'sensors.{name}' = {spec!r} must be a mapping "
                                 f"of {', '.join(SIGNAL_KEYS)}")
        check_known_keys(spec, SIGNAL_KEYS, f"sensors.{name}")
        for key, value in spec.items():
            if key == "delay_periods":
                spec[key] = check_integer(f"sensors.{name}.{key}", value, 0,
                                          MAX_DELAY_PERIODS)
                continue
            spec[key] = check_number(f"sensors.{name}.{key}", value)
            if spec[key] < 0.0:
                raise ParameterError(f"scenario: 'sensors.{name}.{key}' = {value!r} must "
                                     "be >= 0")
    if "seed" in sensors:
        sensors["seed"] = check_integer("sensors.seed", sensors["seed"], 0, 2**32 - 1)
    return dict(sensors)


def check_scenario_mapping(data: dict[str, Any]) -> dict[str, Any]:
    """The values of a scenario file's mapping (its keys already known), type-checked."""
    values = dict(data)
    try:
        check_no_empty_block(values, "", _BLOCKS)
    except ParameterError as exc:
        raise ParameterError(f"scenario: {exc}") from None
    for key in _STRINGS:
        if key in values and not (isinstance(values[key], str) and values[key]):
            raise ParameterError(f"scenario: '{key}' = {values[key]!r} must be a name "
                                 "(a string)")
    for key in _NUMBERS:
        if key in values:
            values[key] = check_number(key, values[key])
    if not isinstance(values.get("description", ""), str):
        raise ParameterError(f"scenario: 'description' = {values['description']!r} must be "
                             "text")
    for key in ("overrides", "drive"):
        if not isinstance(values.get(key) or {}, dict):
            raise ParameterError(f"scenario: '{key}' = {values[key]!r} must be a mapping")
    for key in ("formation", "needs"):
        if not isinstance(values.get(key) or [], list):
            raise ParameterError(f"scenario: '{key}' = {values[key]!r} must be a list")
    values["params"] = check_params(values.get("params") or {})
    values["schedule"] = check_schedule(values.get("schedule") or [],
                                        values.get("duration_s", DEFAULT_DURATION_S))
    values["sensors"] = check_sensors(values.get("sensors") or {})
    return values


def check_scenario_size(duration_s: float, control_rate_hz: float) -> None:
    """The rate within CONTROL_RATE_RANGE_HZ and the run within MAX_PERIODS periods."""
    low, high = CONTROL_RATE_RANGE_HZ
    if not low <= control_rate_hz <= high:
        raise ParameterError(f"scenario: 'control_rate_hz' = {control_rate_hz:g} is outside "
                             f"[{low:g}, {high:g}] Hz (sim_node's publish_rate_hz)")
    periods = duration_s * control_rate_hz
    if periods > MAX_PERIODS:
        raise ParameterError(f"scenario: 'duration_s' (--t-end) = {duration_s:g} s at "
                             f"{control_rate_hz:g} Hz is {periods:.3g} periods; at most "
                             f"{MAX_PERIODS:,} ({MAX_PERIODS / control_rate_hz:g} s at this "
                             "rate)")
