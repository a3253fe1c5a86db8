"""top_drive_controller: a reference controller as a ROS node (node ``top_drive_controller``).

Subscribes to the rig's surface measurements only (``drill/surface/measured``: the drive's
encoder, motor torque and torque sub; never the downhole truth) and publishes one
``drill/cmd/top_drive`` command per sample, stamped with the sample it reacts to. With the sim
in command-triggered lockstep (``lockstep:=true -p lockstep_trigger:=command``) it drives the
pace: the loop of :class:`~drill_sim_ros.ros.lockstep_driver.LockstepDriver`, with a
controller of :mod:`drill_sim_ros.control` as its policy.

    top_drive_controller --ros-args -p controller:=soft_torque -p enable_at_s:=60.0 \
        -p soft_torque.impedance_factor:=1.5
    top_drive_controller --ros-args -p scenario:=my_scenario.yaml -p periods:=18000
"""

from __future__ import annotations

import json
import math
import sys
import time
from typing import Any

import rclpy
import yaml
from rcl_interfaces.msg import FloatingPointRange, IntegerRange, ParameterDescriptor
from rclpy.executors import ExternalShutdownException, SingleThreadedExecutor

from drill_sim_ros import topics
from drill_sim_ros.control.bench import build_controller
from drill_sim_ros.control.command import Command, SurfaceMeasurement
from drill_sim_ros.control.controllers import CONTROL_MODES
from drill_sim_ros.control.isolation import ControllerError
from drill_sim_ros.control.registry import BUILTIN
from drill_sim_ros.control.scenario import Scenario, load_scenario
from drill_sim_ros.model.checks import as_number, shown
from drill_sim_ros.model.errors import DrillSimError, ParameterError
from drill_sim_ros.model.yaml_input import load_yaml
from drill_sim_ros.ros.lockstep_driver import LockstepDriver
from drill_sim_ros.ros.parameters import check_parameter_rules, check_plain_args

NODE_NAME = "top_drive_controller"
CONTROLLER_ERROR_PREFIX = f"{NODE_NAME}: error: "
CONTROLLER_USAGE = """usage: top_drive_controller [--ros-args -p controller:=NAME ...]

A reference top-drive controller as a ROS 2 node, answering every sample of sim_node in
lockstep (docs/closed-loop.md, docs/control-loop.md). Its settings are ROS parameters."""


def _double(description: str, low: float = 0.0, high: float = 1e9) -> ParameterDescriptor:
    return ParameterDescriptor(description=description, read_only=True, dynamic_typing=True,
                               floating_point_range=[FloatingPointRange(
                                   from_value=low, to_value=high, step=0.0)])


