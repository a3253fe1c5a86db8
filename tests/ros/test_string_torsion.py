"""The string profiles over loopback DDS: the distributed string along depth at
string.rate_hz on sample stamps, in the in-process recording too (read back by mcap_ros2 and
rosbags), as drill_sim_msgs/StringProfile on drill/typed/string/torsion (string.message
typed, the default) or as JointState on drill/string/torsion; none for a lumped string."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory
from rosbags.highlevel import AnyReader
from std_srvs.srv import Trigger

from drill_sim_ros import topics
from drill_sim_ros.model.params import RPM_PER_RAD_S
from drill_sim_ros.model.presets import DEFAULT_PRESET, load_preset
from drill_sim_ros.ros.sim_node import SimNode
from tests.archive.helpers import running, wait_for
from tests.ros.harness import Probe, overrides, ros_context
from tests.viz.rrd_read import read_recording

pytestmark = pytest.mark.ros
F = topics.TELEMETRY_INDEX
STEPS = 20
PERIOD_S = 0.01          # publish_rate_hz 100 (the default)
WATCHED = (topics.STRING_TORSION, topics.TYPED_STRING_TORSION, topics.TELEMETRY)
TOPIC_OF = {"typed": topics.TYPED_STRING_TORSION, "joint_state": topics.STRING_TORSION}


def stamp_ns(msg) -> int:
    return msg.header.stamp.sec * 1_000_000_000 + msg.header.stamp.nanosec


def stepped_run(tmp_path, **params) -> tuple[dict[str, list], list[str]]:
    """STEPS lockstep periods of a node with ``params``; the messages of WATCHED and the
    nodes publishing either string topic."""
    with ros_context() as ros:
        node = SimNode(context=ros.context, parameter_overrides=overrides(
            lockstep=True, status_line=False, top_drive__mode="kinematic",
            record__path=str(tmp_path / "run.mcap"), **params))
        node.start()
        ros.add(node)
        probe = ros.add(Probe(ros.context, WATCHED))
        assert ros.spin_until(lambda: node.count_subscribers(topics.TELEMETRY) > 0, 10.0)
        for _ in range(STEPS):
            response = ros.call(probe, Trigger, f"/{topics.NODE_NAME}/step", Trigger.Request())
            assert response.success, response.message
        assert ros.spin_until(lambda: probe.count(topics.TELEMETRY) == STEPS + 1, 10.0)
        ros.spin_for(0.3)
        published = [info.node_name for topic in topics.PROFILE_TOPICS
                     for info in probe.get_publishers_info_by_topic(topic)]
        ros.remove(node)                    # finishes the recording
        return {t: probe.messages(t) for t in WATCHED}, published


def bar_values(value: list) -> np.ndarray:
    return np.array(value[0]["buffer"], dtype=np.float64)


def recorded(path, topic: str) -> list:
    with path.open("rb") as stream:
        reader = make_reader(stream, decoder_factories=[DecoderFactory()])
        return [decoded for _, _, _, decoded in reader.iter_decoded_messages(topics=[topic])]


def recorded_by_rosbags(path, topic: str) -> list:
    with AnyReader([path]) as reader:
        chosen = [c for c in reader.connections if c.topic == topic]
        return [reader.deserialize(raw, connection.msgtype)
                for connection, _, raw in reader.messages(connections=chosen)]


def profile(msg) -> tuple[list, np.ndarray, np.ndarray]:
    """(the depths as the message gives them: m, or joint names; speeds; torques) of a
    StringProfile or a JointState, read as their definitions say."""
    if hasattr(msg, "depth_m"):
        return list(msg.depth_m), np.array(msg.speed_rad_s), np.array(msg.torque_nm)
    assert len(msg.position) == 0
    return list(msg.name), np.array(msg.velocity), np.array(msg.effort)


@pytest.fixture(scope="module")
def runs(tmp_path_factory: pytest.TempPathFactory) -> dict[str, tuple[Path, dict, list]]:
    """A stepped run per string.message: (its recording, its messages, the publishers)."""
    out = {}
    for message in TOPIC_OF:
        tmp = tmp_path_factory.mktemp(message)
        got, published = stepped_run(tmp, string__rate_hz=20.0, string__depths=16,
                                     string__message=message)
        out[message] = (tmp / "run.mcap", got, published)
    return out


@pytest.mark.parametrize("message", ["typed", "joint_state"])
def test_profiles_at_the_rate_on_sample_stamps_recorded_alike(runs, message) -> None:
    path, got, published = runs[message]
    assert published == [topics.NODE_NAME]
    topic = TOPIC_OF[message]
    other = next(t for t in topics.PROFILE_TOPICS if t != topic)
    profiles, telemetry = got[topic], got[topics.TELEMETRY]
    assert got[other] == []
    # every 5th sample of 100 Hz, the t = 0 one first: 0, 50, ..., 200 ms
    assert [stamp_ns(m) for m in profiles] == [i * 50_000_000 for i in range(5)]
    rows = {round(m.data[F["sim_time_s"]] * 1e9): m.data for m in telemetry}
    info = json.loads(recorded(path, topics.RUN_INFO)[0].data)["string"]
    depths = np.array(info["profile_depths_m"])
    assert len(depths) == 16 and np.all(np.diff(depths) > 0)
    length = info["length_m"]
    np.testing.assert_allclose(depths, (np.arange(16) + 0.5) * length / 16)
    labels = depths.tolist() if message == "typed" else [f"string_{d:06.1f}m" for d in depths]
    for msg in profiles:
        assert msg.header.frame_id == ("drill_sim_ros" if message == "typed" else "")
        names, speed, torque = profile(msg)
        assert names == labels and len(speed) == len(torque) == 16
        row = rows[stamp_ns(msg)]
        # the kinematic top turns at the surface speed, and so does the shallowest depth:
        # the string starts steady, and nothing from below reaches it in 0.2 s (the bit is
        # 0.85 s away); the deepest depth turns nearly with the BHA
        surface_rpm = row[F["surface_rpm"]]
        assert abs(speed[0] * RPM_PER_RAD_S - surface_rpm) < 1e-9 * surface_rpm
        assert abs(speed[-1] * RPM_PER_RAD_S - row[F["bha_rpm"]]) < 1.0
    # at t = 0 the string turns at the surface speed carrying the bit's torque plus the
    # viscous drag (rate x inertia x speed) of the string below each depth: all of it at
    # the shallowest depth (above the first damper), less with depth
    spec = load_preset(DEFAULT_PRESET).string
    omega = rows[0][F["surface_rpm"]] / RPM_PER_RAD_S
    drag_nm = sum(x.torsional_damping_per_s * x.inertia_kg_m2 for x in spec.sections) * omega
    _, speed0, effort = profile(profiles[0])
    assert effort[0] == pytest.approx(rows[0][F["tob_nm"]] + drag_nm, rel=1e-9)
    assert np.all(np.diff(effort) <= 1e-9 * effort[0]) and effort[-1] > rows[0][F["tob_nm"]]
    np.testing.assert_allclose(speed0 * RPM_PER_RAD_S, rows[0][F["surface_rpm"]], rtol=1e-12)
    for stored in (recorded(path, topic),
                   recorded_by_rosbags(path, topic)):
        assert [stamp_ns(m) for m in stored] == [stamp_ns(m) for m in profiles]
        for a, b in zip(stored, profiles, strict=True):
            for x, y in zip(profile(a), profile(b), strict=True):
                np.testing.assert_array_equal(x, y)


def test_lumped_string_and_rate_zero_publish_no_profiles(tmp_path) -> None:
    cases = ({"model__preset": "field_8p5in_shale_lumped"}, {"string__rate_hz": 0.0})
    for i, params in enumerate(cases):
        (tmp_path / str(i)).mkdir()
        got, published = stepped_run(tmp_path / str(i), **params)
        assert published == []
        assert got[topics.STRING_TORSION] == got[topics.TYPED_STRING_TORSION] == []


@pytest.mark.parametrize("message", ["typed", "joint_state"])
def test_mcap_to_rerun_shows_the_recorded_profiles(runs, message, tmp_path) -> None:
    """The recording through mcap_to_rerun, read back by rerun's reader: one bar chart per
    profile, at its stamp, over its depths (StringProfile: in m; JointState: the names' 0.1 m)."""
    path, got, _ = runs[message]
    rrd = tmp_path / "run.rrd"
    proc = subprocess.run([str(Path(sys.prefix) / "bin" / "mcap_to_rerun"), str(path), "-o",
                           str(rrd)], capture_output=True, text=True, timeout=300, check=False)
    assert proc.returncode == 0, proc.stderr
    profiles = got[TOPIC_OF[message]]
    data = read_recording(rrd)["/string/speed"]
    np.testing.assert_array_equal(data.time_ns, [stamp_ns(m) for m in profiles])
    for value, msg in zip(data.columns["BarChart:values"], profiles, strict=True):
        np.testing.assert_allclose(bar_values(value), profile(msg)[1] * RPM_PER_RAD_S,
                                   rtol=1e-12)
    info = json.loads(recorded(path, topics.RUN_INFO)[0].data)["string"]
    depths = np.array(info["profile_depths_m"])
    want = depths if message == "typed" else np.round(depths, 1)
    np.testing.assert_allclose(bar_values(data.columns["BarChart:abscissa"][-1]), want,
                               rtol=1e-12)


def test_replay_reproduces_the_typed_profiles(runs, tmp_path) -> None:
    """mcap_replay republishes drill/typed/string/torsion: the same profiles, in order."""
    path, got, _ = runs["typed"]
    topic = topics.TYPED_STRING_TORSION
    with ros_context() as ros:
        probe = ros.add(Probe(ros.context, (topic,)))
        command = ["mcap_replay", str(path), "--topics", topic, "--rate", "10",
                   "--wait-for-subscribers", "20", "--delay", "0.3"]
        with running(command, tmp_path / "replay.log") as replay:
            assert ros.spin_until(lambda: probe.count(topic) == len(got[topic])
                                  or replay.poll() is not None, 30.0)
            assert wait_for(lambda: replay.poll() is not None, 30.0)
            ros.spin_for(0.2)                 # stragglers would show as extra messages
    assert replay.returncode == 0
    replayed = probe.messages(topic)
    assert [stamp_ns(m) for m in replayed] == [stamp_ns(m) for m in got[topic]]
    for a, b in zip(replayed, got[topic], strict=True):
        assert a == b
