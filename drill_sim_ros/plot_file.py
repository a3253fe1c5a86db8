"""``--plot FILE`` (and the other files written at the end of a run) of the offline
commands: checked before the run, written into a temporary file beside it, moved onto it
when done (an existing file only with ``--overwrite``), so a run that fails or is
interrupted leaves nothing half-written."""

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


def add_plot_arguments(parser: Any, picture: str, others: str = "") -> None:
    """``--plot FILE`` (``picture``: what it draws) and ``--overwrite`` on ``parser``;
    ``others`` names the command's other output options that ``--overwrite`` covers."""
    parser.add_argument("--plot", type=Path, help=f"write a PNG of {picture} (also .svg or "
                        ".pdf); an existing file is kept unless --overwrite")
    parser.add_argument("--overwrite", action="store_true",
                        help=f"replace an existing --plot{others} file")


def _output_target(path: Path | None, overwrite: bool, option: str,
                   suffixes: tuple[str, ...]) -> Path | None:
    """A writable temporary path beside the file of ``option`` (checked before the run), or
    None; the caller removes it when done (:func:`commit_output` moves it on)."""
    if path is None:
        return None
    if path.is_dir():
        raise DrillSimError(f"{option} {path} is a directory; give a file name such as "
                            f"{path / ('run' + suffixes[0])}")
    if path.suffix.lower() not in suffixes:
        allowed = f"one of {', '.join(suffixes)}" if len(suffixes) > 1 else suffixes[0]
        raise DrillSimError(f"{option} {path}: unknown suffix {path.suffix!r}; use {allowed}")
    try:
        return temporary_beside(path, overwrite, keep_suffix=True)
    except OutputExistsError as exc:
        raise DrillSimError(f"{option}: {exc}") from None
    except OutputError as exc:
        reason = str(exc).rsplit(": ", 1)[-1]
        raise DrillSimError(f"{option} {path}: cannot write there ({reason})") from None


def commit_output(temporary: Path, path: Path, overwrite: bool, option: str) -> None:
    """The finished file ``temporary`` onto ``path`` (the file of ``option``)."""
    try:
        commit(temporary, path, overwrite)
    except OutputError as exc:
        raise DrillSimError(f"{option}: {exc}") from None


def commit_plot(temporary: Path, path: Path, overwrite: bool) -> None:
    """The finished picture ``temporary`` onto ``--plot`` ``path``."""
    commit_output(temporary, path, overwrite, "--plot")


@contextmanager
def output_into(path: Path | None, overwrite: bool, option: str = "--plot",
                suffixes: tuple[str, ...] = PLOT_SUFFIXES) -> Iterator[Path | None]:
    """:func:`_output_target` for the run inside the ``with``, removed after it whatever
    happened (:func:`commit_output` has moved it on when the file was done)."""
    created = [] if path is None else _missing_directories(path)
    temporary = _output_target(path, overwrite, option, suffixes)
    if temporary is not None:
        _UNFINISHED[temporary] = created
    try:
        yield temporary
    finally:
        if temporary is not None:
            _UNFINISHED.pop(temporary, None)
            temporary.unlink(missing_ok=True)
        if path is not None and not path.exists():
            _remove_empty(created)


# the temporary files of the outputs under way, and the directories made for each
_UNFINISHED: dict[Path, list[Path]] = {}


def remove_unfinished() -> None:
    """Remove every output under way (its temporary file, the empty directories made for
    it): what a stop signal's handler calls before the command unwinds, so nothing is left
    even where its exception cannot unwind (raised inside a C callback, e.g. numba's
    compiler, Python ignores it)."""
    for temporary, created in list(_UNFINISHED.items()):
        temporary.unlink(missing_ok=True)
        _remove_empty(created)


def _missing_directories(path: Path) -> list[Path]:
    """The directories above ``path`` that do not exist yet (deepest first): the ones
    writing it creates."""
    return [d for d in (path.parent, *path.parent.parents) if not d.exists()]


def _remove_empty(directories: list[Path]) -> None:
    """Remove ``directories`` (deepest first) that are still empty: a run that made them for
    its file and failed, or was stopped, leaves none behind."""
    for directory in directories:
        try:
            directory.rmdir()
        except OSError:                      # not empty (something else wrote there), gone
            return


def plot_into(path: Path | None, overwrite: bool) -> Any:
    """:func:`output_into` for ``--plot``."""
    return output_into(path, overwrite)
