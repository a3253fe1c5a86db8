"""The closed-loop bench over DDS: sim_node and top_drive_controller as real processes.

:func:`run_over_dds` starts sim_node in command-triggered lockstep with in-process recording
(the settings of :func:`drill_sim_ros.control.bench.sim_node_parameters`, the same session as
the in-process bench) and the ``top_drive_controller`` node on the same scenario, both on
loopback DDS (``ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST``, the caller's ``ROS_DOMAIN_ID``);
the controller drives the pace for the scenario's periods and exits; then the sim is stopped
(SIGINT finishes the recording) and the telemetry is read back from the MCAP file.
"""

from __future__ import annotations

import json
import logging
import os
import random
import signal
import subprocess
import sys
import tempfile
from collections.abc import Callable
from pathlib import Path
from typing import TextIO

import numpy as np
from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory

from drill_sim_ros import topics
from drill_sim_ros.control.bench import ClosedLoopRun, sim_node_parameters
from drill_sim_ros.control.isolation import ControllerError
from drill_sim_ros.control.scenario import Scenario, save_scenario
from drill_sim_ros.model.errors import DrillSimError
from drill_sim_ros.model.presets import Preset
from drill_sim_ros.model.telemetry import N_FIELDS

_log = logging.getLogger(__name__)

STOP_TIMEOUT_S = 20.0


