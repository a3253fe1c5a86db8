"""The OPC UA gateway's busy port is one line, and a stopped or failed run leaves no partial
picture and no directory it made (issue 52, point 6)."""

from __future__ import annotations

import asyncio
import logging
import os
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import pytest

from drill_sim_ros.hil.rig_server import Rig, RigServer
from drill_sim_ros.model.errors import DrillSimError
from tests.hil.test_rig_server import SETTINGS, StandIn
from tests.robust.helpers import FAULTY, ROOT, one_error_line, run_cli

WAIT_S = 60.0


def test_a_busy_gateway_port_is_one_line_without_a_traceback(
        caplog: pytest.LogCaptureFixture) -> None:
    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        url = f"opc.tcp://127.0.0.1:{taken.getsockname()[1]}/drill_sim/"
        stand_in = StandIn()
        server = RigServer(url, [Rig("north", SETTINGS, stand_in.send, stand_in.switch_mode)])
        with caplog.at_level(logging.DEBUG), pytest.raises(DrillSimError) as caught:
            asyncio.run(asyncio.wait_for(server.start(), WAIT_S))
    message = str(caught.value)
    assert "\n" not in message and url in message and "in use" in message
    assert not [r for r in caplog.records if r.exc_info or r.levelno >= logging.ERROR]


def _wait_for(predicate, what: str) -> None:
    deadline = time.monotonic() + WAIT_S
    while not predicate():
        assert time.monotonic() < deadline, f"no {what} after {WAIT_S:g} s"
        time.sleep(0.05)


@pytest.mark.parametrize(("sig", "rc"), [(signal.SIGTERM, 130), (signal.SIGINT, 130)])
def test_a_signal_during_startup_plot_leaves_nothing(tmp_path: Path, sig: int,
                                                     rc: int) -> None:
    made = tmp_path / "out"
    target = made / "sub" / "term.png"
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    with subprocess.Popen([sys.executable, "-m", "drill_sim_ros.cli", "startup", "--params",
                           "field_8p5in_deviated", "--rpm", "30", "--seconds", "3600",
                           "--plot", str(target)], cwd=ROOT, env=env,
                          stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                          text=True) as process:
        try:
            _wait_for(lambda: target.parent.exists() and any(target.parent.iterdir()),
                      "partial picture")
            process.send_signal(sig)
            _, err = process.communicate(timeout=WAIT_S)
        finally:
            process.kill()
    assert process.returncode == rc, err
    assert "Traceback" not in err
    assert not made.exists(), list(made.rglob("*"))


def test_a_run_that_fails_leaves_no_directory_it_made(capsys: pytest.CaptureFixture[str],
                                                      tmp_path: Path) -> None:
    made = tmp_path / "new" / "dir"
    rc, _, err = run_cli(capsys, "closed-loop", "--controller", f"{FAULTY}:RaisesInStep",
                         "--t-end", "1", "--no-baseline", "--plot", str(made / "p.png"))
    one_error_line(rc, err, "RaisesInStep")
    assert not (tmp_path / "new").exists()
    assert list(tmp_path.iterdir()) == []


TORN_COMPILE = """
import os, signal, sys, time
from drill_sim_ros import cli, startup_cli
def torn(args):
    try:
        os.kill(os.getpid(), signal.SIGINT)
        time.sleep(60)
    except KeyboardInterrupt:
        raise RuntimeError("no compiled object yet for <Library 'line_energy'>") from None
    return 0
startup_cli.cmd_startup = torn
sys.exit(cli.main(["startup", "--params", "field_8p5in_deviated"]))
"""


def test_a_stop_that_a_library_re_raises_as_its_own_error_is_still_an_interruption() -> None:
    """numba's compiler, interrupted by the KeyboardInterrupt a SIGINT raises, re-raises it
    as a RuntimeError ("no compiled object yet for <Library ...>", measured 2026-12-06 with
    a Ctrl-C during a cold compile on a loaded machine: a traceback and status 1). After a
    stop signal any error is the interruption's: one line, status 130. In a process of its
    own: the stop arms the last resort (os._exit after the grace), which must not end the
    test run."""
    done = subprocess.run([sys.executable, "-c", TORN_COMPILE], cwd=ROOT,
                          env={**os.environ, "PYTHONPATH": str(ROOT)}, capture_output=True,
                          text=True, timeout=WAIT_S)
    assert done.returncode == 130, done.stderr
    assert done.stderr.strip() == "drill_sim startup: interrupted", done.stderr
