"""sim_node's recording and start-up faults, as a user meets them: an existing or unwritable
record.path, a full disk, bad parameters and params files, and split recordings."""

from __future__ import annotations

import os
import signal
import subprocess
import time

import pytest
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
from rclpy.qos import QoSProfile

from drill_sim_ros import topics
from drill_sim_ros.archive.reader import ArchiveReader
from drill_sim_ros.model.presets import DEFAULT_PRESET
from drill_sim_ros.ros import typed
from drill_sim_ros.viz.mcap_telemetry import recorded_preset
from tests.archive.helpers import BIN, counts_mcap_ros2, running, stop, wait_for
from tests.archive.ros_fixtures import ros_node, step_sim
from tests.archive.test_sim_node_archive import SAMPLE_TOPICS, _sim_command

pytestmark = pytest.mark.ros
# 0.5 s of log time: every sample topic (/clock included, and the typed telemetry twin when
# drill_sim_msgs is built) at 100 Hz, the string profiles at string.rate_hz (10 Hz), and
# /diagnostics
CHUNK_MESSAGES = 50 * (len(SAMPLE_TOPICS) + int(typed.AVAILABLE)) + 5 + 10


def _sim(*ros_args: str, timeout_s: float = 60) -> subprocess.CompletedProcess:
    return subprocess.run([str(BIN / "sim_node"), "--ros-args", *ros_args],
                          capture_output=True, text=True, timeout=timeout_s,
                          env=os.environ.copy())


def _one_fatal_line(done: subprocess.CompletedProcess) -> str:
    lines = [line for line in (done.stdout + done.stderr).splitlines() if line.strip()]
    assert done.returncode == 2, done.stdout + done.stderr          # a user's mistake
    assert len(lines) == 1 and "[FATAL]" in lines[0], lines
    return lines[0]


def test_an_existing_record_path_stops_the_node_and_is_kept(tmp_path) -> None:
    keep = tmp_path / "keep.mcap"
    keep.write_bytes(b"an earlier run" * 100)
    line = _one_fatal_line(_sim("-p", f"record.path:={keep}", "-p", "run_seconds:=2"))
    assert str(keep) in line and "record.overwrite:=true" in line
    assert keep.read_bytes() == b"an earlier run" * 100
    done = _sim("-p", f"record.path:={keep}", "-p", "record.overwrite:=true",
                "-p", "run_seconds:=2", "-p", "status_line:=false")
    assert done.returncode == 0, done.stderr
    assert counts_mcap_ros2(keep)[topics.BIT_WOB] > 0


def test_an_unwritable_record_path_stops_the_node_at_start(tmp_path) -> None:
    blocker = tmp_path / "a_file"
    blocker.write_bytes(b"")
    line = _one_fatal_line(_sim("-p", f"record.path:={blocker}/run.mcap",
                                "-p", "run_seconds:=2"))
    assert f"cannot write {blocker}/run.mcap" in line


@pytest.mark.parametrize(("args", "names"), [
    (["-p", "real_time_factor:=.nan"], ["real_time_factor", "nan", "[0, 1000]"]),
    (["-p", "real_time_factor:=1e6"], ["real_time_factor", "[0, 1000]"]),
    (["-p", "model.n_nodes:=8"], ["model.n_nodes", "[16,"]),
    (["-p", "lockstep:=3"], ["lockstep", "true or false"]),
    (["-p", "model.dtau:=fast"], ["model.dtau", "a number"]),
    (["-p", "model.preset:=no_such_preset"], ["no_such_preset"]),
    (["--params-file", "/nonexistent/sim.yaml"], ["/nonexistent/sim.yaml", "No such file"]),
    (["-p", "foo"], ["'foo'", "NAME:=VALUE"]),
    (["-p", "top_drive.mode:=fast"], ["top_drive.mode", "kinematic, speed, torque"]),
])
def test_bad_start_up_input_is_one_fatal_line(args, names) -> None:
    line = _one_fatal_line(_sim(*args))
    for name in names:
        assert name in line


def test_a_params_file_that_is_not_yaml_is_one_fatal_line(tmp_path) -> None:
    bad = tmp_path / "sim.yaml"
    bad.write_text("drill_sim:\n  ros__parameters:\n    real_time_factor: [1,\n")
    line = _one_fatal_line(_sim("--params-file", str(bad)))
    assert str(bad) in line and "line" in line


