"""closed-loop --plot follows the output policy, checked before the run: an existing file is
kept unless --overwrite, a directory, an unwritable place or an unknown suffix is one line
and no run (no table is printed). So do run --trace and map-plot -o."""

from __future__ import annotations

import warnings
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


def test_an_existing_trace_is_kept_unless_overwrite(capsys, tmp_path: Path) -> None:
    trace = tmp_path / "trace.csv"
    trace.write_text("an earlier trace\n")
    rc, out, err = run_cli(capsys, "run", "--tau-end", "1", "--trace", str(trace))
    one_error_line(rc, err, str(trace), "exists", "--overwrite")
    assert out == "" and trace.read_text() == "an earlier trace\n"
    rc, _, err = run_cli(capsys, "run", "--tau-end", "1", "--trace", str(trace),
                         "--trace-every", "1000", "--overwrite")
    assert rc == 0, err
    rows = trace.read_text().splitlines()
    assert rows[0].startswith("tau,omega") and len(rows) == 1 + 10     # 1e4 steps / 1000


def test_an_existing_map_picture_is_kept_unless_overwrite(capsys, tmp_path: Path) -> None:
    nc, png = tmp_path / "m.nc", tmp_path / "m.png"
    rc, _, err = run_cli(capsys, "map", "--params", "fig5_8a", "--vary", "beta=0.2,0.4",
                         "--tau-end", "1", "--workers", "1", "--out", str(nc))
    assert rc == 0, err
    png.write_bytes(b"an earlier picture")
    rc, out, err = run_cli(capsys, "map-plot", str(nc), "--var", "kappa")  # to m.png
    one_error_line(rc, err, str(png), "exists", "--overwrite")
    assert out == "" and png.read_bytes() == b"an earlier picture"
    rc, _, err = run_cli(capsys, "map-plot", str(nc), "--var", "kappa", "--overwrite")
    assert rc == 0, err
    assert png.read_bytes()[:8] == PNG_MAGIC
    assert sorted(p.name for p in tmp_path.iterdir() if p.name.startswith("m.")) == [
        "m.nc", "m.png"]                                                  # no temporary left
    assert not [p for p in tmp_path.iterdir() if "partial" in p.name]


def test_a_bit_at_rest_all_run_draws_without_warnings(capsys, tmp_path: Path) -> None:
    """tight_torque_limit stalls at its first stick (57 s): after the switch-on at 60 s the
    bit never moves, so its spectrum has nothing to put on a log axis. The picture says so
    in words instead of drawing an empty log-log plot and warning on stderr."""
    png = tmp_path / "stall.png"
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        rc, _, err = run_cli(capsys, "closed-loop", "--scenario", "tight_torque_limit",
                             "--no-baseline", "--json", "--plot", str(png))
    assert rc == 0, err
    assert png.read_bytes()[:8] == PNG_MAGIC
    assert not [str(w.message) for w in caught if "positive" in str(w.message)]
