"""closed-loop --plot follows the output policy, checked before the run: an existing file is
kept unless --overwrite, a directory, an unwritable place or an unknown suffix is one line
and no run (no table is printed)."""

from __future__ import annotations

from pathlib import Path

import pytest

from tests.robust.helpers import one_error_line, run_cli

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"
SHORT = ("closed-loop", "--t-end", "1", "--no-baseline", "--json")


def test_an_existing_plot_is_kept_unless_overwrite(capsys, tmp_path: Path) -> None:
    png = tmp_path / "kept.png"
    png.write_bytes(b"an earlier picture")
    rc, out, err = run_cli(capsys, *SHORT, "--plot", str(png))
    one_error_line(rc, err, str(png), "exists", "--overwrite")
    assert out == "" and png.read_bytes() == b"an earlier picture"
    rc, out, err = run_cli(capsys, *SHORT, "--plot", str(png), "--overwrite")
    assert rc == 0, err
    assert out and png.read_bytes()[:8] == PNG_MAGIC
    assert sorted(p.name for p in tmp_path.iterdir()) == ["kept.png"]    # no temporary left


def test_a_plot_in_a_missing_directory_creates_it(capsys, tmp_path: Path) -> None:
    png = tmp_path / "new" / "dir" / "run.png"
    rc, _, err = run_cli(capsys, *SHORT, "--plot", str(png))
    assert rc == 0, err
    assert png.read_bytes()[:8] == PNG_MAGIC


@pytest.mark.parametrize(("where", "names"), [
    ("a_dir.png", ("a_dir.png", "is a directory")),
    ("a_dir", ("a_dir", "is a directory")),         # the issue's --plot /some/dir
    ("x.jpg", ("x.jpg", "unknown suffix", ".png")),
    ("/proc/drill_sim_test.png", ("/proc/drill_sim_test.png", "cannot write")),
])
def test_a_plot_path_that_cannot_be_written_stops_before_the_run(
        capsys, tmp_path: Path, where: str, names: tuple[str, ...]) -> None:
    (tmp_path / "a_dir.png").mkdir()
    (tmp_path / "a_dir").mkdir()
    path = where if where.startswith("/") else str(tmp_path / where)
    rc, out, err = run_cli(capsys, *SHORT, "--plot", path)
    one_error_line(rc, err, *names)
    assert out == ""                           # checked before the run, not after it
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a_dir", "a_dir.png"]  # no .png
    assert not any((tmp_path / "a_dir.png").iterdir())
    assert not any((tmp_path / "a_dir").iterdir())
