"""The content of a ``--params-file`` for sim_node: every parameter it sets must exist.

rcl applies a params file silently: a section for another node name, a misspelt parameter
or a value where a group belongs (``model: 5``) are ignored and the node runs on defaults.
:func:`check_params_content` refuses them with one ParameterError line naming the file,
the key and the closest known parameter. Sections for other nodes are allowed (one file
may configure a whole launch) as long as one section applies to this node.
"""

from __future__ import annotations

import difflib
from typing import Any

from drill_sim_ros.model.errors import ParameterError

ROS_PARAMETERS = "ros__parameters"
# parameters every rclpy node has, and prefixes rclpy reads
BUILTIN_PARAMETERS = ("use_sim_time", "start_type_description_service")
BUILTIN_PREFIXES = ("qos_overrides.",)


def applies_to(section: str, node_name: str) -> bool:
    """A section key names ``node_name``: ``node``, ``/node``, ``/ns/node`` or wildcards."""
    key = str(section)
    return "*" in key or key.lstrip("/").split("/")[-1] == node_name


def flatten(values: dict[Any, Any], prefix: str = "") -> dict[str, Any]:
    """Nested mappings as dotted names (``model: {preset: x}`` -> ``model.preset``)."""
    out: dict[str, Any] = {}
    for key, value in values.items():
        name = f"{prefix}{key}"
        if isinstance(value, dict):
            out.update(flatten(value, f"{name}."))
        else:
            out[name] = value
    return out


def _unknown(path: str, name: str, known: set[str], node_name: str) -> ParameterError:
    groups = {k.rsplit(".", 1)[0] for k in known if "." in k}
    close = difflib.get_close_matches(name, sorted(known), n=1, cutoff=0.6)
    hint = f"; '{name}' is a group: give its parameters ({name}: {{NAME: value}})" \
        if name in groups else (f"; did you mean {close[0]}?" if close else "")
    return ParameterError(f"--params-file {path}: {node_name} has no parameter '{name}'"
                          f"{hint} (ros2 param list /{node_name} lists them)")


def check_params_content(path: str, data: Any, node_name: str, known: set[str]) -> None:
    """``data`` (the parsed file) sets only ``known`` parameters of ``node_name``."""
    if not isinstance(data, dict) or not data:
        raise ParameterError(f"--params-file {path}: expected '{node_name}: "
                             f"{{{ROS_PARAMETERS}: {{NAME: value}}}}', got {data!r:.60}")
    sections = [key for key in data if applies_to(key, node_name)]
    if not sections:
        raise ParameterError(f"--params-file {path} has no section for node {node_name} "
                             f"(found: {', '.join(map(str, data))}); start it with "
                             f"'{node_name}:' or '/**:'")
    for key in sections:
        body = data[key]
        if not isinstance(body, dict) or not isinstance(body.get(ROS_PARAMETERS), dict) \
                or set(body) != {ROS_PARAMETERS}:
            raise ParameterError(f"--params-file {path}: section '{key}' must hold only "
                                 f"'{ROS_PARAMETERS}:' with a mapping of parameters")
        for name in flatten(body[ROS_PARAMETERS]):
            if name in known or name in BUILTIN_PARAMETERS or name.startswith(
                    BUILTIN_PREFIXES):
                continue
            raise _unknown(path, name, known, node_name)
