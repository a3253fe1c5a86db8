"""launch/drill_sim.launch.py (issue 26). This machine has no launch_ros: the file is read
with ast and every executable, parameter, argument and file it names is checked against
the package; the real launch runs where launch_ros is importable (a ROS 2 Jazzy install)."""

from __future__ import annotations

import ast
import os
import signal
import subprocess
import sys
from pathlib import Path

import pytest
from rclpy.node import Node
from std_msgs.msg import Float64MultiArray

from drill_sim_ros import topics
from drill_sim_ros.archive import recorder_node
from drill_sim_ros.ros.parameters import SPEC_BY_NAME
from drill_sim_ros.viz import bridge_node

REPO = Path(__file__).resolve().parents[2]
LAUNCH_FILE = REPO / "launch" / "drill_sim.launch.py"
PACKAGE = "drill_sim_ros"
ROS_PARAMETERS = {"use_sim_time"}         # what every rclpy node declares itself


def _tree(path: Path) -> ast.Module:
    return ast.parse(path.read_text(), str(path))


def _calls(tree: ast.AST, name: str) -> list[ast.Call]:
    return [node for node in ast.walk(tree) if isinstance(node, ast.Call)
            and getattr(node.func, "id", getattr(node.func, "attr", None)) == name]


def _keyword(call: ast.Call, name: str) -> ast.expr | None:
    return next((k.value for k in call.keywords if k.arg == name), None)


def _literal_strings(node: ast.AST) -> list[str]:
    return [n.value for n in ast.walk(node) if isinstance(n, ast.Constant)
            and isinstance(n.value, str)]


def _launch_nodes() -> dict[str, ast.Call]:
    """executable -> its launch_ros Node(...) call."""
    return {_keyword(call, "executable").value: call for call in _calls(_tree(LAUNCH_FILE),
                                                                         "Node")}


def _console_scripts() -> set[str]:
    scripts = next(k.value for call in _calls(_tree(REPO / "setup.py"), "setup")
                   for k in call.keywords if k.arg == "entry_points")
    return {entry.split("=")[0].strip() for entry in _literal_strings(scripts) if "=" in entry}


def _command_line(call: ast.Call, value: str) -> list[str]:
    """The node's ``arguments``, each launch substitution standing as ``value``."""
    return [e.value if isinstance(e, ast.Constant) else value
            for e in _keyword(call, "arguments").elts]


def _parameter_names(call: ast.Call) -> set[str]:
    parameters = _keyword(call, "parameters")
    return {key.value for node in ast.walk(parameters) if isinstance(node, ast.Dict)
            for key in node.keys if isinstance(key, ast.Constant)}


def _declared_parameters(path: Path) -> set[str]:
    """The literal names a node module passes to declare_parameter."""
    return {call.args[0].value for call in _calls(_tree(path), "declare_parameter")
            if call.args and isinstance(call.args[0], ast.Constant)}


def _arguments() -> dict[str, object]:
    namespace: dict[str, object] = {}
    tree = _tree(LAUNCH_FILE)
    assignment = next(node for node in tree.body if isinstance(node, ast.Assign)
                      and getattr(node.targets[0], "id", "") == "ARGUMENTS")
    exec(compile(ast.Module([assignment], []), str(LAUNCH_FILE), "exec"), namespace)
    return namespace["ARGUMENTS"]


def test_every_executable_it_starts_is_a_console_script_of_this_package() -> None:
    nodes = _launch_nodes()
    assert set(nodes) == {"sim_node", "mcap_recorder", "rerun_bridge", "top_drive_controller"}
    assert set(nodes) <= _console_scripts()
    for call in nodes.values():
        assert isinstance(_keyword(call, "package"), ast.Name)     # PACKAGE
    assert f'PACKAGE = "{PACKAGE}"' in LAUNCH_FILE.read_text()
    assert _keyword(nodes["sim_node"], "name").value == topics.NODE_NAME


