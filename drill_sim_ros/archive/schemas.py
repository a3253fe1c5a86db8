"""ROS 2 message definitions for MCAP schemas, from the installed packages' share directories.

A schema in the MCAP ``ros2`` profile is named ``pkg/msg/Type`` with encoding ``ros2msg``; its
data is the main ``.msg`` text followed, for each type it depends on, by a separator line of 80
``=`` and a ``MSG: pkg/Type`` line with that type's ``.msg`` text (the format rosbag2 writes and
mcap-ros2-support, rosbags and Foxglove parse). The RIHS01 type hash comes from the
``share/<pkg>/msg/<Type>.json`` file rosidl generates next to the ``.msg``.
"""

from __future__ import annotations

import functools
import json
import os
import sys
from dataclasses import dataclass
from pathlib import Path

from drill_sim_ros.archive.errors import UnknownMessageTypeError

SCHEMA_ENCODING = "ros2msg"
SEPARATOR = "=" * 80


@dataclass(frozen=True)
class MessageDefinition:
    """A full ``ros2msg`` definition of one message type.

    type_name: ``pkg/msg/Type``; text: concatenated definition; type_hash: ``RIHS01_<hex>``.
    """

    type_name: str
    text: str
    type_hash: str


def split_type_name(type_name: str) -> tuple[str, str]:
    """``pkg/msg/Type`` (or ``pkg/Type``) -> (``pkg``, ``Type``)."""
    parts = type_name.split("/")
    if len(parts) not in (2, 3) or (len(parts) == 3 and parts[1] != "msg") or not all(parts):
        raise UnknownMessageTypeError(f"not a ROS 2 message type name: {type_name!r}")
    return parts[0], parts[-1]


def _prefixes() -> list[Path]:
    """Install prefixes to search: AMENT_PREFIX_PATH, then the running interpreter's prefix."""
    found = [Path(p) for p in os.environ.get("AMENT_PREFIX_PATH", "").split(os.pathsep) if p]
    return [*found, Path(sys.prefix)]


def _msg_file(package: str, name: str, suffix: str) -> Path:
    for prefix in _prefixes():
        candidate = prefix / "share" / package / "msg" / f"{name}{suffix}"
        if candidate.is_file():
            return candidate
    raise UnknownMessageTypeError(
        f"no {package}/msg/{name}{suffix} under any prefix of AMENT_PREFIX_PATH or {sys.prefix}"
    )


def _type_description(package: str, name: str) -> dict:
    return json.loads(_msg_file(package, name, ".json").read_text(encoding="utf-8"))


def _own_hash(description: dict, type_name: str) -> str:
    for entry in description.get("type_hashes", []):
        if entry.get("type_name") == type_name:
            return str(entry["hash_string"])
    raise UnknownMessageTypeError(f"no type hash for {type_name} in its .json description")


@functools.cache
def message_definition(type_name: str) -> MessageDefinition:
    """The definition of ``pkg/msg/Type`` (cached: each type is built once per process)."""
    package, name = split_type_name(type_name)
    full_name = f"{package}/msg/{name}"
    description = _type_description(package, name)
    referenced = description["type_description_msg"]["referenced_type_descriptions"]
    blocks = [_msg_file(package, name, ".msg").read_text(encoding="utf-8").rstrip("\n")]
    for dependency in referenced:
        dep_package, dep_name = split_type_name(dependency["type_name"])
        dep_text = _msg_file(dep_package, dep_name, ".msg").read_text(encoding="utf-8")
        blocks.append(f"{SEPARATOR}\nMSG: {dep_package}/{dep_name}\n{dep_text.rstrip(chr(10))}")
    text = "\n".join(blocks) + "\n"
    return MessageDefinition(full_name, text, _own_hash(description, full_name))
