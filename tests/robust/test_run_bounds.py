"""drill_sim run and sweep: a run too long to finish and values that are not numbers are
one line before any work."""

from __future__ import annotations

from tests.robust.helpers import one_error_line, run_cli


def test_a_run_of_more_steps_than_the_bound_is_refused(capsys) -> None:
    # 1e9 / 1e-4 = 1e13 steps, about two days of the kernel at 16 ns per step
    rc, out, err = run_cli(capsys, "run", "--tau-end", "1e9", "--dtau", "1e-4")
    one_error_line(rc, err, "--tau-end = 1e+09", "1e+13 steps", "at most 1e+10")
    assert out == ""


def test_sweep_values_that_are_not_numbers_are_one_line(capsys) -> None:
    rc, _, err = run_cli(capsys, "sweep", "--vary", "beta", "--values", "a,b")
    one_error_line(rc, err, "--values 'a,b'", "START:STOP:COUNT")
    rc, _, err = run_cli(capsys, "sweep", "--vary", "beta", "--values", "0:1:1000000")
    one_error_line(rc, err, "COUNT = 1000000", "[1, 10000]")
