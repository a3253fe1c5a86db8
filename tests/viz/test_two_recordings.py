"""One run of the real sim_node recorded twice, in process (record.path) and over DDS
(mcap_recorder): the two files have different log times, and mcap_to_rerun makes the same
dashboard of both.

Lockstep, so that the DDS recording holds every sample too (each ~/step publishes one).
"""

from __future__ import annotations

import signal
import time
from pathlib import Path

import numpy as np
import pytest
from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory

from drill_sim_ros import topics
from drill_sim_ros.viz.mcap_to_rerun import convert
from tests.archive.helpers import running, stop, wait_for
from tests.archive.ros_fixtures import ros_node, step_sim
from tests.viz.rrd_read import read_recording

pytestmark = pytest.mark.ros
STEPS = 300                       # 3 s of simulated time at 100 Hz
SAMPLE_TOPICS = [t for t in topics.MSG_TYPES
                 if t not in (*topics.COMMANDS, *topics.PROFILE_TOPICS, topics.DIAGNOSTICS,
                              topics.RUN_INFO)]


def _record_twice(tmp: Path) -> tuple[Path, Path, int, int]:
    inprocess, dds = tmp / "inprocess.mcap", tmp / "dds.mcap"
    sim_cmd = ["sim_node", "--ros-args", "-p", "lockstep:=true", "-p", "status_line:=false",
               "-p", f"record.path:={inprocess}"]
    before = time.time_ns()
    with running(sim_cmd, tmp / "sim.log") as sim, \
            running(["mcap_recorder", "-o", str(dds)], tmp / "rec.log") as recorder, \
            ros_node("test_two_recordings") as node:
        assert wait_for(lambda: all(node.count_subscribers(t) > 0 for t in SAMPLE_TOPICS),
                        30), "the recorder never subscribed"
        time.sleep(0.3)
        step_sim(node, STEPS)
        time.sleep(0.5)
        assert stop(recorder, signal.SIGINT) == 0, (tmp / "rec.log").read_text()
        assert stop(sim, signal.SIGINT) == 0, (tmp / "sim.log").read_text()
    return inprocess, dds, before, time.time_ns()


def _joint_states(path: Path) -> tuple[np.ndarray, np.ndarray]:
    """(log time ns, header stamp ns) of the bit joint states."""
    log, stamps = [], []
    with path.open("rb") as stream:
        reader = make_reader(stream, decoder_factories=[DecoderFactory()])
        for _, _, message, decoded in reader.iter_decoded_messages(
                topics=[topics.BIT_JOINT_STATES]):
            log.append(message.log_time)
            stamps.append(decoded.header.stamp.sec * 1_000_000_000
                          + decoded.header.stamp.nanosec)
    return np.array(log), np.array(stamps)


@pytest.fixture(scope="module")
def recordings(tmp_path_factory: pytest.TempPathFactory) -> dict:
    tmp = tmp_path_factory.mktemp("two_recordings")
    inprocess, dds, before, after = _record_twice(tmp)
    out = {"before": before, "after": after, "inprocess": inprocess, "dds": dds}
    for name in ("inprocess", "dds"):
        rrd = tmp / f"{name}.rrd"
        out[f"{name}_samples"] = convert(out[name], rrd)
        out[f"{name}_data"] = read_recording(rrd)
    return out


def test_in_process_log_time_is_a_real_date_spaced_like_sim_time(recordings: dict) -> None:
    log, stamps = _joint_states(recordings["inprocess"])
    assert len(log) == STEPS + 1                                  # t = 0, then each step
    assert stamps[-1] - stamps[0] == STEPS * 10_000_000           # stamps: simulated time
    assert recordings["before"] <= log[0] <= recordings["after"]   # not 1970
    np.testing.assert_array_equal(log - log[0], stamps - stamps[0])
    dds_log, dds_stamps = _joint_states(recordings["dds"])
    np.testing.assert_array_equal(dds_stamps, stamps)             # the same messages
    assert recordings["before"] <= dds_log[0] <= recordings["after"]


def test_both_files_give_the_same_dashboard(recordings: dict) -> None:
    a, b = recordings["inprocess_data"], recordings["dds_data"]
    assert recordings["inprocess_samples"] == recordings["dds_samples"] == STEPS + 1
    assert sorted(a) == sorted(b)
    for path in set(a) - {"/__properties"}:      # (it holds when the .rrd was written)
        np.testing.assert_array_equal(a[path].time_ns, b[path].time_ns, err_msg=path)
        assert a[path].columns == b[path].columns, path
        assert a[path].static == b[path].static, path