def ros_environment() -> dict[str, str]:
    """This environment with DDS on loopback and a domain (the caller's, else random)."""
    env = dict(os.environ)
    env["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
    env.pop("ROS_LOCALHOST_ONLY", None)
    env.setdefault("ROS_DOMAIN_ID", str(random.randint(1, 101)))
    prefixes = [p for p in env.get("AMENT_PREFIX_PATH", "").split(os.pathsep) if p]
    if sys.prefix not in prefixes:
        env["AMENT_PREFIX_PATH"] = os.pathsep.join([*prefixes, sys.prefix])
    return env


def _ros_args(values: dict[str, object]) -> list[str]:
    out = []
    for name, value in values.items():
        text = ("true" if value else "false") if isinstance(value, bool) else \
            repr(value) if isinstance(value, float) else \
            "'" + value.replace("'", "''") + "'" if isinstance(value, str) else str(value)
        # (a string is single-quoted YAML, so '[...]' stays a string, e.g. formation.layers)
        out += ["-p", f"{name}:={text}"]
    return out


def read_telemetry(path: Path) -> np.ndarray:
    """Every /drill/telemetry row of a recording, in order, shape (count, N_FIELDS)."""
    with open(path, "rb") as stream:
        reader = make_reader(stream, decoder_factories=[DecoderFactory()])
        rows = [list(msg.data) for *_, msg in reader.iter_decoded_messages(
            topics=[topics.TELEMETRY])]
    return np.array(rows, dtype=np.float64)


def _stop(process: subprocess.Popen, sig: int = signal.SIGINT) -> int:
    if process.poll() is None:
        process.send_signal(sig)
        try:
            return process.wait(timeout=STOP_TIMEOUT_S)
        except subprocess.TimeoutExpired:
            process.kill()
    return process.wait()


def _recorded_rows(path: Path) -> np.ndarray:
    """The telemetry recorded so far (an interrupted run), at least the t = 0 row slot."""
    try:
        rows = read_telemetry(path)
    except Exception:  # (an unfinished file: what it holds is a bonus, not a promise)
        rows = np.empty((0, N_FIELDS))
    return rows if len(rows) else np.zeros((1, N_FIELDS))


def _controller_error(stderr: str) -> str:
    """The controller node's one line about the controller under test (exit 2)."""
    from drill_sim_ros.ros.controller_node import CONTROLLER_ERROR_PREFIX
    lines = [line for line in stderr.splitlines() if line.startswith(CONTROLLER_ERROR_PREFIX)]
    return (lines[-1][len(CONTROLLER_ERROR_PREFIX):] + " (over DDS)") if lines else \
        f"over DDS: top_drive_controller exited 2: {stderr.strip()[-300:]}"


def _start_sim(scenario: Scenario, preset: Preset, record_path: Path, log_path: Path,
               env: dict[str, str]) -> tuple[subprocess.Popen, TextIO]:
    """sim_node in command-triggered lockstep, recording to ``record_path``, its output in
    ``log_path``; the process and the open log (the caller closes it)."""
    sim_values = {"lockstep": True, "lockstep_trigger": "command", "status_line": False,
                  "publish_clock": False, "record.path": str(record_path),
                  **sim_node_parameters(scenario, preset)}
    sim_log = open(log_path, "w")  # noqa: SIM115 (closed by the caller)
    sim = subprocess.Popen([sys.executable, "-m", "drill_sim_ros.ros.sim_node",
                            "--ros-args", *_ros_args(sim_values)], env=env,
                           stdout=sim_log, stderr=subprocess.STDOUT)
    return sim, sim_log


def _run_controller(scenario_path: Path, periods: int, env: dict[str, str],
                    timeout_s: float) -> subprocess.CompletedProcess[str]:
    """The top_drive_controller node for ``periods`` periods of the scenario file."""
    return subprocess.run(
        [sys.executable, "-m", "drill_sim_ros.ros.controller_node", "--ros-args",
         *_ros_args({"scenario": str(scenario_path), "periods": periods})],
        env=env, capture_output=True, text=True, timeout=timeout_s)


def _check_exits(controller: subprocess.CompletedProcess[str], sim_rc: int,
                 sim_log_path: Path) -> None:
    """Pass on the controller's warnings; ControllerError or DrillSimError if either failed."""
    for line in controller.stderr.splitlines():     # e.g. a slow controller
        if "warning: controller" in line:
            _log.warning("%s (over DDS)", line[line.index("warning: controller"):])
    if controller.returncode == 2:
        raise ControllerError(_controller_error(controller.stderr))
    if controller.returncode != 0 or sim_rc != 0:
        raise DrillSimError(
            f"over DDS: top_drive_controller exited {controller.returncode}, sim_node "
            f"{sim_rc}: {controller.stderr.strip()[-400:]} "
            f"{sim_log_path.read_text()[-400:]}")


def _run_processes(scenario: Scenario, preset: Preset, tmp: Path, env: dict[str, str],
                   timeout_s: float, record_path: Path) -> ClosedLoopRun:
    """sim_node (recording to ``record_path``) and the controller node on ``scenario``,
    their other files in ``tmp``; the recording's telemetry (``interrupted`` and the rows
    so far on Ctrl-C)."""
    scenario_path, log_path = tmp / "scenario.yaml", tmp / "sim_node.log"
    save_scenario(scenario, scenario_path)
    sim, sim_log = _start_sim(scenario, preset, record_path, log_path, env)
    try:
        controller = _run_controller(scenario_path, scenario.periods, env, timeout_s)
    except subprocess.TimeoutExpired as exc:
        _stop(sim)
        raise DrillSimError(f"the controller node did not finish {scenario.periods} periods "
                            f"in {timeout_s:g} s") from exc
    except KeyboardInterrupt:                # the children had SIGINT too: both stop
        _stop(sim)
        return ClosedLoopRun(scenario, _recorded_rows(record_path), 0.0, interrupted=True)
    finally:
        rc = _stop(sim)
        sim_log.close()
    _check_exits(controller, rc, log_path)
    summary = json.loads(controller.stdout.strip().splitlines()[-1])
    return ClosedLoopRun(scenario, read_telemetry(record_path), float(summary["wall_s"]),
                         int(summary["clamped_commands"]))


def run_over_dds(scenario: Scenario,
                 progress: Callable[[int, int], None] | None = None,
                 timeout_s: float | None = None,
                 record_path: Path | None = None) -> ClosedLoopRun:
    """Run ``scenario`` over DDS; the telemetry of the recording, t = 0 sample first.
    sim_node records to ``record_path`` (a file that must not exist yet; the caller keeps
    it), else to a temporary directory removed when the run is read."""
    scenario.check_supported()
    if scenario.overrides:
        raise DrillSimError("over DDS, a scenario's 'overrides' do not reach sim_node: put "
                            "them in a preset file and name it in 'preset'")
    preset = scenario.load_preset()
    schedule = scenario.setpoints(preset)
    if schedule.off_bottom_changes or schedule.off_bottom0:
        raise DrillSimError("over DDS, the schedule's off_bottom actions are the driller's: "
                            "run the scenario in process, or call sim_node's ~/off_bottom "
                            "service (std_srvs/SetBool) yourself")
    periods = scenario.periods
    timeout_s = timeout_s or 120.0 + periods / 50.0
    env = ros_environment()
    with tempfile.TemporaryDirectory(prefix="drill_closed_loop_") as tmp:
        run = _run_processes(scenario, preset, Path(tmp), env, timeout_s,
                             record_path or Path(tmp) / "run.mcap")
    if run.interrupted:
        return run
    if progress is not None:
        progress(periods, periods)
    if len(run.rows) != periods + 1:
        raise DrillSimError(f"over DDS: the recording holds {len(run.rows)} samples, expected "
                            f"{periods + 1}")
    return run
