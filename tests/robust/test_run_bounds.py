"""drill_sim run and sweep: a run too long to finish, values that are not numbers and a
fractional number of blades are one line before any work; Ctrl-C in a run is a clean stop."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time

from tests.robust.helpers import ROOT, one_error_line, run_cli


def test_a_run_of_more_steps_than_the_bound_is_refused(capsys) -> None:
    # 1e9 / 1e-4 = 1e13 steps, about two days of the kernel at 16 ns per step
    rc, out, err = run_cli(capsys, "run", "--tau-end", "1e9", "--dtau", "1e-4")
    one_error_line(rc, err, "--tau-end = 1e+09", "1e+13 steps", "at most 1e+10")
    assert out == ""


def test_a_negative_t_end_is_named_as_typed(capsys) -> None:
    rc, out, err = run_cli(capsys, "run", "--params", "field_8p5in_shale", "--t-end", "-3")
    one_error_line(rc, err, "--t-end = -3.0", "positive")
    assert out == ""


def test_sweep_values_that_are_not_numbers_are_one_line(capsys) -> None:
    rc, _, err = run_cli(capsys, "sweep", "--vary", "beta", "--values", "a,b")
    one_error_line(rc, err, "--values 'a,b'", "START:STOP:COUNT")
    rc, _, err = run_cli(capsys, "sweep", "--vary", "beta", "--values", "0:1:1000000")
    one_error_line(rc, err, "COUNT = 1000000", "[1, 10000]")


def test_a_fractional_number_of_blades_is_never_rounded(capsys) -> None:
    rc, out, err = run_cli(capsys, "sweep", "--vary", "n", "--values", "2.5,3", "--tau-end",
                           "1")
    one_error_line(rc, err, "--values '2.5,3'", "n = 2.5", "whole number")
    assert out == ""                                  # not a run at n = 2


def test_ctrl_c_in_a_run_is_one_line_and_exit_130() -> None:
    # 1e9 steps: minutes of kernel, so the signal lands inside it
    process = subprocess.Popen([sys.executable, "-m", "drill_sim_ros.cli", "run", "--tau-end",
                                "1e5", "--dtau", "1e-4"], cwd=ROOT, stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, text=True)
    time.sleep(4.0)                                   # past the imports, into the kernel
    assert process.poll() is None
    process.send_signal(signal.SIGINT)
    start = time.monotonic()
    out, err = process.communicate(timeout=60)
    assert process.returncode == 130, err
    assert err.strip().splitlines() == ["drill_sim run: interrupted"] and out == ""
    assert time.monotonic() - start < 30              # the kernel hears it between chunks


def test_output_into_a_closed_pipe_is_no_traceback() -> None:
    """`drill_sim params | head -1`: the reader is gone before the output ends."""
    read_end, write_end = os.pipe()
    os.close(read_end)                                # a reader that has already gone
    try:
        done = subprocess.run([sys.executable, "-m", "drill_sim_ros.cli", "presets"],
                              cwd=ROOT, stdout=write_end, stderr=subprocess.PIPE, text=True,
                              timeout=60)
    finally:
        os.close(write_end)
    assert done.returncode == 128 + signal.SIGPIPE, done.stderr
    assert done.stderr == ""
