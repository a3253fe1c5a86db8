"""Errors of the MCAP archive; all descend from :class:`ArchiveError`."""

from __future__ import annotations

from drill_sim_ros.model.errors import DrillSimError


class ArchiveError(DrillSimError):
    """Base class of every error the archive raises on purpose."""


class ArchiveNotFoundError(ArchiveError, FileNotFoundError):
    """The archive file does not exist."""


class NotAnArchiveError(ArchiveError):
    """The file is not an MCAP file (bad magic, empty, or unreadable header)."""


class UnknownMessageTypeError(ArchiveError, LookupError):
    """A message type has no definition in the installed packages (share/<pkg>/msg)."""


class WriterClosedError(ArchiveError):
    """A write was attempted after the writer was finished."""
