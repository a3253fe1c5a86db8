"""Is ``--scheduler`` a Dask scheduler? Checked before ``distributed.Client`` is built.

``distributed.Client(address, timeout=30)`` can wait far past its timeout on a server that
accepts the connection and never answers (a silent TCP listener, an HTTP server). A Dask
scheduler speaks first: it sends its handshake as soon as a connection is accepted. So
:func:`check_scheduler` checks the address's form (``tcp://HOST:PORT`` or ``HOST:PORT``),
connects with a timeout and waits, bounded, for those first bytes; anything else is one
:class:`~drill_sim_ros.model.errors.DrillSimError` line naming the address.
"""

from __future__ import annotations

import re
import socket

from drill_sim_ros.model.errors import DrillSimError

PROBE_TIMEOUT_S = 10.0
_ADDRESS = re.compile(r"^(?:tcp://)?(\[[0-9a-fA-F:]+\]|[A-Za-z0-9.\-]+):(\d{1,5})$")


def parse_address(scheduler: str) -> tuple[str, int]:
    """(host, port) of ``tcp://HOST:PORT`` or ``HOST:PORT``; DrillSimError otherwise."""
    match = _ADDRESS.match(scheduler.strip())
    if not match or not 0 < int(match.group(2)) < 65536:
        hint = (" (that is a web address; the dashboard's http:// page is not the "
                "scheduler)" if scheduler.startswith(("http://", "https://")) else "")
        raise DrillSimError(f"--scheduler {scheduler!r}: a Dask scheduler address is "
                            f"tcp://HOST:PORT, e.g. tcp://127.0.0.1:8786{hint}")
    return match.group(1).strip("[]"), int(match.group(2))


def check_scheduler(scheduler: str, timeout_s: float | None = None) -> str:
    """``scheduler`` as ``tcp://HOST:PORT`` once it has answered like a Dask scheduler
    within ``timeout_s`` (default PROBE_TIMEOUT_S)."""
    host, port = parse_address(scheduler)
    timeout_s = PROBE_TIMEOUT_S if timeout_s is None else timeout_s
    try:
        with socket.create_connection((host, port), timeout=timeout_s) as sock:
            sock.settimeout(timeout_s)
            first = sock.recv(16)
    except TimeoutError:
        raise DrillSimError(f"--scheduler {scheduler}: the server at {host}:{port} accepted "
                            f"the connection but sent nothing in {timeout_s:g} s; it is not "
                            "a Dask scheduler") from None
    except OSError as exc:
        raise DrillSimError(f"--scheduler {scheduler}: cannot connect to {host}:{port} "
                            f"({exc.strerror or exc})") from None
    if not first or first.startswith(b"HTTP"):
        raise DrillSimError(f"--scheduler {scheduler}: the server at {host}:{port} is not a "
                            "Dask scheduler (it closed the connection or answered HTTP)")
    return f"tcp://{host}:{port}"