class ControllerNode(LockstepDriver):
    """The controller of the node's parameters (a scenario file, then the overrides)."""

    def __init__(self, **node_kwargs: Any) -> None:
        super().__init__(self._react, periods=0, name=NODE_NAME,
                         sample_topic=topics.SURFACE_MEASURED, keep=False, **node_kwargs)
        self.scenario = self._declared_scenario()
        self.periods = self.get_parameter("periods").value
        preset = self.scenario.load_preset()
        self.controller = build_controller(self.scenario, preset)
        self.first_sample_s: float | None = None
        self.last_sample_s: float | None = None
        self.get_logger().info(
            f"{self.scenario.controller} ({self.scenario.mode} mode) on {preset.name}, "
            f"switch-on at {self.scenario.enable_at_s:g} s, "
            f"params {getattr(self.controller, 'params', self.scenario.params)}")

    def _declared_scenario(self) -> Scenario:
        path = self.declare_parameter("scenario", "", ParameterDescriptor(
            description="scenario YAML (control/scenario.py); the parameters below override "
                        "it; '' = the defaults", read_only=True)).value
        base = load_scenario(path) if path else Scenario()
        name = self.declare_parameter("controller", base.controller, ParameterDescriptor(
            description=f"one of {sorted(BUILTIN)} or package.module:Class",
            read_only=True)).value
        mode = self.declare_parameter("mode", base.mode, ParameterDescriptor(
            description="speed: send the drive's speed setpoint; torque: close the speed loop "
                        "here and send the motor torque", read_only=True,
            additional_constraints="one of: " + ", ".join(CONTROL_MODES))).value
        preset = self.declare_parameter("preset", base.preset, ParameterDescriptor(
            description="physical preset the controller is tuned from (the sim's "
                        "model.preset)", read_only=True)).value
        enable_at_s = self.declare_parameter("enable_at_s", base.enable_at_s, _double(
            "switch-on time, simulated s; before it the drive runs on the setpoint")).value
        self.declare_parameter("periods", 0, ParameterDescriptor(
            description="stop after this many periods (0: run until stopped)", read_only=True,
            integer_range=[IntegerRange(from_value=0, to_value=2**31 - 1, step=1)]))
        params = dict(base.params)
        text = self.declare_parameter("params", "", ParameterDescriptor(
            description="the controller's parameters as a YAML mapping (for module:Class "
                        "controllers), e.g. '{gain: 2.0}'", read_only=True)).value
        if text:
            params.update(params_from_text(text))
        for cls in BUILTIN.values():
            for key, description in cls.PARAMS.items():
                value = self.declare_parameter(f"{cls.name}.{key}", 0.0, _double(
                    f"{description}; 0 = derived from the preset's physics")).value
                if cls.name == name and value > 0:
                    params[key] = float(value)
        return base.with_(controller=name, mode=mode, preset=preset,
                          enable_at_s=float(enable_at_s), params=params)

    def _react(self, m: SurfaceMeasurement | None) -> Command:
        if m is not None:
            now = time.monotonic()
            self.first_sample_s = self.first_sample_s or now
            self.last_sample_s = now
        return self.controller.update(m)

    def summary(self) -> dict[str, Any]:
        """Periods received and their wall time (first to last sample)."""
        wall = (self.last_sample_s or 0.0) - (self.first_sample_s or 0.0)
        return {"periods": self.received, "wall_s": wall,
                "periods_per_s": (self.received - 1) / wall if wall > 0 else math.nan,
                "clamped_commands": int(getattr(self.controller, "clamped_commands", 0))}



def params_from_text(text: str) -> dict[str, float]:
    """The ``params`` parameter's YAML mapping of names to numbers (checks.as_number: YAML
    1.1's ``2.0e1`` text too); one ParameterError line naming what is wrong."""
    try:
        data = load_yaml(text)
    except yaml.YAMLError as exc:
        raise ParameterError(f"params = {text!r} is not valid YAML: "
                             f"{' '.join(str(exc).split())}") from None
    if not isinstance(data, dict):
        raise ParameterError(f"params = {text!r} must be a YAML mapping of names to numbers, "
                             "e.g. '{gain: 2.0}'")
    out = {}
    for key, value in data.items():
        number = as_number(value)
        if number is None or not math.isfinite(number):
            raise ParameterError(f"params.{key} = {shown(value)} must be a finite number")
        out[str(key)] = number
    return out

def main(args: list[str] | None = None) -> int:
    """Console script ``top_drive_controller``; with ``periods`` > 0 it prints one JSON line
    (periods, wall_s, periods_per_s) when done and exits 0. A failure of the controller
    itself (an exception, a wrong type, a non-finite command: ``control.isolation``) is one
    stderr line starting with CONTROLLER_ERROR_PREFIX, exit 2; a user's mistake (a bad
    argument, parameter or scenario) is one line, exit 2."""
    try:
        check_parameter_rules(sys.argv if args is None else args)
        check_plain_args(sys.argv if args is None else args, CONTROLLER_USAGE)
    except ParameterError as exc:
        rclpy.logging.get_logger(NODE_NAME).fatal(str(exc))
        return 2
    rclpy.init(args=args)
    node = None
    try:
        node = ControllerNode()
        executor = SingleThreadedExecutor()
        executor.add_node(node)
        while rclpy.ok() and not node.done:
            executor.spin_once(timeout_sec=0.1)
        if node.done:
            print(json.dumps(node.summary()), flush=True)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    except ControllerError as exc:       # the controller under test failed: one line, exit 2
        print(f"{CONTROLLER_ERROR_PREFIX}{exc}", file=sys.stderr, flush=True)
        return 2
    except (DrillSimError, ValueError) as exc:      # a user's mistake: one line, exit 2
        rclpy.logging.get_logger(NODE_NAME).fatal(str(exc))
        return 2
    finally:
        if node is not None:
            node.destroy_node()
        rclpy.try_shutdown()
    return 0


if __name__ == "__main__":
    sys.exit(main())