def _statuses(messages: list[DiagnosticArray]) -> list[DiagnosticStatus]:
    return [s for m in messages for s in m.status if s.name.endswith(": simulation")]


def test_a_full_disk_turns_diagnostics_to_error_and_the_sim_runs_on(small_disk, tmp_path):
    path = small_disk / "run.mcap"
    log = tmp_path / "sim.log"
    command = ["sim_node", "--ros-args", "-p", f"record.path:={path}",
               "-p", "real_time_factor:=0", "-p", "status_line:=false"]
    received: list[DiagnosticArray] = []
    with running(command, log) as sim, ros_node("test_diagnostics") as node:
        node.create_subscription(DiagnosticArray, topics.DIAGNOSTICS, received.append,
                                 QoSProfile(depth=10))

        def failed() -> list[DiagnosticStatus]:
            return [s for s in _statuses(received) if s.level == DiagnosticStatus.ERROR]

        assert wait_for(lambda: len(failed()) >= 2, 60), log.read_text()
        first, later = failed()[0], failed()[-1]
        assert "No space left on device" in first.message
        values = [{v.key: v.value for v in s.values} for s in (first, later)]
        assert float(values[1]["sim_time_s"]) > float(values[0]["sim_time_s"])  # runs on
        assert values[1]["recorder_written"] == values[0]["recorder_written"]  # honest count
        assert stop(sim, signal.SIGINT) == 1
    text = log.read_text()
    assert "Traceback" not in text
    final = [line for line in text.splitlines() if "recording incomplete" in line]
    assert len(final) == 1 and "lost" in final[0], text
    kept = int(final[0].split("; ")[-1].split(" messages kept")[0])
    readable = sum(1 for _ in ArchiveReader(path).messages())
    # kept counts chunks whose every record reached the OS; the chunk whose message index
    # hit the full disk may still be readable: at most one 0.5 s chunk (10 topics x 100 Hz)
    assert 0 < kept <= readable <= kept + CHUNK_MESSAGES


def test_in_process_recording_splits_by_simulated_duration(tmp_path) -> None:
    path = tmp_path / "run.mcap"
    steps = 40                    # 0.4 s of simulated time at 100 Hz: four 0.1 s files
    with running(_sim_command(f"record.path:={path}", "record.split_duration_s:=0.1"),
                 tmp_path / "sim.log") as sim, ros_node("test_stepper") as node:
        step_sim(node, steps)
        assert stop(sim, signal.SIGINT) == 0, (tmp_path / "sim.log").read_text()
    parts = sorted(tmp_path.glob("run_*.mcap"))
    assert [p.name for p in parts][:4] == [f"run_{i:04d}.mcap" for i in range(4)]
    assert not path.exists()
    totals = dict.fromkeys(SAMPLE_TOPICS, 0)
    for part in parts:
        counts = counts_mcap_ros2(part)
        assert ArchiveReader(part).summary() is not None
        assert recorded_preset(part) == DEFAULT_PRESET     # every part stands alone
        assert max(counts[t] for t in SAMPLE_TOPICS) <= 10 + 1
        for topic in SAMPLE_TOPICS:
            totals[topic] += counts[topic]
    assert totals == dict.fromkeys(SAMPLE_TOPICS, steps + 1)      # the t = 0 sample too


def test_a_command_of_the_wrong_type_is_named_once(tmp_path) -> None:
    from std_msgs.msg import Int32

    log = tmp_path / "sim.log"
    with running(_sim_command(), log) as sim, ros_node("test_wrong_type") as node:
        pub = node.create_publisher(Int32, topics.CMD_WOB, QoSProfile(depth=10))
        pub.publish(Int32(data=5))
        wanted = f"publishes std_msgs/msg/Int32 on {topics.CMD_WOB}"
        assert wait_for(lambda: wanted in log.read_text(), 30), log.read_text()
        time.sleep(2.5)                                       # two more graph checks
        assert log.read_text().count(wanted) == 1
        assert "/test_wrong_type" in log.read_text()
        assert stop(sim, signal.SIGINT) == 0
