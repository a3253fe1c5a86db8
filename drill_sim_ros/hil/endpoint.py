"""Where the gateway may listen: loopback for anonymous clients, elsewhere only secured
(issue 33).

An OPC UA server reachable off the machine lets anyone who reaches it command a simulated top
drive and, in hardware in the loop, the rig's controller under test. Anonymous access without
security is served on loopback only; a non-loopback endpoint needs the secured mode
(:mod:`.security`: Basic256Sha256, Sign & Encrypt, a user and password) and is refused at
start with one line without it.
"""

from __future__ import annotations

import ipaddress
from urllib.parse import urlsplit

from drill_sim_ros.model.errors import ParameterError

LOOPBACK_NAMES = ("localhost",)


def endpoint_host(endpoint: str) -> str:
    """The host of an ``opc.tcp://host:port/path`` endpoint (ParameterError if malformed)."""
    parts = urlsplit(endpoint)
    try:
        port = parts.port
    except ValueError:
        port = None
    if parts.scheme != "opc.tcp" or not parts.hostname or port is None:
        raise ParameterError(f"endpoint {endpoint!r} is not opc.tcp://HOST:PORT/PATH")
    return parts.hostname


def is_loopback(host: str) -> bool:
    if host in LOOPBACK_NAMES:
        return True
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return False


def check_endpoint(endpoint: str, secured: bool = False) -> None:
    """ParameterError (one line) unless ``endpoint`` binds a loopback address or the gateway
    is ``secured``."""
    host = endpoint_host(endpoint)
    if not secured and not is_loopback(host):
        raise ParameterError(
            f"endpoint {endpoint!r} binds {host}, off loopback: anonymous access without a "
            "security policy is allowed on loopback only; set security.certificate, "
            "security.private_key, security.user and security.password_file (Basic256Sha256, "
            "Sign & Encrypt), or bind 127.0.0.1")
