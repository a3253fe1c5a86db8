"""Test-session environment: DDS on loopback and a domain of our own.

Set before anything imports rclpy, so every node and subprocess a test starts inherits it.
"""

from __future__ import annotations

import os
import sys

os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
os.environ.pop("ROS_LOCALHOST_ONLY", None)
# A domain per test session (pid-derived) unless the caller (the Makefile) chose one.
os.environ.setdefault("ROS_DOMAIN_ID", str(1 + os.getpid() % 101))
_prefixes = [p for p in os.environ.get("AMENT_PREFIX_PATH", "").split(os.pathsep) if p]
if sys.prefix not in _prefixes:
    os.environ["AMENT_PREFIX_PATH"] = os.pathsep.join([*_prefixes, sys.prefix])
