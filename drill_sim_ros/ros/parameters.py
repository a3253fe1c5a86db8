"""The sim_node parameters: one table of specs feeding descriptors, defaults and validation.

Each :class:`ParamSpec` names a parameter, its type, default (a value, or a function of the
loaded preset for the physical overrides), range, unit and whether it may change at runtime.
The same table produces the rclpy ``ParameterDescriptor`` (with ``FloatingPointRange`` /
``IntegerRange``) and validates values in the set-parameters callback, so the reason a value
is rejected always names the parameter and its allowed range.
"""

from __future__ import annotations

import itertools
import math
import re
import sys
from collections.abc import Callable
from dataclasses import dataclass, fields
from typing import Any

import rclpy
import yaml
from rcl_interfaces.msg import FloatingPointRange, IntegerRange, ParameterDescriptor
from rclpy.exceptions import InvalidParameterTypeException, InvalidParameterValueException
from rclpy.impl.implementation_singleton import rclpy_implementation
from rclpy.utilities import remove_ros_args

from drill_sim_ros.model import defaults
from drill_sim_ros.model.checks import as_number, shown
from drill_sim_ros.model.consistency import check_stick_band, check_wob_carried
from drill_sim_ros.model.errors import ParameterError
from drill_sim_ros.model.measurement import MAX_DELAY_PERIODS, SIGNALS
from drill_sim_ros.model.params import UNIT_SCALES
from drill_sim_ros.model.presets import DEFAULT_PRESET, Preset, submerged_string_weight_n
from drill_sim_ros.model.top_drive import (
    MODES,
    TopDrivePhysical,
    limit_of_setting,
    paper_drive,
    setting_of_limit,
)
from drill_sim_ros.model.yaml_input import load_yaml
from drill_sim_ros.ros.params_file_check import check_params_content
from drill_sim_ros.topics import NODE_NAME

RCLError = rclpy_implementation.RCLError
DOUBLE, INTEGER, BOOL, STRING = "double", "int", "bool", "string"


@dataclass(frozen=True)
class ParamSpec:
    """One parameter: ``default`` may be a callable of the loaded :class:`Preset`."""

    name: str
    kind: str
    default: Any
    description: str
    low: float | None = None
    high: float | None = None
    read_only: bool = False
    choices: tuple[str, ...] = ()     # the allowed values of a string (empty: any)
    unit: str | None = None           # None: the [unit] its description names, if any

    def default_for(self, preset: Preset | None) -> Any:
        return self.default(preset) if callable(self.default) else self.default


def _preset_wob_n(preset: Preset | None) -> float:
    return 0.0 if preset is None else preset.scales.wob_n(preset.params.w0)


def _preset_rpm(preset: Preset | None) -> float:
    return 0.0 if preset is None else preset.scales.rpm(preset.params.omega0)


def _preset_dtau(preset: Preset | None) -> float:
    return defaults.DTAU if preset is None else preset.dtau


def _max_wob_n(preset: Preset | None) -> float:
    return defaults.max_wob_n(_preset_wob_n(preset))


# the top_drive.* limits whose "no limit" is 0 in a ROS double parameter (a finite range) and
# inf in the drive: decoded by top_drive.limit_of_setting / setting_of_limit, nowhere else
LIMIT_PARAMETERS = ("max_torque_nm", "max_torque_rate_nm_s")


def _drive_value(name: str) -> Callable[[Preset | None], Any]:
    """The ``top_drive.<name>`` default: the preset's drive's ``name`` (SI, as it is)."""
    def default(preset: Preset | None) -> Any:
        drive = paper_drive(UNIT_SCALES) if preset is None else preset.drive
        value = getattr(drive, name)
        return setting_of_limit(value) if name in LIMIT_PARAMETERS else value
    return default


def top_drive_of(values: dict[str, Any]) -> TopDrivePhysical:
    """The drive of the ``top_drive.<field>`` parameters in ``values``: one parameter per
    field of :class:`TopDrivePhysical`, in SI as given (the session scales it once), the
    limits' 0 = none through :func:`~drill_sim_ros.model.top_drive.limit_of_setting`."""
    drive = {f.name: values[f"top_drive.{f.name}"] for f in fields(TopDrivePhysical)}
    for name in LIMIT_PARAMETERS:
        drive[name] = limit_of_setting(drive[name])
    return TopDrivePhysical(**drive)


