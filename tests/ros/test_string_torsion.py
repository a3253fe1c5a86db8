"""drill/string/torsion over loopback DDS: the distributed string along depth at
string.rate_hz on sample stamps, in the in-process recording too; none for a lumped string."""

from __future__ import annotations

import json

import numpy as np
import pytest
from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory
from std_srvs.srv import Trigger

from drill_sim_ros import topics
from drill_sim_ros.model.params import RPM_PER_RAD_S
from drill_sim_ros.model.presets import DEFAULT_PRESET, load_preset
from drill_sim_ros.ros.sim_node import SimNode
from tests.ros.harness import Probe, overrides, ros_context

pytestmark = pytest.mark.ros
F = topics.TELEMETRY_INDEX
STEPS = 20
PERIOD_S = 0.01          # publish_rate_hz 100 (the default)
WATCHED = (topics.STRING_TORSION, topics.TELEMETRY)


def stamp_ns(msg) -> int:
    return msg.header.stamp.sec * 1_000_000_000 + msg.header.stamp.nanosec


def stepped_run(tmp_path, **params) -> tuple[dict[str, list], list[str]]:
    """STEPS lockstep periods of a node with ``params``; the messages of WATCHED and the
    nodes publishing drill/string/torsion."""
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
        published = [info.node_name for info in
                     probe.get_publishers_info_by_topic(topics.STRING_TORSION)]
        ros.remove(node)                    # finishes the recording
        return {t: probe.messages(t) for t in WATCHED}, published


def recorded(path, topic: str) -> list:
    with path.open("rb") as stream:
        reader = make_reader(stream, decoder_factories=[DecoderFactory()])
        return [decoded for _, _, _, decoded in reader.iter_decoded_messages(topics=[topic])]


def test_profiles_at_the_rate_on_sample_stamps_recorded_alike(tmp_path) -> None:
    got, published = stepped_run(tmp_path, string__rate_hz=20.0, string__depths=16)
    assert published == [topics.NODE_NAME]
    profiles, telemetry = got[topics.STRING_TORSION], got[topics.TELEMETRY]
    # every 5th sample of 100 Hz, the t = 0 one first: 0, 50, ..., 200 ms
    assert [stamp_ns(m) for m in profiles] == [i * 50_000_000 for i in range(5)]
    rows = {round(m.data[F["sim_time_s"]] * 1e9): m.data for m in telemetry}
    info = json.loads(recorded(tmp_path / "run.mcap", topics.RUN_INFO)[0].data)["string"]
    depths = np.array(info["profile_depths_m"])
    assert len(depths) == 16 and np.all(np.diff(depths) > 0)
    length = info["length_m"]
    np.testing.assert_allclose(depths, (np.arange(16) + 0.5) * length / 16)
    for msg in profiles:
        assert list(msg.name) == [f"string_{d:06.1f}m" for d in depths]
        assert len(msg.velocity) == len(msg.effort) == 16 and not msg.position
        row = rows[stamp_ns(msg)]
        # the kinematic top turns at the surface speed, and so does the shallowest depth:
        # the string starts steady, and nothing from below reaches it in 0.2 s (the bit is
        # 0.85 s away); the deepest depth turns nearly with the BHA
        surface_rpm = row[F["surface_rpm"]]
        assert abs(msg.velocity[0] * RPM_PER_RAD_S - surface_rpm) < 1e-9 * surface_rpm
        assert abs(msg.velocity[-1] * RPM_PER_RAD_S - row[F["bha_rpm"]]) < 1.0
    # at t = 0 the string turns at the surface speed carrying the bit's torque plus the
    # viscous drag (rate x inertia x speed) of the string below each depth: all of it at
    # the shallowest depth (above the first damper), less with depth
    spec = load_preset(DEFAULT_PRESET).string
    omega = rows[0][F["surface_rpm"]] / RPM_PER_RAD_S
    drag_nm = sum(x.torsional_damping_per_s * x.inertia_kg_m2 for x in spec.sections) * omega
    effort = np.array(profiles[0].effort)
    assert effort[0] == pytest.approx(rows[0][F["tob_nm"]] + drag_nm, rel=1e-9)
    assert np.all(np.diff(effort) <= 1e-9 * effort[0]) and effort[-1] > rows[0][F["tob_nm"]]
    np.testing.assert_allclose(np.array(profiles[0].velocity) * RPM_PER_RAD_S,
                               rows[0][F["surface_rpm"]], rtol=1e-12)
    stored = recorded(tmp_path / "run.mcap", topics.STRING_TORSION)
    assert [stamp_ns(m) for m in stored] == [stamp_ns(m) for m in profiles]
    for a, b in zip(stored, profiles, strict=True):
        assert list(a.velocity) == list(b.velocity) and list(a.effort) == list(b.effort)


def test_lumped_string_and_rate_zero_publish_no_profiles(tmp_path) -> None:
    cases = ({"model__preset": "field_8p5in_shale_lumped"}, {"string__rate_hz": 0.0})
    for i, params in enumerate(cases):
        (tmp_path / str(i)).mkdir()
        got, published = stepped_run(tmp_path / str(i), **params)
        assert published == [] and got[topics.STRING_TORSION] == []
