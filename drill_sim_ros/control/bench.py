"""The closed-loop bench in process: a controller and the session, period by period.

ROS-free. :func:`run_in_process` steps :class:`~drill_sim_ros.model.session.SimSession`
exactly as sim_node does in command-triggered lockstep (``lockstep:=true -p
lockstep_trigger:=command``), so both give the same telemetry bit for bit:

1. the session is built from the same settings sim_node takes from its parameters
   (:func:`session_config`, :func:`sim_node_parameters`), and its t = 0 sample is taken
   (sim_node publishes it at start; the sensors' noise and delay lines see it);
2. the controller's first command answers the t = 0 sample (stamp 0), which sim_node
   publishes, latched, before it waits for its first command;
3. each command is applied with sim_node's limits (``control.command.apply_command``: speed and WOB
   within [0, limit]; the drive applies a motor torque within its own limit) and stamped with
   the sample it reacts to; then exactly one period runs under it (zero-order hold), and the
   sample at the END of that period is what the controller reacts to next.
"""

from __future__ import annotations

import json
import time
from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from drill_sim_ros.control import scorecard
from drill_sim_ros.control.command import (
    Command,
    CommandLimits,
    SurfaceMeasurement,
    apply_command,
    measurement_of_row,
)
from drill_sim_ros.control.isolation import IsolatedController, build_isolated
from drill_sim_ros.control.registry import make_controller
from drill_sim_ros.control.rig import RigPhysics, rig_physics
from drill_sim_ros.control.scenario import Scenario
from drill_sim_ros.model import defaults
from drill_sim_ros.model.errors import ParameterError
from drill_sim_ros.model.measurement import SIGNALS
from drill_sim_ros.model.presets import Preset, submerged_string_weight_n
from drill_sim_ros.model.session import SessionConfig, SimSession
from drill_sim_ros.model.telemetry import N_FIELDS
from drill_sim_ros.model.top_drive import TopDrivePhysical


def command_limits(preset: Preset, rig: RigPhysics) -> CommandLimits:
    """sim_node's command limits at their defaults (limits.*)."""
    wob_n = preset.scales.wob_n(preset.params.w0)
    return CommandLimits(rig.max_surface_rpm, defaults.max_wob_n(wob_n))


@dataclass
class ClosedLoopRun:
    """Telemetry rows (periods + 1, N_FIELDS), the first the t = 0 sample; wall time."""

    scenario: Scenario
    rows: np.ndarray
    wall_s: float
    clamped_commands: int = 0
    # the kernel's running statistics (``kernel.A_*``) at the end, and after period
    # ``snapshot_after`` when asked (differences of the sums are window sums)
    accumulators: np.ndarray | None = None
    snapshot: np.ndarray | None = None
    interrupted: bool = False     # Ctrl-C: ``rows`` holds the periods done

    def score(self, from_s: float | None = None) -> dict[str, Any]:
        """The scorecard of these rows (:func:`scorecard.score`) on the run's own scenario:
        its preset's rig and setpoints, scored after ``from_s`` (default: the switch-on)."""
        preset = self.scenario.load_preset()
        start_s = self.scenario.enable_at_s if from_s is None else from_s
        return scorecard.score(self.rows, start_s, self.scenario.setpoints(preset),
                               rig_physics(preset), self.scenario.period_s)


def scenario_drive(scenario: Scenario, preset: Preset) -> TopDrivePhysical:
    """The drive sim_node runs for ``scenario`` (SI): ``preset``'s, which
    :meth:`Scenario.load_preset` gave the scenario's torque limit, motor lag and torque rate
    limit, in the scenario's mode."""
    return replace(preset.drive, mode=scenario.mode)


def session_config(scenario: Scenario, preset: Preset) -> SessionConfig:
    """The session sim_node builds from :func:`sim_node_parameters` of ``scenario``."""
    schedule = scenario.setpoints(preset)
    return SessionConfig(
        preset=preset, publish_rate_hz=scenario.control_rate_hz, dtau_max=preset.dtau,
        n_nodes=defaults.n_nodes(preset), perturb_v=defaults.PERTURB_V,
        applied_wob_n=schedule.wob_at(0.0), surface_rpm=schedule.rpm_at(0.0),
        window_s=defaults.WINDOW_S, submerged_weight_n=submerged_string_weight_n(preset),
        top_drive=scenario_drive(scenario, preset),
        sensors=scenario.rig_sensors(), formation=tuple(scenario.formation),
        top_drive_accel_rpm_s=float(scenario.drive.get("accel_rpm_s", 0.0)),
        wob_rate_n_s=float(scenario.drive.get("wob_rate_n_s", 0.0)),
        command_delay_s=float(scenario.drive.get("command_delay_s", 0.0)))


def sim_node_parameters(scenario: Scenario, preset: Preset) -> dict[str, object]:
    """sim_node's parameters for the same session as :func:`session_config` (the rest at
    their defaults, which :func:`session_config` mirrors)."""
    schedule = scenario.setpoints(preset)
    out: dict[str, object] = {
        "model.preset": scenario.preset, "publish_rate_hz": float(scenario.control_rate_hz),
        "model.applied_wob_n": schedule.wob_at(0.0), "model.surface_rpm": schedule.rpm_at(0.0),
        "top_drive.mode": scenario.mode, "sensors.seed": int(scenario.sensors.get("seed", 0))}
    for signal in SIGNALS:
        for key, value in (scenario.sensors.get(signal) or {}).items():
            out[f"sensors.{signal}.{key}"] = value
    for key, name in SCENARIO_DRIVE_PARAMETERS.items():
        if key in scenario.drive:
            out[name] = float(scenario.drive[key])
    if scenario.formation:
        out["formation.layers"] = json.dumps([dict(x) for x in scenario.formation])
    return out


