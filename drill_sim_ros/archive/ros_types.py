"""Python classes of ROS 2 message types named ``pkg/msg/Type``."""

from __future__ import annotations

import functools
import importlib

from drill_sim_ros.archive.errors import UnknownMessageTypeError
from drill_sim_ros.archive.schemas import split_type_name


@functools.cache
def message_class(type_name: str) -> type:
    """The generated rclpy class of ``pkg/msg/Type`` (its Python package must be installed)."""
    package, name = split_type_name(type_name)
    try:
        return getattr(importlib.import_module(f"{package}.msg"), name)
    except (ImportError, AttributeError) as exc:
        raise UnknownMessageTypeError(f"no Python message class for {type_name}: {exc}") from exc
