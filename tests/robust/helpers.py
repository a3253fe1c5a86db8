"""Running ``drill_sim`` as a user does, and what "one line, no traceback" means."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from drill_sim_ros import cli

ROOT = Path(__file__).resolve().parents[2]
FAULTY = "tests/robust/faulty_controllers.py"


def run_cli(capsys: pytest.CaptureFixture[str], *args: str) -> tuple[int, str, str]:
    """``drill_sim ARGS`` in this process (from the repository root): rc, stdout, stderr.
    An uncaught exception (a traceback for the user) fails the test here."""
    rc = cli.main(list(args))
    out, err = capsys.readouterr()
    return rc, out, err


def one_error_line(rc: int, err: str, *names: str) -> str:
    """rc 2 and exactly one ``error:`` line on stderr, naming every one of ``names``."""
    lines = [line for line in err.splitlines() if "error" in line]
    assert rc == 2, err
    assert len(lines) == 1, err
    assert "Traceback" not in err
    for name in names:
        assert name in lines[0], (name, lines[0])
    return lines[0]


def run_process(*args: str, timeout_s: float = 120) -> subprocess.CompletedProcess[str]:
    """``python -m drill_sim_ros.cli ARGS`` as a process."""
    return subprocess.run([sys.executable, "-m", "drill_sim_ros.cli", *args],
                          capture_output=True, text=True, timeout=timeout_s, cwd=ROOT)