# a scenario's drive keys (the drive and the command path) -> sim_node's parameters
SCENARIO_DRIVE_PARAMETERS = {"accel_rpm_s": "limits.top_drive_accel_rpm_s",
                             "wob_rate_n_s": "limits.wob_rate_n_s",
                             "max_torque_nm": "top_drive.max_torque_nm",
                             "command_delay_s": "commands.delay_s",
                             "motor_lag_s": "top_drive.motor_lag_s",
                             "max_torque_rate_nm_s": "top_drive.max_torque_rate_nm_s"}


def build_controller(scenario: Scenario, preset: Preset) -> IsolatedController:
    """The scenario's controller, tuned from the preset's physics, isolated
    (:mod:`~drill_sim_ros.control.isolation`: its failures are one ControllerError line)."""
    return build_isolated(scenario.controller, lambda: make_controller(
        scenario.controller, rig=rig_physics(preset), schedule=scenario.setpoints(preset),
        mode=scenario.mode, period_s=scenario.period_s, enable_at_s=scenario.enable_at_s,
        **scenario.params), scenario.period_s)


class Bench:
    """The closed loop one control period at a time (module doc): :meth:`step` applies a
    command with sim_node's limits, stamps it with the sample it reacts to and runs one
    period. ``rows`` (periods + 1, N_FIELDS) fills as it goes, the t = 0 sample first; the
    sample at the end of the last period is ``rows[period]``. One implementation behind
    :func:`run_in_process` and the Gymnasium environment."""

    def __init__(self, scenario: Scenario, preset: Preset | None = None) -> None:
        scenario.check_supported()
        self.scenario = scenario
        self.preset = scenario.load_preset() if preset is None else preset
        self.rig = rig_physics(self.preset)
        self.schedule = scenario.setpoints(self.preset)
        if (self.schedule.off_bottom_changes or self.schedule.off_bottom0) and \
                not self.preset.string.distributed:
            raise ParameterError(f"scenario: off_bottom in the schedule needs a distributed "
                                 f"string (a hook); preset '{self.preset.name}' is lumped")
        self.limits = command_limits(self.preset, self.rig)
        self.session = SimSession(session_config(scenario, self.preset))
        self._off_bottom = self.schedule.off_bottom0   # the driller's last action
        if self._off_bottom:         # a start-up: picked up, at rest and untwisted
            self.session.start_at_rest()
        self.periods = scenario.periods
        self.rows = np.empty((self.periods + 1, N_FIELDS))
        self.rows[0] = self.session.current().rows[0]
        self.period = 0
        self.stamp_ns = 0            # stamp of the newest sample (what a command reacts to)

    @property
    def done(self) -> bool:
        return self.period >= self.periods

    @property
    def row(self) -> np.ndarray:
        """The newest sample (SI, TELEMETRY_FIELDS)."""
        return self.rows[self.period]

    def measurement(self) -> SurfaceMeasurement:
        """What the rig's surface sensors give in the newest sample."""
        return measurement_of_row(self.rows[self.period], self.stamp_ns)

    def step(self, command: Command) -> np.ndarray:
        """Apply ``command`` (ParameterError if not finite) and run one period under it;
        the sample at its end. Raises ``NumericalFault``."""
        if self.done:
            raise ParameterError(f"the scenario's {self.periods} periods are done")
        for applied, why in apply_command(self.session, command, self.limits):
            if not applied:
                raise ParameterError(f"the controller commanded {why}; commands must be finite")
        self._driller()
        self.session.command_stamp_ns = self.stamp_ns
        block = self.session.run(1)
        self.period += 1
        self.rows[self.period] = block.rows[0]
        self.stamp_ns = int(block.stamps_ns[0])
        return self.rows[self.period]


    def _driller(self) -> None:
        """The driller's own action of the schedule: the bit picked up off bottom or tagged
        again from this period on (not the controller's to command)."""
        off = self.schedule.off_bottom_at(self.period * self.scenario.period_s)
        if off != self._off_bottom:
            self.session.set_off_bottom(off)
            self._off_bottom = off


def run_in_process(scenario: Scenario,
                   progress: Callable[[int, int], None] | None = None,
                   snapshot_after: int | None = None) -> ClosedLoopRun:
    """Run ``scenario``: its telemetry, the t = 0 sample first (see the module doc); the
    kernel's accumulators at the end and, if ``snapshot_after`` is given, after that many
    periods (0: before the first)."""
    bench = Bench(scenario)
    controller = build_controller(scenario, bench.preset)
    sim = bench.session.sim
    start = time.perf_counter()
    command = controller.update(bench.measurement())   # the answer to t = 0
    snapshot = sim.accumulators if snapshot_after == 0 else None
    interrupted = False
    try:
        for i in range(bench.periods):
            bench.step(command)
            if snapshot_after == i + 1:
                snapshot = sim.accumulators
            if not bench.done:
                command = controller.update(bench.measurement())
            if progress is not None and (i + 1) % 1000 == 0:
                progress(i + 1, bench.periods)
    except KeyboardInterrupt:
        interrupted = True
    wall_s = time.perf_counter() - start
    return ClosedLoopRun(scenario, bench.rows[:bench.period + 1], wall_s,
                         int(getattr(controller, "clamped_commands", 0)), sim.accumulators,
                         snapshot, interrupted)