def test_every_parameter_it_sets_is_declared_by_that_node() -> None:
    nodes = _launch_nodes()
    assert _parameter_names(nodes["sim_node"]) <= set(SPEC_BY_NAME) | ROS_PARAMETERS
    controller = _declared_parameters(REPO / PACKAGE / "ros" / "controller_node.py")
    assert _parameter_names(nodes["top_drive_controller"]) <= controller | ROS_PARAMETERS
    for executable in ("mcap_recorder", "rerun_bridge"):
        assert _parameter_names(nodes[executable]) == ROS_PARAMETERS


def test_every_command_line_it_builds_parses() -> None:
    nodes = _launch_nodes()
    recorder = _command_line(nodes["mcap_recorder"], "x.mcap")
    assert recorder_node._parse(recorder).output == "x.mcap"
    bridge = _command_line(nodes["rerun_bridge"], "x.rrd")
    assert bridge_node.parse_args(bridge).save == "x.rrd"


def test_its_arguments_are_declared_and_used_and_its_files_exist() -> None:
    tree = _tree(LAUNCH_FILE)
    used = {call.args[0].value for call in _calls(tree, "_arg")}
    arguments = _arguments()
    assert used == set(arguments)
    assert {"namespace", "use_sim_time", "preset", "record", "bridge", "controller"} <= used
    assert arguments["use_sim_time"][0] == "false" and arguments["controller"][0] == ""
    for call in _calls(tree, "PathJoinSubstitution"):
        parts = _literal_strings(call)
        assert (REPO.joinpath(*parts)).is_file(), parts          # config/sim.yaml
    preset = arguments["preset"][0]
    assert (REPO / "config" / "presets" / f"{preset}.yaml").is_file()
    assert any(isinstance(node, ast.FunctionDef) and node.name == "generate_launch_description"
               for node in tree.body)


LAUNCH_SCRIPT = """
import sys
from launch import LaunchService
from launch.actions import IncludeLaunchDescription
from launch.launch_description_sources import PythonLaunchDescriptionSource
service = LaunchService()
arguments = [tuple(a.split(":=", 1)) for a in sys.argv[2:]]
service.include_launch_description(IncludeLaunchDescription(
    PythonLaunchDescriptionSource(sys.argv[1]), launch_arguments=arguments))
sys.exit(service.run())
"""


@pytest.mark.ros
def test_the_launch_file_runs_a_namespaced_rig(tmp_path) -> None:
    """Where launch_ros is installed: the installed launch file starts the sim under its
    namespace, with the installed params file, and stops cleanly on SIGINT."""
    pytest.importorskip("launch_ros")
    from tests.ros.harness import ros_context
    from tests.ros.test_colcon import colcon_build, installed_env

    prefix = colcon_build(tmp_path)
    env = installed_env(prefix)
    env["PATH"] = f"{Path(sys.executable).parent}{os.pathsep}{env.get('PATH', '')}"
    launch_file = prefix / "share" / PACKAGE / "launch" / "drill_sim.launch.py"
    command = [sys.executable, "-c", LAUNCH_SCRIPT, str(launch_file), "namespace:=rig_launch",
               "real_time_factor:=5.0"]
    name = "/rig_launch" + topics.TELEMETRY
    received: list[Float64MultiArray] = []
    with ros_context() as ros:
        listener = ros.add(Node("launch_listener", context=ros.context))
        listener.create_subscription(Float64MultiArray, name, received.append, 1000)
        process = subprocess.Popen(command, env=env, cwd=tmp_path, stdout=subprocess.PIPE,
                                   stderr=subprocess.STDOUT, text=True)
        try:
            published = ros.spin_until(lambda: len(received) >= 20, 90.0)
            process.send_signal(signal.SIGINT)
            out, _ = process.communicate(timeout=30)
        finally:
            if process.poll() is None:
                process.kill()
                process.communicate()
    assert published, out
    assert process.returncode == 0, out