def _sensor_specs() -> tuple[ParamSpec, ...]:
    """sensors.<signal>.noise_std / quantum / delay_periods for each surface signal."""
    out = []
    for signal in SIGNALS:
        unit = {"drive_speed_rad_s": "rad/s", "hook_load_n": "N"}.get(signal, "N m")
        out += [
            ParamSpec(f"sensors.{signal}.noise_std", DOUBLE, 0.0,
                      f"Gaussian noise (standard deviation) of the measured {signal} [{unit}];"
                      " 0 = none. Seeded by sensors.seed: lockstep stays bit-identical.",
                      0.0, 1e9, read_only=True),
            ParamSpec(f"sensors.{signal}.quantum", DOUBLE, 0.0,
                      f"Quantisation step of the measured {signal} [{unit}]; 0 = none.",
                      0.0, 1e9, read_only=True),
            ParamSpec(f"sensors.{signal}.delay_periods", INTEGER, 0,
                      f"Delay of the measured {signal} in whole publish periods.",
                      0, MAX_DELAY_PERIODS, read_only=True, unit="periods"),
        ]
    return tuple(out)


SPECS: tuple[ParamSpec, ...] = (
    ParamSpec("model.preset", STRING, DEFAULT_PRESET,
              "Preset name (config/presets/<name>.yaml) or path to a preset YAML file.",
              read_only=True),
    ParamSpec("model.applied_wob_n", DOUBLE, _preset_wob_n,
              "Initial applied weight on bit [N] (default: the preset's); /drill/cmd/wob "
              "changes the live setpoint, ~/reset returns to this value.",
              0.0, 1e9, read_only=True),
    ParamSpec("model.surface_rpm", DOUBLE, _preset_rpm,
              "Initial top-drive speed [rev/min] (default: the preset's); "
              "/drill/cmd/surface_rpm changes the live setpoint.", 0.0, 1e4, read_only=True),
    ParamSpec("model.dtau", DOUBLE, _preset_dtau,
              "Largest dimensionless integrator step (RGD07 units of t*); refined so that a "
              "whole number of steps fills one publish period.", 1e-7, 0.05, read_only=True,
              unit="1"),
    ParamSpec("model.n_nodes", INTEGER, defaults.n_nodes,
              "Bottom-hole profile nodes per blade sector.", 16, 1 << 22, read_only=True),
    ParamSpec("model.perturb_v", DOUBLE, defaults.PERTURB_V,
              "Dimensionless axial-velocity perturbation added at t = 0 (seeds the "
              "instability).", -1e3, 1e3, read_only=True, unit="1"),
    ParamSpec("model.submerged_string_weight_n", DOUBLE, submerged_string_weight_n,
              "Buoyed weight of drill pipe + BHA [N]; hook load = this - the string's "
              "force at the top (the applied WOB once the hook's loop has settled; this "
              "whole weight off bottom). "
              "Default: steel mass x g x (1 - 1200 kg/m3 mud / steel density); in a "
              "preset's well, the buoyed weight along the hole's axis in its own mud (what "
              "the string hangs with when nothing drags); 0 for dimensionless presets.",
              0.0, 1e10),
    ParamSpec("limits.max_surface_rpm", DOUBLE, defaults.MAX_SURFACE_RPM,
              "Surface-rpm commands above this [rev/min] are clamped to it.", 0.0, 1e4),
    ParamSpec("limits.max_wob_n", DOUBLE, _max_wob_n,
              "WOB commands above this [N] are clamped to it (default: 10 x the preset's WOB).",
              0.0, 1e9),
    ParamSpec("limits.top_drive_accel_rpm_s", DOUBLE, 0.0,
              "Top-drive acceleration limit [rev/min per s]; 0 = step changes.", 0.0, 1e6,
              read_only=True),
    ParamSpec("limits.wob_rate_n_s", DOUBLE, 0.0,
              "Applied-WOB rate limit [N/s]; 0 = step changes.", 0.0, 1e9, read_only=True),
    ParamSpec("commands.delay_s", DOUBLE, 0.0,
              "Transport delay of every setpoint command (drill/cmd/*) [s]: a command "
              "received at sim time t takes effect at t + delay, at the integrator step "
              "nearest it, also within a publish period; 0 = from the next step.", 0.0, 60.0,
              read_only=True),
    ParamSpec("publish_rate_hz", DOUBLE, 100.0,
              "Samples published per second of SIMULATED time.", 1.0, 1000.0, read_only=True,
              unit="Hz"),
    ParamSpec("string.rate_hz", DOUBLE, 10.0,
              "String profiles (topic: string.message) per second of SIMULATED time, on "
              "every round(publish_rate_hz / string.rate_hz)-th sample (at most one per "
              "sample); 0 = off. A lumped string has none.", 0.0, 1000.0, read_only=True,
              unit="Hz"),
    ParamSpec("string.depths", INTEGER, 64,
              "Depths of each string profile: the middles of this many equal intervals of "
              "the string, top to bottom.", 1, 64, read_only=True),
    ParamSpec("string.message", STRING, "typed",
              "The string profiles' message: typed = drill_sim_msgs/StringProfile on "
              "drill/typed/string/torsion (depths, speeds, torques); joint_state = "
              "sensor_msgs/JointState on drill/string/torsion (one joint per depth), for "
              "tools that read only standard messages, and the fallback without "
              "drill_sim_msgs.", read_only=True, choices=("typed", "joint_state")),
    ParamSpec("publish_clock", BOOL, True, "Publish /clock (rosgraph_msgs/Clock) in sim time."),
    ParamSpec("clock_rate_hz", DOUBLE, 100.0,
              "/clock messages per second of SIMULATED time, on the samples' stamps: at most "
              "one per sample (at or above publish_rate_hz, every sample).", 1.0, 1000.0,
              read_only=True),
    ParamSpec("real_time_factor", DOUBLE, 1.0,
              "Simulated seconds per wall second; 0 = as fast as possible.", 0.0, 1000.0,
              unit="1"),
    ParamSpec("lockstep", BOOL, False,
              "Advance one publish period per trigger (lockstep_trigger) only; deterministic."),
    ParamSpec("lockstep.warn_after_s", DOUBLE, 2.0,
              "In lockstep, warn on /diagnostics and in the log after this many wall seconds "
              "without a command (or a ~/step call) [s]; 0 = never.", 0.0, 1e6),
    ParamSpec("lockstep_trigger", STRING, "service",
              "What advances one period in lockstep: 'service' (a ~/step call) or 'command' "
              "(each message on drill/cmd/top_drive, applied first).",
              choices=("service", "command")),
    ParamSpec("top_drive.mode", STRING, _drive_value("mode"),
              "kinematic: the paper's imposed speed; speed: the drive's inertia turned by its "
              "PI speed loop; torque: the motor torque commanded on drill/cmd/top_drive. "
              "Switching keeps the drive's speed and torque (no bump).",
              choices=MODES),
    ParamSpec("top_drive.inertia_kg_m2", DOUBLE, _drive_value("inertia_kg_m2"),
              "Drive inertia J referred to the quill [kg m^2] (default: the preset's).",
              1e-9, 1e9, read_only=True),
    ParamSpec("top_drive.kp_nm_s", DOUBLE, _drive_value("kp_nm_s"),
              "Speed loop proportional gain [N m per rad/s] (speed mode).", 0.0, 1e12),
    ParamSpec("top_drive.ki_nm", DOUBLE, _drive_value("ki_nm"),
              "Speed loop integral gain [N m per rad] (speed mode).", 0.0, 1e12),
    ParamSpec("top_drive.max_torque_nm", DOUBLE, _drive_value("max_torque_nm"),
              "Motor torque limit +-[N m] (speed and torque modes); 0 = none.", 0.0, 1e12),
    ParamSpec("top_drive.motor_lag_s", DOUBLE, _drive_value("motor_lag_s"),
              "Time constant of the first-order lag of the motor torque behind its command "
              "(the drive's torque bandwidth) [s] (speed and torque modes); 0 = none.",
              0.0, 60.0),
    ParamSpec("top_drive.max_torque_rate_nm_s", DOUBLE, _drive_value("max_torque_rate_nm_s"),
              "Largest rate of change of the motor torque, after the lag [N m/s] (speed and "
              "torque modes); 0 = none.", 0.0, 1e12, unit="N m/s"),
    ParamSpec("formation.layers", STRING, "",
              "Rock layers by depth below the start, as a JSON list of {top_m, "
              "intrinsic_specific_energy_pa, mu_gamma, contact_stress_times_wearflat_n_per_m} "
              "(a missing rock key keeps the preset's); each applies from the step the bit "
              "reaches its top; '' = the preset's rock throughout."),
    ParamSpec("sensors.seed", INTEGER, 0, "Seed of the surface sensors' noise.", 0,
              2**31 - 1, read_only=True),
    *_sensor_specs(),
    ParamSpec("run_seconds", DOUBLE, 0.0,
              "Exit cleanly after this many wall seconds; 0 = run until stopped.", 0.0, 1e9,
              read_only=True, unit="s"),
    ParamSpec("record.path", STRING, "",
              "Record every published message to this MCAP file (in process); '' = off. "
              "An existing file is refused unless record.overwrite.", read_only=True),
    ParamSpec("record.overwrite", BOOL, False,
              "Replace an existing record.path (or its split parts) instead of refusing "
              "to start.", read_only=True),
    ParamSpec("record.split_size_mb", DOUBLE, 0.0,
              "Start a new numbered file (run_0000.mcap, ...) after this many MB; 0 = one "
              "file.", 0.0, 1e6, read_only=True, unit="MB"),
    ParamSpec("record.split_duration_s", DOUBLE, 0.0,
              "Start a new numbered file after this many simulated seconds; 0 = one file.",
              0.0, 1e9, read_only=True, unit="s"),
    ParamSpec("diagnostics.window_s", DOUBLE, defaults.WINDOW_S,
              "Simulated seconds of bit speed behind the stick-slip severity on /diagnostics.",
              0.1, 3600.0, read_only=True, unit="s"),
    ParamSpec("diagnostics.command_timeout_s", DOUBLE, 1.0,
              "Once a drill/cmd/top_drive command came, /diagnostics warns (controller "
              "silent) when none follows for this many SIMULATED seconds; 0 = never.", 0.0, 1e6),
    ParamSpec("status_line", BOOL, True,
              "Show one live status line when stderr is a terminal."),
)
SPEC_BY_NAME = {spec.name: spec for spec in SPECS}
# the top_drive.* parameters that may change at runtime: a change rebuilds the drive
RUNTIME_DRIVE_PARAMETERS = frozenset(spec.name for spec in SPECS if not spec.read_only
                                     and spec.name.startswith("top_drive."))


