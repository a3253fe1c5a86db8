"""The package as ROS 2 tools see it: colcon builds an install tree, ament_index resolves it the
way `ros2 run drill_sim_ros sim_node` does, and that executable publishes and stops cleanly on
SIGINT; SIGTERM and SIGHUP also end a run cleanly with its MCAP recording finished (issue 3)."""

from __future__ import annotations

import contextlib
import os
import shutil
import signal
import subprocess
import sys
from pathlib import Path

import pytest

from drill_sim_ros import topics
from tests.ros.harness import Probe, ros_context

pytestmark = pytest.mark.ros
REPO = Path(__file__).resolve().parents[2]
PACKAGE = "drill_sim_ros"
PACKAGE_FILES = ("setup.py", "setup.cfg", "package.xml", "resource", "config", "launch",
                 PACKAGE)
VENV_BIN = Path(sys.executable).parent


def colcon_build(workspace: Path) -> Path:
    """Copy the package into ``workspace``/src, colcon build it; returns the install prefix."""
    src = workspace / "src" / PACKAGE
    src.mkdir(parents=True)
    ignore = shutil.ignore_patterns("__pycache__", "*.pyc", "*.nbi", "*.nbc")
    for name in PACKAGE_FILES:
        source = REPO / name
        if source.is_dir():
            shutil.copytree(source, src / name, ignore=ignore)
        else:
            shutil.copy2(source, src / name)
    env = {**os.environ, "PATH": f"{VENV_BIN}{os.pathsep}{os.environ.get('PATH', '')}"}
    done = subprocess.run([str(VENV_BIN / "colcon"), "build", "--base-paths", "src"],
                          cwd=workspace, env=env, capture_output=True, text=True, timeout=180)
    assert done.returncode == 0, done.stdout + done.stderr
    return workspace / "install" / PACKAGE


def installed_env(prefix: Path) -> dict[str, str]:
    """What `. install/setup.sh` sets for an ament_python package."""
    site = prefix / "lib" / f"python{sys.version_info.major}.{sys.version_info.minor}" / \
        "site-packages"
    ament = [str(prefix), *[p for p in os.environ.get("AMENT_PREFIX_PATH", "").split(
        os.pathsep) if p]]
    return {**os.environ, "AMENT_PREFIX_PATH": os.pathsep.join(ament), "PYTHONPATH": str(site),
            "PYTHONUNBUFFERED": "1"}


def resolve_like_ros2_run(env: dict[str, str], cwd: Path) -> tuple[Path, Path]:
    """(package prefix from ament_index, the package's import location) in ``env``."""
    code = ("from ament_index_python.packages import get_package_prefix\n"
            "import drill_sim_ros\n"
            "print(get_package_prefix('drill_sim_ros')); print(drill_sim_ros.__file__)")
    done = subprocess.run([sys.executable, "-c", code], env=env, cwd=cwd, capture_output=True,
                          text=True, timeout=60)
    assert done.returncode == 0, done.stderr
    prefix, module = done.stdout.split()
    return Path(prefix), Path(module)


def run_until_published(command: list[str], env: dict[str, str], stop: signal.Signals
                        ) -> subprocess.CompletedProcess:
    """Start ``command``, wait for 20 telemetry samples, send ``stop``, return its result."""
    with ros_context() as ros:
        probe = ros.add(Probe(ros.context, [topics.TELEMETRY]))
        proc = subprocess.Popen(command, env=env, stdout=subprocess.PIPE,
                                stderr=subprocess.STDOUT, text=True)
        try:
            # a fresh install compiles its kernels cold (no numba cache yet): on a loaded
            # 2-core machine that alone can take most of a minute, and a signal that comes
            # during the compile is handled only after it
            published = ros.spin_until(lambda: probe.count(topics.TELEMETRY) >= 20, 150.0)
            proc.send_signal(stop)
            try:
                out, _ = proc.communicate(timeout=90)
            except subprocess.TimeoutExpired:
                proc.send_signal(signal.SIGUSR1)     # sim_node dumps its threads' stacks
                with contextlib.suppress(subprocess.TimeoutExpired):
                    proc.communicate(timeout=5)
                proc.kill()
                out, _ = proc.communicate()
                pytest.fail(f"no exit within 90 s of {stop.name}; its threads:\n{out[-6000:]}")
        finally:
            if proc.poll() is None:
                proc.kill()
                proc.communicate()
    assert published, "the node did not publish"
    return subprocess.CompletedProcess(command, proc.returncode, out)


