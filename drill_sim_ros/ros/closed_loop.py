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

import numpy as np
from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory

from drill_sim_ros import topics
from drill_sim_ros.control.bench import ClosedLoopRun, sim_node_parameters
from drill_sim_ros.control.isolation import ControllerError
from drill_sim_ros.control.scenario import Scenario, save_scenario
from drill_sim_ros.model.errors import DrillSimError
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


def run_over_dds(scenario: Scenario,
                 progress: Callable[[int, int], None] | None = None,
                 timeout_s: float | None = None) -> ClosedLoopRun:
    """Run ``scenario`` over DDS; the telemetry of the recording, t = 0 sample first."""
    scenario.check_supported()
    if scenario.overrides:
        raise DrillSimError("over DDS, a scenario's 'overrides' do not reach sim_node: put "
                            "them in a preset file and name it in 'preset'")
    preset = scenario.load_preset()
    periods = scenario.periods
    timeout_s = timeout_s or 120.0 + periods / 50.0
    env = ros_environment()
    with tempfile.TemporaryDirectory(prefix="drill_closed_loop_") as tmp:
        scenario_path, record_path = Path(tmp) / "scenario.yaml", Path(tmp) / "run.mcap"
        save_scenario(scenario, scenario_path)
        sim_values = {"lockstep": True, "lockstep_trigger": "command", "status_line": False,
                      "publish_clock": False, "record.path": str(record_path),
                      **sim_node_parameters(scenario, preset)}
        sim_log = open(Path(tmp) / "sim_node.log", "w")  # noqa: SIM115 (closed below)
        sim = subprocess.Popen([sys.executable, "-m", "drill_sim_ros.ros.sim_node",
                                "--ros-args", *_ros_args(sim_values)], env=env,
                               stdout=sim_log, stderr=subprocess.STDOUT)
        try:
            controller = subprocess.run(
                [sys.executable, "-m", "drill_sim_ros.ros.controller_node", "--ros-args",
                 *_ros_args({"scenario": str(scenario_path), "periods": periods})],
                env=env, capture_output=True, text=True, timeout=timeout_s)
        except subprocess.TimeoutExpired as exc:
            _stop(sim)
            raise DrillSimError(f"the controller node did not finish {periods} periods in "
                                f"{timeout_s:g} s") from exc
        except KeyboardInterrupt:                # the children had SIGINT too: both stop
            _stop(sim)
            return ClosedLoopRun(scenario, _recorded_rows(record_path), 0.0,
                                 interrupted=True)
        finally:
            rc = _stop(sim)
            sim_log.close()
        for line in controller.stderr.splitlines():     # e.g. a slow controller
            if "warning: controller" in line:
                _log.warning("%s (over DDS)", line[line.index("warning: controller"):])
        if controller.returncode == 2:
            raise ControllerError(_controller_error(controller.stderr))
        if controller.returncode != 0 or rc != 0:
            raise DrillSimError(
                f"over DDS: top_drive_controller exited {controller.returncode}, sim_node "
                f"{rc}: {controller.stderr.strip()[-400:]} "
                f"{(Path(tmp) / 'sim_node.log').read_text()[-400:]}")
        summary = json.loads(controller.stdout.strip().splitlines()[-1])
        rows = read_telemetry(record_path)
    if progress is not None:
        progress(periods, periods)
    if len(rows) != periods + 1:
        raise DrillSimError(f"over DDS: the recording holds {len(rows)} samples, expected "
                            f"{periods + 1}")
    return ClosedLoopRun(scenario, rows, float(summary["wall_s"]),
                         int(summary["clamped_commands"]))
