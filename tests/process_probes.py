"""What tests and benchmarks read about the processes they start, from /proc (CPU time,
resident memory, listening sockets), and a free loopback port to give one (Linux)."""

from __future__ import annotations

import os
import socket
import time
from pathlib import Path

TICKS_PER_S = os.sysconf("SC_CLK_TCK")
LISTEN = "0A"                 # the TCP state LISTEN in /proc/net/tcp


def cpu_seconds(pid: int) -> float:
    """utime + stime of a process, in seconds."""
    fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / TICKS_PER_S


def rss_bytes(pid: int) -> int:
    """Resident set size of a process, bytes."""
    for line in Path(f"/proc/{pid}/status").read_text().splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1]) * 1024
    raise RuntimeError(f"no VmRSS for {pid}")


def free_port() -> int:
    """A TCP port on 127.0.0.1 that nothing listens on now."""
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return sock.getsockname()[1]


def listening_addresses(port: int) -> set[str]:
    """Hex local addresses (as in /proc/net/tcp*) listening on ``port``."""
    found = set()
    for table in ("/proc/net/tcp", "/proc/net/tcp6"):
        for line in Path(table).read_text().splitlines()[1:]:
            fields = line.split()
            address, port_hex = fields[1].rsplit(":", 1)
            if int(port_hex, 16) == port and fields[3] == LISTEN:
                found.add(address)
    return found


def wait_listening(port: int, timeout_s: float) -> set[str]:
    """The addresses listening on ``port`` once there are any, within ``timeout_s``; else
    an empty set."""
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        if found := listening_addresses(port):
            return found
        time.sleep(0.05)
    return set()