def descriptor(spec: ParamSpec) -> ParameterDescriptor:
    """The rclpy descriptor of ``spec``; doubles accept integers too (``-p x:=2``)."""
    desc = ParameterDescriptor(description=spec.description, read_only=spec.read_only)
    if spec.kind == DOUBLE:
        desc.dynamic_typing = True
        desc.floating_point_range = [FloatingPointRange(
            from_value=float(spec.low), to_value=float(spec.high), step=0.0)]
    elif spec.kind == INTEGER:
        desc.integer_range = [IntegerRange(
            from_value=int(spec.low), to_value=int(spec.high), step=1)]
    if spec.choices:
        desc.additional_constraints = "one of: " + ", ".join(spec.choices)
    return desc


def validate(spec: ParamSpec, value: Any) -> str | None:
    """None if ``value`` is acceptable for ``spec``, else the reason (naming the range)."""
    if spec.kind == DOUBLE:
        if isinstance(value, str) and _beyond_a_double(value):     # rcl keeps it as text
            return (f"{spec.name} = {_shown_text(value)} is beyond a double; it must be a "
                    f"number in [{spec.low:g}, {spec.high:g}]")
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            return f"{spec.name} must be a number, got {value!r}"
        if not (math.isfinite(value) and spec.low <= value <= spec.high):
            return f"{spec.name} = {value!r} is outside [{spec.low:g}, {spec.high:g}]"
    elif spec.kind == INTEGER:
        if isinstance(value, bool) or not isinstance(value, int):
            return f"{spec.name} must be an integer, got {value!r}"
        if not spec.low <= value <= spec.high:
            return f"{spec.name} = {value!r} is outside [{spec.low:g}, {spec.high:g}]"
    elif spec.kind == BOOL and not isinstance(value, bool):
        return f"{spec.name} must be true or false, got {value!r}"
    elif spec.kind == STRING and not isinstance(value, str):
        return f"{spec.name} must be a string, got {value!r}"
    elif spec.choices and value not in spec.choices:
        return f"{spec.name} = {value!r} is not one of {', '.join(spec.choices)}"
    return None


