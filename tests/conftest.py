"""Test-session environment: DDS on loopback, a domain of our own, and SIGINT as a terminal
delivers it.

Set before anything imports rclpy, so every node and subprocess a test starts inherits it.
"""

from __future__ import annotations

import os
import signal
import sys

os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
os.environ.pop("ROS_LOCALHOST_ONLY", None)
# A domain per test session (pid-derived) unless the caller (the Makefile) chose one; each
# pytest-xdist worker (gw0, gw1, ...) the next domains from it, so two workers' nodes and
# topics never meet.
os.environ.setdefault("ROS_DOMAIN_ID", str(1 + os.getpid() % 101))
_worker = os.environ.get("PYTEST_XDIST_WORKER", "")
if _worker.startswith("gw"):
    os.environ["ROS_DOMAIN_ID"] = str(
        1 + (int(os.environ["ROS_DOMAIN_ID"]) - 1 + int(_worker[2:])) % 101)
_prefixes = [p for p in os.environ.get("AMENT_PREFIX_PATH", "").split(os.pathsep) if p]
if sys.prefix not in _prefixes:
    os.environ["AMENT_PREFIX_PATH"] = os.pathsep.join([*_prefixes, sys.prefix])


def sigint_as_default() -> None:
    """SIGINT raises KeyboardInterrupt here and is unblocked, whatever the caller set.

    A shell starts a background job (``make test &``, ``nohup``, some CI runners) with
    SIGINT ignored; an ignored signal survives ``exec``, so every process a test starts
    would ignore the Ctrl-C the test sends it. A handler does not survive ``exec``: with one
    here, children start with SIGINT at its default. A blocked signal mask would be
    inherited as well.
    """
    signal.signal(signal.SIGINT, signal.default_int_handler)
    signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})


sigint_as_default()


import subprocess  # noqa: E402
from collections.abc import Iterator  # noqa: E402
from pathlib import Path  # noqa: E402

import pytest  # noqa: E402

SMALL_DISK_BYTES = 2 * 1024 * 1024


@pytest.fixture
def small_disk(tmp_path: Path) -> Iterator[Path]:
    """A 2 MiB tmpfs mounted in tmp_path (a full disk on demand); skipped where mounting is
    not allowed."""
    mount_point = tmp_path / "small_disk"
    mount_point.mkdir()
    done = subprocess.run(["mount", "-t", "tmpfs", "-o", f"size={SMALL_DISK_BYTES}", "tmpfs",
                           str(mount_point)], capture_output=True, text=True, timeout=10)
    if done.returncode != 0:
        pytest.skip(f"cannot mount a small tmpfs here: {done.stderr.strip() or done.returncode}")
    try:
        yield mount_point
    finally:
        subprocess.run(["umount", "-l", str(mount_point)], capture_output=True, timeout=10)
