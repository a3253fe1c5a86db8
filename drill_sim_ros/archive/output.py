"""The one output policy of every tool: never overwrite an existing file unless told to.

:func:`open_output` opens a file to write from its first byte: it refuses an existing file
(:class:`OutputExistsError`) unless ``overwrite``, creates missing parent directories, and
turns any OS error into one :class:`OutputError` line naming the path. Tools that produce a
file only at the end (``mcap_to_rerun``, ``mcap_reindex``) write a temporary file beside the
target and :func:`commit` it, so an interrupted or failed run leaves no partial output and
the existing file, if any, untouched.
"""

from __future__ import annotations

import errno
import os
from pathlib import Path
from typing import IO

from drill_sim_ros.archive.errors import ArchiveError

OVERWRITE_HINT = "--overwrite"


class OutputError(ArchiveError):
    """An output file cannot be created or written; the message is one line with the path."""


class OutputExistsError(OutputError, FileExistsError):
    """The output exists and overwriting was not asked for."""


def _exists_error(path: Path, hint: str) -> OutputExistsError:
    return OutputExistsError(f"{path} exists; not overwriting it (pass {hint} to replace it, "
                             "or choose another path)")


def _os_error(path: Path, exc: OSError) -> OutputError:
    return OutputError(f"cannot write {path}: {exc.strerror or exc}")


def check_output(path: str | Path, overwrite: bool, hint: str = OVERWRITE_HINT) -> Path:
    """``path`` as a Path, refused if it exists (unless ``overwrite``) or is a directory."""
    path = Path(path)
    if path.is_dir():
        raise OutputError(f"cannot write {path}: it is a directory")
    if path.exists() and not overwrite:
        raise _exists_error(path, hint)
    return path


def open_output(path: str | Path, overwrite: bool, hint: str = OVERWRITE_HINT) -> IO[bytes]:
    """Open ``path`` for writing under the policy above (exclusive create unless overwrite)."""
    path = check_output(path, overwrite, hint)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise _os_error(path, exc) from None
    try:
        return path.open("wb" if overwrite else "xb")
    except FileExistsError:                     # created by someone else since the check
        raise _exists_error(path, hint) from None
    except OSError as exc:
        raise _os_error(path, exc) from None


def temporary_beside(path: str | Path, overwrite: bool, hint: str = OVERWRITE_HINT,
                     keep_suffix: bool = False) -> Path:
    """A fresh temporary path in ``path``'s directory (checked writable) for :func:`commit`;
    with ``keep_suffix`` it ends in ``path``'s suffix (for writers that pick the format
    from it)."""
    path = check_output(path, overwrite, hint)
    suffix = path.suffix if keep_suffix else ""
    temporary = path.with_name(f".{path.name}.{os.getpid()}.partial{suffix}")
    open_output(temporary, overwrite=True).close()
    return temporary


def _link_or_move(temporary: Path, path: Path, hint: str) -> None:
    """A hard link fails if ``path`` appeared meanwhile; without links, check and move."""
    try:
        os.link(temporary, path)
    except OSError as exc:
        if exc.errno not in (errno.EPERM, errno.EOPNOTSUPP, errno.EXDEV, errno.EMLINK):
            raise
        if path.exists():
            raise _exists_error(path, hint) from None
        os.replace(temporary, path)


def commit(temporary: Path, path: str | Path, overwrite: bool,
           hint: str = OVERWRITE_HINT) -> None:
    """Move the finished ``temporary`` onto ``path`` atomically (no clobber unless told)."""
    path = Path(path)
    try:
        if overwrite:
            os.replace(temporary, path)
            return
        _link_or_move(temporary, path, hint)
    except FileExistsError:
        raise _exists_error(path, hint) from None
    except OSError as exc:
        raise _os_error(path, exc) from None
    finally:
        temporary.unlink(missing_ok=True)
