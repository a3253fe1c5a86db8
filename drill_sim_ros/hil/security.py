"""The gateway's secured mode: Basic256Sha256, Sign & Encrypt, one user with a password.

ROS-free. :func:`load_security` turns the four ``security.*`` settings into a
:class:`Security` (all four given), None (none given), or one ParameterError line (some given,
or a file that cannot be read). :class:`PasswordUser` is the asyncua user manager that admits
that one user and nobody else.
"""

from __future__ import annotations

import hmac
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from asyncua.crypto.permission_rules import User, UserRole

from drill_sim_ros.model.errors import ParameterError

APPLICATION_URI = "urn:drill_sim_ros:opcua_gateway"   # the server certificate's URI
SETTINGS = ("security.certificate", "security.private_key", "security.user",
            "security.password_file")


@dataclass(frozen=True)
class Security:
    """The server's certificate (DER or PEM) and private key (PEM) files, and its user."""

    certificate: Path
    private_key: Path
    user: str
    password: str


def _readable(name: str, path: str) -> Path:
    file = Path(path)
    if not file.is_file():
        raise ParameterError(f"{name} {path!r}: no such file")
    return file


def load_security(values: dict[str, str]) -> Security | None:
    """The secured mode of ``values`` (SETTINGS -> text; '' = not given), or None."""
    given = [name for name in SETTINGS if values.get(name)]
    if not given:
        return None
    missing = [name for name in SETTINGS if name not in given]
    if missing:
        raise ParameterError(f"the secured gateway needs all of {', '.join(SETTINGS)}; "
                             f"missing: {', '.join(missing)}")
    password_file = _readable("security.password_file", values["security.password_file"])
    lines = password_file.read_text(encoding="utf-8").splitlines()
    if not lines or not lines[0]:
        raise ParameterError(f"security.password_file {str(password_file)!r} is empty")
    return Security(_readable("security.certificate", values["security.certificate"]),
                    _readable("security.private_key", values["security.private_key"]),
                    values["security.user"], lines[0])


class PasswordUser:
    """asyncua's user manager: the one user with the right password, nobody else."""

    def __init__(self, user: str, password: str) -> None:
        self._user, self._password = user, password

    def get_user(self, iserver: Any, username: str | None = None,
                 password: str | None = None, certificate: Any = None) -> User | None:
        if username != self._user or password is None:
            return None
        if not hmac.compare_digest(password.encode(), self._password.encode()):
            return None
        return User(role=UserRole.User, name=username)