def coerce(spec: ParamSpec, value: Any) -> Any:
    """The Python value the node uses (doubles given as integers become floats)."""
    return float(value) if spec.kind == DOUBLE else value


def yaml_defaults(preset: Preset | None = None) -> dict[str, Any]:
    """``{name: default}`` for a plain YAML loader or documentation."""
    return {spec.name: spec.default_for(preset) for spec in SPECS}


def declare_all(node: Any, load: Callable[[str], Preset]) -> tuple[Preset, dict[str, Any]]:
    """Declare every spec on ``node``; returns the loaded preset and the values in use.

    ``model.preset`` is declared first so the physical defaults can come from it. A value
    that rclpy or the spec rejects raises one ParameterError naming it and its range.
    """
    first = SPECS[0]
    name = _declare(node, first, first.default)
    preset = load(name)
    values: dict[str, Any] = {first.name: name}
    for spec in SPECS[1:]:
        value = _declare(node, spec, spec.default_for(preset))
        reason = validate(spec, value)
        if reason is not None:
            raise ParameterError(reason)
        values[spec.name] = coerce(spec, value)
    check_operating_point(preset, values)
    return preset, values


def check_operating_point(preset: Preset, values: dict[str, Any]) -> None:
    """The start's WOB and speed against the string (model.consistency): the WOB within
    the buoyed weight (when one is modelled, > 0), a turning string above the wall's stick
    band; one ParameterError line naming both."""
    weight_n = values["model.submerged_string_weight_n"]
    if weight_n > 0.0:
        check_wob_carried("model.applied_wob_n", values["model.applied_wob_n"], weight_n)
    well = preset.string.well
    if well is not None and well.has_friction:
        check_stick_band("model.surface_rpm", values["model.surface_rpm"],
                         well.side_friction.stick_speed_rad_s)


