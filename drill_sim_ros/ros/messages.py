"""Message classes of the ROS interface and small message builders."""

from __future__ import annotations

import importlib

from diagnostic_msgs.msg import DiagnosticStatus, KeyValue

from drill_sim_ros import topics

HARDWARE_ID = "drill_sim_ros"


def message_class(type_name: str) -> type:
    """The rclpy class of ``pkg/msg/Type``."""
    package, _, name = type_name.split("/")
    return getattr(importlib.import_module(f"{package}.msg"), name)


def type_of(topic: str) -> type:
    """The message class of one of the topics in :mod:`drill_sim_ros.topics`."""
    return message_class(topics.MSG_TYPES[topic])


def status(name: str, level: bytes, message: str, values: dict[str, str]) -> DiagnosticStatus:
    """A DiagnosticStatus with ``values`` as key/value pairs."""
    return DiagnosticStatus(level=level, name=name, message=message, hardware_id=HARDWARE_ID,
                            values=[KeyValue(key=k, value=v) for k, v in values.items()])
