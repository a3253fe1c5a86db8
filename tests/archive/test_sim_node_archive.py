"""The real sim_node, recorded in lockstep: in process (record.path) and over DDS (mcap_recorder).

In lockstep every ~/step publishes exactly one sample on each data topic and /clock, so the
recorded counts must equal the number of steps exactly; /diagnostics (1 Hz wall) is only
checked against the file's own statistics.
"""

from __future__ import annotations

import signal
import time

import pytest

from drill_sim_ros import topics
from drill_sim_ros.model.presets import load_preset
from drill_sim_ros.viz.mcap_telemetry import recorded_preset, recorded_run_info
from tests.archive.helpers import (
    counts_mcap_ros2,
    counts_rosbags,
    running,
    statistics_counts,
    stop,
    wait_for,
)
from tests.archive.ros_fixtures import ros_node, step_sim

pytestmark = pytest.mark.ros

STEPS = 40
SAMPLE_TOPICS = [t for t in topics.MSG_TYPES
                 if t not in (*topics.COMMANDS, topics.DIAGNOSTICS,
                              topics.RUN_INFO)]


def _sim_command(*params: str) -> list[str]:
    args = ["lockstep:=true", "status_line:=false", *params]
    return ["sim_node", "--ros-args", *[a for p in args for a in ("-p", p)]]


def _check(path, samples: int | None) -> None:
    """Every sample topic holds ``samples`` messages; None: the steps' and perhaps the t = 0
    sample, which a recorder hears only if it matched before the sim published it."""
    counts = counts_mcap_ros2(path)
    assert counts == counts_rosbags(path) == statistics_counts(path)
    if samples is None:
        assert all(counts[t] in (STEPS, STEPS + 1) for t in SAMPLE_TOPICS), counts
    else:
        assert {t: counts[t] for t in SAMPLE_TOPICS} == dict.fromkeys(SAMPLE_TOPICS, samples)
    assert counts[topics.RUN_INFO] == 1                 # latched: once, even for a late recorder
    info = recorded_run_info(path)
    scales = load_preset("field_8p5in_shale_lumped").scales
    assert info["preset"] == "field_8p5in_shale_lumped"
    assert (info["t_star_s"], info["l_star_m"], info["force_unit_n"], info["torque_unit_nm"]) \
        == (scales.time_s, scales.length_m, scales.force_n, scales.torque_nm)


def test_lockstep_in_process_recording_is_exact(tmp_path) -> None:
    path = tmp_path / "inprocess.mcap"
    with running(_sim_command(f"record.path:={path}"), tmp_path / "sim.log") as sim, \
            ros_node("test_stepper") as node:
        step_sim(node, STEPS)
        assert stop(sim, signal.SIGINT) == 0, (tmp_path / "sim.log").read_text()
    _check(path, STEPS + 1)                     # the t = 0 sample, then one per step
    assert "0 dropped" in (tmp_path / "sim.log").read_text()
    assert recorded_preset(path) == "field_8p5in_shale_lumped"     # the default preset


def _recorder_ready(node) -> bool:
    return all(node.count_subscribers(t) > 0 for t in SAMPLE_TOPICS)


def test_lockstep_sim_recorded_over_dds_is_exact(tmp_path) -> None:
    path = tmp_path / "dds.mcap"
    recorder_cmd = ["mcap_recorder", "-o", str(path)]
    with running(_sim_command(), tmp_path / "sim.log") as sim, \
            running(recorder_cmd, tmp_path / "rec.log") as recorder, \
            ros_node("test_stepper") as node:
        assert wait_for(lambda: _recorder_ready(node), 30), "recorder never subscribed"
        time.sleep(0.3)
        step_sim(node, STEPS)
        time.sleep(0.5)
        assert stop(recorder, signal.SIGINT) == 0, (tmp_path / "rec.log").read_text()
        stop(sim, signal.SIGINT)
    _check(path, STEPS + 1)                     # t = 0 goes out with the first step
