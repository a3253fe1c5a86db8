"""Logs made by the simulator, for testing a fit against known parameters: a start-up run
by the drive's own speed loop (``drill_sim startup``), its surface signals measured by the
rig's sensors of a scenario (model/measurement.py: noise and quantisation; the delays left
out, the log's stamps being the sensors' own), at the run's 100 Hz."""

from __future__ import annotations

import numpy as np

from drill_sim_ros.control.scenario import load_scenario, scenario_path
from drill_sim_ros.fit.log import SurfaceLog
from drill_sim_ros.model.measurement import SIGNALS, RigSensors, SignalSpec
from drill_sim_ros.model.presets import Preset
from drill_sim_ros.model.startup import RPM_PER_RAD_S, StartupRun, run_startup

SENSOR_SCENARIO = "noisy_delayed_sensors"


def scenario_sensors(seed: int, scenario: str = SENSOR_SCENARIO) -> RigSensors:
    """The sensors of ``scenario`` without their delays, the noise seeded by ``seed``."""
    sensors = load_scenario(scenario_path(scenario)).sensors
    specs = {name: SignalSpec(noise_std=float(spec.get("noise_std", 0.0)),
                              quantum=float(spec.get("quantum", 0.0)))
             for name, spec in sensors.items() if name in SIGNALS}
    return RigSensors(specs, seed=seed)


def synthetic_log(preset: Preset, rpm: float, ramp_s: float, seconds: float,
                  sensors: RigSensors, rest_s: float = 1.0) -> SurfaceLog:
    """A start-up of ``preset`` at rest for ``rest_s`` then ramped to ``rpm`` in ``ramp_s``,
    ``seconds`` long in all, as ``sensors`` measure it (:func:`measured_log`)."""
    return measured_log(run_startup(preset, rpm, ramp_s, seconds - rest_s), sensors, rest_s,
                        f"synthetic start-up of {preset.name}")


def measured_log(run: StartupRun, sensors: RigSensors, rest_s: float, source: str
                 ) -> SurfaceLog:
    """The start-up ``run`` (from rest at t = 0) after ``rest_s`` at rest (the samples of
    t = 0 repeated: the string still, untwisted), its drive speed, motor, string torque
    measured by ``sensors``; the torque of the log is the string torque (a torque sub); the
    drive's setpoint as commanded (a command, not a measurement: no noise)."""
    dt = float(np.median(np.diff(run.t_s)))
    lead = max(1, round(rest_s / dt))
    t_s = np.concatenate((np.arange(lead) * dt, run.t_s + lead * dt))

    def rest_then(values: np.ndarray) -> np.ndarray:
        return np.concatenate((np.full(lead, values[0]), values))
    truth = np.column_stack((rest_then(run.drive_rpm / RPM_PER_RAD_S),
                             rest_then(run.motor_torque_nm),
                             rest_then(run.surface_torque_nm), np.zeros(t_s.size)))
    measured = sensors.measure(truth)
    return SurfaceLog(source=source, t_s=t_s, speed_rad_s=measured[:, 0],
                      torque_nm=measured[:, 2], torque_kind="string",
                      setpoint_rad_s=rest_then(run.setpoint_rpm / RPM_PER_RAD_S))


def write_csv(log: SurfaceLog, path: str) -> None:
    """``log`` as a CSV that ``drill_sim fit --log`` reads: time_s, surface_rpm and
    string_torque_knm (or motor_torque_knm), and setpoint_rpm where the log has it."""
    columns = {"time_s": log.t_s, "surface_rpm": log.speed_rad_s * RPM_PER_RAD_S,
               f"{log.torque_kind}_torque_knm": log.torque_nm / 1e3}
    if log.setpoint_rad_s is not None:
        columns["setpoint_rpm"] = log.setpoint_rad_s * RPM_PER_RAD_S
    np.savetxt(path, np.column_stack(list(columns.values())), delimiter=",",
               header=",".join(columns), comments="", fmt="%.6g")