_KIND_TEXT = {DOUBLE: "a number", INTEGER: "an integer", BOOL: "true or false",
              STRING: "a string"}


def _declare(node: Any, spec: ParamSpec, default: Any) -> Any:
    """The declared value; rclpy's range and type rejections become one ParameterError."""
    try:
        return node.declare_parameter(spec.name, default, descriptor(spec)).value
    except InvalidParameterValueException as exc:
        given = _VALUE_IN_REASON.search(str(exc))
        shown = given.group(1) if given else "the given value"
        raise ParameterError(f"{spec.name} = {shown} is outside [{spec.low:g}, "
                             f"{spec.high:g}]") from None
    except InvalidParameterTypeException as exc:
        given = _TYPE_IN_REASON.search(str(exc))
        shown = f"{given.group(1)!r} ({given.group(2).lower()})" if given else "another type"
        raise ParameterError(f"{spec.name} must be {_KIND_TEXT[spec.kind]}, got "
                             f"{shown}") from None


def _beyond_a_double(text: str) -> bool:
    """``text`` (what rcl kept as a string) is a number too large for a double (rcl reads
    ``1e400`` and a 400-digit integer as strings)."""
    number = as_number(text)
    return number is not None and math.isinf(number)


def _shown_text(text: str) -> str:
    """A number's text as an error shows it (checks.shown: a long integer as its size)."""
    stripped = text.strip().lstrip("+-")
    return shown(int(text)) if stripped.isdigit() else repr(text)


# rclpy's exception texts (rclpy/exceptions.py) carry the rejected value; they hold no field.
_VALUE_IN_REASON = re.compile(r"Invalid parameter value \((.*?)\) for parameter")
_TYPE_IN_REASON = re.compile(r"to '(.*?)' of type '(\w+)'")
# rcl's messages end in source locations (", at /path/file.c:123") that help nobody here.
_SOURCE_LOCATION = re.compile(r",? at [^,]*\.c:\d+")


