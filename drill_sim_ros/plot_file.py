"""``--plot FILE`` of the offline commands: checked before the run, drawn into a temporary
file beside it, moved onto it when done (an existing file only with ``--overwrite``), so a
run that fails or is interrupted leaves nothing half-written."""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

from drill_sim_ros.archive.output import (
    OutputError,
    OutputExistsError,
    commit,
    temporary_beside,
)
from drill_sim_ros.model.errors import DrillSimError

PLOT_SUFFIXES = (".png", ".svg", ".pdf")


def add_plot_arguments(parser: Any, picture: str) -> None:
    """``--plot FILE`` (``picture``: what it draws) and ``--overwrite`` on ``parser``."""
    parser.add_argument("--plot", type=Path, help=f"write a PNG of {picture} (also .svg or "
                        ".pdf); an existing file is kept unless --overwrite")
    parser.add_argument("--overwrite", action="store_true",
                        help="replace an existing --plot file")


def _plot_target(path: Path | None, overwrite: bool) -> Path | None:
    """A writable temporary file beside ``--plot`` (checked before the run), or None; the
    caller removes it when done (:func:`commit_plot` moves it on)."""
    if path is None:
        return None
    if path.is_dir():
        raise DrillSimError(f"--plot {path} is a directory; give a file name such as "
                            f"{path / 'run.png'}")
    if path.suffix.lower() not in PLOT_SUFFIXES:
        raise DrillSimError(f"--plot {path}: unknown suffix {path.suffix!r}; use one of "
                            f"{', '.join(PLOT_SUFFIXES)}")
    try:
        return temporary_beside(path, overwrite, keep_suffix=True)
    except OutputExistsError as exc:
        raise DrillSimError(f"--plot: {exc}") from None
    except OutputError as exc:
        reason = str(exc).rsplit(": ", 1)[-1]
        raise DrillSimError(f"--plot {path}: cannot write there ({reason})") from None


def commit_plot(temporary: Path, path: Path, overwrite: bool) -> None:
    """The finished picture ``temporary`` onto ``--plot`` ``path``."""
    try:
        commit(temporary, path, overwrite)
    except OutputError as exc:
        raise DrillSimError(f"--plot: {exc}") from None


@contextmanager
def plot_into(path: Path | None, overwrite: bool) -> Iterator[Path | None]:
    """:func:`_plot_target` for the run inside the ``with``, removed after it whatever
    happened (:func:`commit_plot` has moved it on when the picture was done)."""
    temporary = _plot_target(path, overwrite)
    try:
        yield temporary
    finally:
        if temporary is not None:
            temporary.unlink(missing_ok=True)
