"""The gateway's secured mode: Basic256Sha256, Sign & Encrypt, one user with a password.

ROS-free. :func:`load_security` turns the four ``security.*`` settings into a
:class:`Security` (all four given), None (none given), or one ParameterError line (some given,
a file that cannot be read, a certificate without the gateway's application URI, or a private
key that is not the certificate's). :class:`PasswordUser` is the asyncua user manager that admits
that one user and nobody else.
"""

from __future__ import annotations

import hmac
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from asyncua.crypto.permission_rules import User, UserRole
from cryptography import x509
from cryptography.hazmat.primitives import serialization

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


def _certificate(path: Path) -> x509.Certificate:
    data = path.read_bytes()
    try:
        if data.lstrip().startswith(b"-----BEGIN"):
            return x509.load_pem_x509_certificate(data)
        return x509.load_der_x509_certificate(data)
    except ValueError:
        raise ParameterError(f"security.certificate {str(path)!r} is not a DER or PEM "
                             "certificate") from None


def certificate_uris(certificate: x509.Certificate) -> list[str]:
    """The URIs of a certificate's subjectAltName (an application instance certificate's
    ApplicationUri is one of them, OPC UA Part 6 6.2.2)."""
    try:
        names = certificate.extensions.get_extension_for_class(x509.SubjectAlternativeName)
    except x509.ExtensionNotFound:
        return []
    return names.value.get_values_for_type(x509.UniformResourceIdentifier)


def check_key_pair(certificate_path: Path, key_path: Path) -> None:
    """ParameterError (one line) unless the certificate carries :data:`APPLICATION_URI` and the
    private key is the certificate's: either mismatch would start a server whose every secured
    client times out (``Decryption failed``)."""
    certificate = _certificate(certificate_path)
    uris = certificate_uris(certificate)
    if APPLICATION_URI not in uris:
        raise ParameterError(f"security.certificate {str(certificate_path)!r} is for "
                             f"{', '.join(uris) or 'no application URI'}, not the gateway's "
                             f"{APPLICATION_URI} (make one with that URI in subjectAltName)")
    try:
        key = serialization.load_pem_private_key(key_path.read_bytes(), password=None)
    except (ValueError, TypeError):
        raise ParameterError(f"security.private_key {str(key_path)!r} is not an unencrypted "
                             "PEM private key") from None
    public = serialization.PublicFormat.SubjectPublicKeyInfo
    if key.public_key().public_bytes(serialization.Encoding.DER, public) != \
            certificate.public_key().public_bytes(serialization.Encoding.DER, public):
        raise ParameterError(f"security.private_key {str(key_path)!r} is not the key of "
                             f"security.certificate {str(certificate_path)!r}")


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
    certificate = _readable("security.certificate", values["security.certificate"])
    private_key = _readable("security.private_key", values["security.private_key"])
    check_key_pair(certificate, private_key)
    return Security(certificate, private_key, values["security.user"], lines[0])


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
