"""package.xml and setup.py against the code: declared is what is imported, installed is what
the nodes read (issue 26). What colcon then builds from them: tests/ros/test_colcon.py."""

from __future__ import annotations

import ast
import re
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
PACKAGE = "drill_sim_ros"
# import name -> rosdep key, for the Python libraries rosdep knows
ROSDEP_KEYS = {"numpy": "python3-numpy", "yaml": "python3-yaml",
               "matplotlib": "python3-matplotlib"}
# ROS packages that the wheels or a Jazzy install provide under their own name
ROS_PACKAGES = {"rclpy", "rcl_interfaces", "builtin_interfaces", "std_msgs", "sensor_msgs",
                "diagnostic_msgs", "std_srvs", "rosgraph_msgs", "geometry_msgs",
                "ament_index_python", "launch", "launch_ros", "drill_sim_msgs"}


def imported_modules(paths: list[Path]) -> set[str]:
    """The top-level modules that ``paths`` import (absolute imports, anywhere in a file)."""
    found: set[str] = set()
    for path in paths:
        for node in ast.walk(ast.parse(path.read_text(), str(path))):
            if isinstance(node, ast.Import):
                found |= {alias.name.split(".")[0] for alias in node.names}
            elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
                found.add(node.module.split(".")[0])
    return found - set(sys.stdlib_module_names) - {PACKAGE}


def _manifest() -> ET.Element:
    return ET.parse(REPO / "package.xml").getroot()


def _depends(kind: str) -> set[str]:
    return {element.text.strip() for element in _manifest().iter(kind)}


def _code_files() -> list[Path]:
    return [*sorted((REPO / PACKAGE).rglob("*.py")), *sorted((REPO / "launch").glob("*.py"))]


def test_package_xml_declares_exactly_what_the_code_imports() -> None:
    imported = imported_modules(_code_files())
    ros = imported & ROS_PACKAGES
    keys = {ROSDEP_KEYS[name] for name in imported if name in ROSDEP_KEYS}
    assert _depends("exec_depend") | _depends("depend") == ros | keys


def test_every_pip_only_import_is_named_in_the_manifest() -> None:
    imported = imported_modules(_code_files()) - ROS_PACKAGES - set(ROSDEP_KEYS)
    comments = " ".join(re.findall(r"<!--(.*?)-->", (REPO / "package.xml").read_text(),
                                   re.DOTALL))
    named = set(re.findall(r"[A-Za-z_][\w-]*", comments))
    assert imported <= named, f"imported but not named as pip-installed: {imported - named}"


def test_the_pytest_options_have_their_test_dependencies() -> None:
    options = re.search(r"^addopts = (.*)$", (REPO / "pyproject.toml").read_text(),
                        re.MULTILINE).group(1)
    tests = _depends("test_depend")
    assert "python3-pytest" in tests
    if "--timeout" in options:
        assert "python3-pytest-timeout" in tests


def _installed_files() -> dict[str, list[str]]:
    """setup.py's data_files, evaluated with its own globs: {destination: [source, ...]}."""
    tree = ast.parse((REPO / "setup.py").read_text())
    call = next(node for node in ast.walk(tree) if isinstance(node, ast.Call)
                and getattr(node.func, "id", "") == "setup")
    data_files = next(k.value for k in call.keywords if k.arg == "data_files")
    from glob import glob
    scope = {"glob": lambda pattern: glob(str(REPO / pattern)), "PACKAGE": PACKAGE}
    entries = eval(compile(ast.Expression(data_files), "setup.py", "eval"), scope)
    return {dest: [str(Path(src).resolve().relative_to(REPO)) if Path(src).is_absolute()
                   else src for src in sources] for dest, sources in entries}


def test_every_config_and_launch_file_is_installed() -> None:
    installed = {src for sources in _installed_files().values() for src in sources}
    wanted = [p.relative_to(REPO) for p in (*(REPO / "config").rglob("*.yaml"),
                                            *(REPO / "config").glob("*.xml"),
                                            *(REPO / "launch").glob("*.launch.py"))]
    assert {"config/fastdds_localhost.xml", "config/sim.yaml",
            "launch/drill_sim.launch.py"} <= {str(p) for p in wanted}
    assert {str(p) for p in wanted} <= installed