def test_colcon_install_tree_runs_like_ros2_run(tmp_path):
    prefix = colcon_build(tmp_path)
    executable = prefix / "lib" / PACKAGE / "sim_node"
    assert executable.is_file() and os.access(executable, os.X_OK)
    assert (prefix / "share" / "ament_index" / "resource_index" / "packages" / PACKAGE).is_file()
    share = prefix / "share" / PACKAGE
    for installed in ("config/sim.yaml", "config/fastdds_localhost.xml",
                      "launch/drill_sim.launch.py"):
        assert (share / installed).is_file(), installed
    env = installed_env(prefix)
    found_prefix, module = resolve_like_ros2_run(env, tmp_path)
    assert found_prefix == prefix
    assert prefix in module.parents, "the installed copy, not the source tree, is imported"
    ros2_run = found_prefix / "lib" / PACKAGE / "sim_node"   # what `ros2 run` executes
    params = prefix / "share" / PACKAGE / "config" / "sim.yaml"
    done = run_until_published([str(ros2_run), "--ros-args", "--params-file", str(params),
                                "-p", "status_line:=false"], env, signal.SIGINT)
    assert done.returncode == 0, done.stdout


@pytest.mark.parametrize("signum", [signal.SIGTERM, signal.SIGHUP], ids=["SIGTERM", "SIGHUP"])
def test_sigterm_or_a_closed_terminal_ends_a_recording_run_cleanly(tmp_path, signum):
    from mcap.reader import make_reader

    path = tmp_path / "run" / "run.mcap"
    done = run_until_published([str(VENV_BIN / "sim_node"), "--ros-args", "-p",
                                f"record.path:={path}", "-p", "status_line:=false",
                                "-p", "real_time_factor:=5"], os.environ.copy(),
                               signum)
    assert done.returncode == 0, done.stdout
    with path.open("rb") as stream:
        summary = make_reader(stream).get_summary()
    assert summary is not None and summary.statistics.message_count >= 20 * 9
    recorded = {channel.topic for channel in summary.channels.values()}
    # the default string.message is typed: the profiles go on the typed topic, not on the
    # JointState one; every other standard topic is recorded
    assert set(topics.MSG_TYPES) - set(topics.COMMANDS) - {topics.STRING_TORSION} <= recorded
    assert topics.TYPED_STRING_TORSION in recorded
    assert topics.STRING_TORSION not in recorded


def test_a_hung_up_terminal_under_the_status_line_still_ends_the_run_cleanly(tmp_path):
    """`make run` in a terminal that is closed: the status line's writes fail (EIO) while
    SIGHUP stops the node, and the recording must still be finished."""
    import pty

    from mcap.reader import make_reader

    path = tmp_path / "run.mcap"
    master, slave = pty.openpty()
    command = [str(VENV_BIN / "sim_node"), "--ros-args", "-p", f"record.path:={path}",
               "-p", "real_time_factor:=5"]
    os.set_blocking(master, False)
    shown = bytearray()

    def published_and_shown() -> bool:
        """The terminal reads what the node writes (else a full pty blocks its writes)."""
        with contextlib.suppress(BlockingIOError):
            shown.extend(os.read(master, 1 << 16))
        return probe.count(topics.TELEMETRY) >= 20 and b"rpm" in shown

    with ros_context() as ros:
        probe = ros.add(Probe(ros.context, [topics.TELEMETRY]))
        proc = subprocess.Popen(command, stdin=slave, stdout=slave, stderr=slave)
        os.close(slave)
        try:
            assert ros.spin_until(published_and_shown, 60.0), bytes(shown[-500:])
            os.close(master)                   # the terminal goes away: writes now fail
            master = -1
            proc.send_signal(signal.SIGHUP)
            assert proc.wait(timeout=20) == 0
        finally:
            if master >= 0:
                os.close(master)
            if proc.poll() is None:
                proc.kill()
                proc.wait()
    with path.open("rb") as stream:
        summary = make_reader(stream).get_summary()
    assert summary is not None and summary.statistics.message_count >= 20 * 9
