"""The test session hands SIGINT on at its default, however it was started: a background job
(``make test &``, ``nohup``, some CI runners) starts with SIGINT ignored, and an ignored
signal is inherited by every process a test starts (tests/conftest.py)."""

from __future__ import annotations

import signal
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
# a Ctrl-C test of a child process that installs no handler of its own (drill_sim run)
CTRL_C_TEST = "tests/robust/test_run_bounds.py::test_ctrl_c_in_a_run_is_one_line_and_exit_130"


def test_sigint_raises_keyboard_interrupt_in_the_session_and_is_not_blocked() -> None:
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler
    assert signal.SIGINT not in signal.pthread_sigmask(signal.SIG_BLOCK, set())


def test_a_child_of_a_session_started_with_sigint_ignored_stops_on_sigint() -> None:
    """The session itself starts as a background job does (``trap '' INT HUP``, then exec),
    and runs a Ctrl-C test: its child hears the SIGINT the test sends."""
    done = subprocess.run(
        ["sh", "-c", "trap '' INT HUP; exec \"$@\"", "sh", sys.executable, "-m", "pytest",
         "-q", "-p", "no:cacheprovider", CTRL_C_TEST], cwd=ROOT,
        capture_output=True, text=True, timeout=240)
    assert done.returncode == 0, done.stdout[-3000:] + done.stderr[-2000:]
    assert "1 passed" in done.stdout


def test_the_shell_trap_is_what_a_background_job_inherits() -> None:
    """The wrapper above does ignore SIGINT in what it starts (else the test proves
    nothing)."""
    done = subprocess.run(
        ["sh", "-c", "trap '' INT HUP; exec \"$@\"", "sh", sys.executable, "-c",
         "import signal; print(signal.getsignal(signal.SIGINT) is signal.SIG_IGN)"],
        capture_output=True, text=True, timeout=60)
    assert done.stdout.strip() == "True", done.stderr