def check_params_files(args: list[str]) -> None:
    """Each ``--params-file`` must exist, parse as YAML and set only sim_node parameters
    (``ros.params_file_check``; one ParameterError line if not).

    Checked before rcl sees them, which would log its own parse error and a C source location.
    """
    for flag, path in itertools.pairwise(args):
        if flag != "--params-file":
            continue
        try:
            with open(path, encoding="utf-8") as stream:
                data = load_yaml(stream)
        except OSError as exc:
            raise ParameterError(f"--params-file {path}: {exc.strerror or exc}") from None
        except yaml.YAMLError as exc:
            raise ParameterError(f"--params-file {path} is not valid YAML: "
                                 f"{' '.join(str(exc).split())}") from None
        check_params_content(path, data, NODE_NAME, set(SPEC_BY_NAME))


def check_parameter_rules(args: list[str]) -> None:
    """Each ``-p`` / ``--param`` after ``--ros-args`` must be ``NAME:=VALUE`` (one
    ParameterError line if not), checked before rcl, which would log its own error first."""
    if "--ros-args" not in args:
        return
    rest = args[args.index("--ros-args") + 1:]
    for i, flag in enumerate(rest):
        if flag not in ("-p", "--param"):
            continue
        rule = rest[i + 1] if i + 1 < len(rest) else ""
        name, sep, _ = rule.partition(":=")
        if not sep or not name.strip():
            raise ParameterError(f"{flag} {rule!r}: a parameter override is NAME:=VALUE, "
                                 "e.g. -p real_time_factor:=2.0")


SIM_NODE_USAGE = """usage: sim_node [--ros-args -p NAME:=VALUE ... --params-file FILE ...]

The drill-string simulator as a ROS 2 node (docs/sim_node.md). Its settings are ROS
parameters: `drill_sim params` lists each with its type, unit, range and default."""


def check_plain_args(argv: list[str], usage: str) -> None:
    """The arguments outside ``--ros-args``: ``-h``/``--help`` prints ``usage`` and exits 0;
    anything else is one ParameterError (a node takes its settings as ROS parameters)."""
    try:
        plain = remove_ros_args(argv)[1:]
    except RCLError as exc:                  # rcl parses the ROS arguments to find the rest
        raise bad_ros_arguments(exc) from None
    if "-h" in plain or "--help" in plain:
        print(usage)
        raise SystemExit(0)
    if plain:
        raise ParameterError(f"unknown argument(s) {' '.join(plain)}: settings are ROS "
                             "parameters, given after --ros-args (-p NAME:=VALUE, "
                             "--params-file FILE); --help for more")


def init_ros(args: list[str] | None = None, usage: str = SIM_NODE_USAGE) -> None:
    """``rclpy.init``; ``--help`` prints ``usage``; an unknown plain argument, an unparsable
    ``--ros-args`` or params file raises one ParameterError."""
    check_params_files(sys.argv if args is None else args)
    check_parameter_rules(sys.argv if args is None else args)
    check_plain_args(sys.argv if args is None else args, usage)
    try:
        rclpy.init(args=args)
    except RCLError as exc:
        raise bad_ros_arguments(exc) from None


def bad_ros_arguments(exc: Exception) -> ParameterError:
    """rcl's complaint about the ROS arguments as one line, without its C source locations."""
    text = _SOURCE_LOCATION.sub("", str(exc)).replace("failed to initialize rcl: ", "")
    return ParameterError(f"bad ROS arguments: {text.strip()}")


def recording_options(values: dict[str, Any]) -> dict[str, Any]:
    """The ``record.*`` values as :class:`~drill_sim_ros.archive.inprocess.InProcessRecorder`
    keyword arguments."""
    size_mb, duration_s = values["record.split_size_mb"], values["record.split_duration_s"]
    return {"overwrite": values["record.overwrite"],
            "split_size_bytes": int(size_mb * 1e6) if size_mb > 0 else None,
            "split_duration_s": duration_s if duration_s > 0 else None}
