"""The controller API of docs/closed-loop.md: its worked example (examples/soft_speed_pi.py, a
textbook SoftSpeed PI) imports only the documented names, sets kp and ki of its loop as the
page says, and runs through `drill_sim closed-loop` in process and over `--ros` with the same
telemetry bit for bit."""

from __future__ import annotations

import ast
import importlib.util
import json
import math
import subprocess
import sys
from pathlib import Path
from types import ModuleType

import pytest

from drill_sim_ros.control.bench import run_in_process
from drill_sim_ros.control.command import SurfaceMeasurement
from drill_sim_ros.control.registry import make_controller
from drill_sim_ros.control.rig import rig_physics
from drill_sim_ros.control.scenario import Scenario
from drill_sim_ros.model.errors import ParameterError
from drill_sim_ros.model.params import RPM_PER_RAD_S

ROOT = Path(__file__).resolve().parents[2]
EXAMPLE = "examples/soft_speed_pi.py"
CLASS = f"{EXAMPLE}:SoftSpeedPI"
# the standard library's modules the example may use besides the documented API
STANDARD = {"__future__", "typing", "math", "dataclasses"}


def _generator() -> ModuleType:
    spec = importlib.util.spec_from_file_location("docs_generate", ROOT / "docs" / "generate.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_the_example_imports_only_the_documented_api() -> None:
    generate = _generator()
    assert generate.CONTROLLER_EXAMPLE == EXAMPLE
    documented = {(module, name) for module, names in generate.CONTROLLER_API
                  for name in names}
    tree = ast.parse((ROOT / EXAMPLE).read_text(encoding="utf-8"))
    imported = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            imported += [(alias.name, None) for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            imported += [(node.module, alias.name) for alias in node.names]
    project = [(module, name) for module, name in imported if module not in STANDARD]
    assert project and set(project) <= documented, set(project) - documented


def _example(rig_preset: str = "field_8p5in_shale", mode: str = "torque", **params: float):
    scenario = Scenario(preset=rig_preset, controller=CLASS, mode=mode, enable_at_s=10.0)
    preset = scenario.load_preset()
    rig = rig_physics(preset)
    controller = make_controller(str(ROOT / EXAMPLE) + ":SoftSpeedPI", rig=rig,
                                 schedule=scenario.setpoints(preset), mode=mode,
                                 period_s=scenario.period_s, enable_at_s=10.0, **params)
    return controller, rig, scenario.setpoints(preset)


@pytest.mark.parametrize("params", [{}, {"kp_nm_s": 600.0, "ki_nm": 3000.0}])
def test_the_first_torque_command_is_the_pi_law_with_the_documented_gains(
        params: dict[str, float]) -> None:
    """Switched on, from a sample where the drive lags the setpoint by 0.1 rad/s: the loop
    starts from the measured motor torque T0 and sends T0 + (kp + ki P) e, with kp = Z and
    ki = J omega_1^2 read from the rig (or the parameters given); before the switch-on the
    drive's delivered loop, kp = 2 J w_c, ki = J w_c^2 with w_c = 3 omega_1."""
    controller, rig, schedule = _example(**params)
    omega_1 = math.sqrt(rig.stiffness_nm_rad / rig.bit_inertia_kg_m2)
    kp = params.get("kp_nm_s", rig.impedance_nm_s)
    ki = params.get("ki_nm", rig.drive_inertia_kg_m2 * omega_1**2)
    p, t0_nm = controller.period_s, 4000.0
    for time_s, (gain_p, gain_i) in (
            (20.0, (kp, ki)),
            (5.0, (2.0 * rig.drive_inertia_kg_m2 * 3.0 * omega_1,
                   rig.drive_inertia_kg_m2 * (3.0 * omega_1) ** 2))):
        controller.reset()
        setpoint_rad_s = schedule.rpm_at(time_s) / RPM_PER_RAD_S
        m = SurfaceMeasurement(time_s, setpoint_rad_s - 0.1, t0_nm, 3900.0)
        command = controller.update(m)
        assert command.speed_rad_s is None
        assert command.motor_torque_nm == pytest.approx(t0_nm + (gain_p + gain_i * p) * 0.1,
                                                        rel=1e-12)


def test_the_example_refuses_speed_mode() -> None:
    with pytest.raises(ParameterError, match="--mode torque"):
        _example(mode="speed")


def drill_sim(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "drill_sim_ros.cli", "closed-loop", *args],
                          capture_output=True, text=True, timeout=600, cwd=ROOT)


SHORT = ("--controller", CLASS, "--mode", "torque", "--params", "field_8p5in_shale_lumped",
         "--t-end", "20", "--enable-at", "5", "--no-baseline", "--json")


@pytest.fixture(scope="module")
def short_run() -> subprocess.CompletedProcess[str]:
    """``drill_sim closed-loop`` of SHORT in process: run once, compared by two tests."""
    return drill_sim(*SHORT)


def test_the_example_runs_from_the_command_line_as_the_bench_runs_it(
        short_run: subprocess.CompletedProcess[str]) -> None:
    """`drill_sim closed-loop --controller examples/soft_speed_pi.py:SoftSpeedPI` scores the
    bench's own run of the same scenario."""
    from drill_sim_ros.control.scorecard import score

    result = short_run
    assert result.returncode == 0, result.stderr
    out = json.loads(result.stdout)
    scenario = Scenario(preset="field_8p5in_shale_lumped", controller=CLASS, mode="torque",
                        duration_s=20.0, enable_at_s=5.0)
    preset = scenario.load_preset()
    rows = run_in_process(scenario).rows
    card = score(rows, 5.0, scenario.setpoints(preset), rig_physics(preset), scenario.period_s)
    assert out["score"] == json.loads(json.dumps(card))


@pytest.mark.ros
def test_in_process_and_over_ros_give_the_same_telemetry(
        short_run: subprocess.CompletedProcess[str]) -> None:
    """The example over DDS (sim_node and top_drive_controller as processes) and in
    process, on noisy, delayed sensors and a setpoint ramp: the same telemetry bit for bit,
    and the command line's --ros scorecard is its in-process one."""
    from drill_sim_ros.ros.closed_loop import run_over_dds

    scenario = Scenario(
        preset="field_8p5in_shale_lumped", controller=str(ROOT / EXAMPLE) + ":SoftSpeedPI",
        mode="torque", duration_s=20.0, enable_at_s=5.0,
        sensors={"seed": 3, "string_torque_nm": {"noise_std": 25.0, "quantum": 1.0},
                 "drive_speed_rad_s": {"noise_std": 1e-3, "delay_periods": 2}},
        schedule=({"t_s": 12.0, "rpm": 70.0, "ramp_s": 4.0},))
    local = run_in_process(scenario).rows
    remote = run_over_dds(scenario, timeout_s=300.0).rows
    assert local.shape == remote.shape == (2001, local.shape[1])
    assert local.tobytes() == remote.tobytes()
    in_process, over_ros = short_run, drill_sim(*SHORT, "--ros")
    assert in_process.returncode == over_ros.returncode == 0, over_ros.stderr
    assert json.loads(over_ros.stdout)["score"] == json.loads(in_process.stdout)["score"]
