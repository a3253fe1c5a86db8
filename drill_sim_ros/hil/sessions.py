"""Which client session a request comes from (issue 53: one writer).

asyncua hands its write callbacks the session's :class:`~asyncua.crypto.permission_rules.User`
and its method callbacks nothing. So the gateway's user manager, :class:`SessionUsers`, gives
every activated session a User object of its own (anonymous clients too), and the object is
the session's identity: compared with ``is``, held weakly (a closed session's object goes
with it, so its ownership lapses at once).

A method call names no session: :func:`note` records the User of each read or write request
in a context variable of the task that serves the connection (asyncua serves each
connection's requests in one task, in order), and :func:`current` reads it back in the
method's callback, which runs in that task. A session that calls a method before it read or
wrote anything is unknown (None).
"""

from __future__ import annotations

import itertools
import weakref
from contextvars import ContextVar
from typing import Any

from asyncua.crypto.permission_rules import User, UserRole

from drill_sim_ros.hil.security import PasswordUser

_CURRENT: ContextVar[weakref.ref[User] | None] = ContextVar("opcua_session_user", default=None)


class SessionUsers:
    """asyncua's user manager: a User object per activated session; with ``password_user``
    (the secured mode), only that user, else anonymous sessions."""

    def __init__(self, password_user: PasswordUser | None = None) -> None:
        self._password_user = password_user
        self._numbers = itertools.count(1)

    def get_user(self, iserver: Any, username: str | None = None,
                 password: str | None = None, certificate: Any = None) -> User | None:
        number = next(self._numbers)
        if self._password_user is None:
            return User(role=UserRole.User, name=f"anonymous session {number}")
        user = self._password_user.get_user(iserver, username, password, certificate)
        return None if user is None else User(role=user.role, name=f"{user.name} ({number})")


def note(user: Any) -> None:
    """Record ``user`` as the session of the connection being served (a read or write)."""
    if isinstance(user, User):
        _CURRENT.set(weakref.ref(user))


def current() -> User | None:
    """The session of the connection being served, if it read or wrote before."""
    ref = _CURRENT.get()
    return None if ref is None else ref()
