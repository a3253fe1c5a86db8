"""The string views of the dashboard: a run of the distributed field preset (the real
session), written as MCAP by mcap_ros2's Writer with drill/string/torsion JointStates,
through mcap_to_rerun, read back by rerun's own reader."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from mcap_ros2.writer import Writer

from drill_sim_ros import topics
from drill_sim_ros.model.params import RPM_PER_RAD_S
from drill_sim_ros.model.presets import load_preset
from drill_sim_ros.model.session import SessionConfig, SimSession
from drill_sim_ros.viz.string_views import IMAGE_PROFILES, speed_colors
from tests.viz import expected as ex
from tests.viz.rrd_read import read_recording, view_origins
from tests.viz.sim_telemetry import FLOAT64_MULTI_ARRAY_DEF, SEPARATOR, telemetry_message

SECONDS = 40.0
FIELD = "field_8p5in_shale"
STRING_VIEWS = {"/string/depth_time", "/string/speed", "/string/torque"}
JOINT_STATE_DEF = (
    "std_msgs/Header header\nstring[] name\nfloat64[] position\nfloat64[] velocity\n"
    f"float64[] effort\n{SEPARATOR}\nMSG: std_msgs/Header\nbuiltin_interfaces/Time stamp\n"
    f"string frame_id\n{SEPARATOR}\nMSG: builtin_interfaces/Time\nint32 sec\n"
    "uint32 nanosec\n")


def field_run() -> tuple[np.ndarray, list, SimSession]:
    sim = SimSession(SessionConfig(preset=load_preset(FIELD),
                                   string_rate_hz=10.0, perturb_v=1e-2))
    first = sim.current()
    block = sim.run(round(SECONDS * 100))
    return np.vstack((first.rows, block.rows)), first.strings + block.strings, sim


def write(path: Path, rows: np.ndarray, strings: list, sim: SimSession) -> None:
    with open(path, "wb") as stream:
        writer = Writer(stream)
        info = writer.register_msgdef("std_msgs/msg/String", "string data\n")
        writer.write_message(topics.RUN_INFO, info, {"data": json.dumps(sim.run_info())},
                             log_time=0, publish_time=0)
        tele = writer.register_msgdef("std_msgs/msg/Float64MultiArray",
                                      FLOAT64_MULTI_ARRAY_DEF)
        joints = writer.register_msgdef("sensor_msgs/msg/JointState", JOINT_STATE_DEF)
        for row in rows:
            stamp = round(row[0] * 1e9)
            writer.write_message(topics.TELEMETRY, tele, telemetry_message(row),
                                 log_time=stamp, publish_time=stamp)
        for s in strings:
            header = {"stamp": {"sec": s.stamp_ns // 10**9, "nanosec": s.stamp_ns % 10**9},
                      "frame_id": ""}
            writer.write_message(topics.STRING_TORSION, joints, {
                "header": header, "name": sim.string_names, "position": [],
                "velocity": s.speed_rad_s.tolist(), "effort": s.torque_nm.tolist()},
                log_time=s.stamp_ns, publish_time=s.stamp_ns)
        writer.finish()


@pytest.fixture(scope="module")
def run(tmp_path_factory: pytest.TempPathFactory) -> dict:
    tmp = tmp_path_factory.mktemp("string_views")
    rows, strings, sim = field_run()
    mcap, rrd = tmp / "field.mcap", tmp / "field.rrd"
    write(mcap, rows, strings, sim)
    exe = Path(sys.prefix) / "bin" / "mcap_to_rerun"
    proc = subprocess.run([str(exe), str(mcap), "-o", str(rrd)], capture_output=True,
                          text=True, timeout=300, check=False)
    assert proc.returncode == 0, proc.stderr
    return {"rows": rows, "strings": strings, "depths": sim.string_depths_m, "rrd": rrd,
            "data": read_recording(rrd)}


def tensor(value: list) -> np.ndarray:
    return np.array(value[0]["buffer"], dtype=np.float64).reshape(value[0]["shape"])


def test_blueprint_has_the_string_views_beside_the_others(run: dict) -> None:
    origins = set(view_origins(run["rrd"]).values())
    assert origins == ex.VIEW_ORIGINS | STRING_VIEWS


def test_bar_charts_hold_every_profile_in_display_units_over_depth(run: dict) -> None:
    stamps = np.array([s.stamp_ns for s in run["strings"]])
    assert len(stamps) == SECONDS * 10 + 1
    for path, values, factor in (("/string/speed", "speed_rad_s", RPM_PER_RAD_S),
                                 ("/string/torque", "torque_nm", 1e-3)):
        data = run["data"][path]
        np.testing.assert_array_equal(data.time_ns, stamps)
        got = np.array([tensor(v) for v in data.columns["BarChart:values"]])
        want = np.array([getattr(s, values) for s in run["strings"]]) * factor
        np.testing.assert_allclose(got, want, rtol=1e-6)       # stored as float64 tensors
        np.testing.assert_allclose(tensor(data.columns["BarChart:abscissa"][-1]),
                                   np.round(run["depths"], 1))   # the names: 0.1 m


def test_depth_time_picture_rows_are_depths_columns_the_last_profiles(run: dict) -> None:
    data = run["data"]["/string/depth_time"]
    times_s = data.time_ns * 1e-9
    assert len(times_s) == pytest.approx(SECONDS, abs=1)           # one per second
    assert np.all(np.diff(times_s) >= 1.0 - 1e-9)
    fmt = data.columns["Image:format"][-1][0]
    image = np.frombuffer(bytes(data.columns["Image:buffer"][-1][0]), dtype=np.uint8)
    image = image.reshape(fmt["height"], fmt["width"], 3)
    assert image.shape == (len(run["depths"]), IMAGE_PROFILES, 3)
    by_stamp = {s.stamp_ns: s for s in run["strings"]}
    last = by_stamp[int(data.time_ns[-1])]
    full_scale = 2.0 * load_preset(FIELD).physical.surface_rpm    # twice the preset's speed
    np.testing.assert_array_equal(image[:, -1], speed_colors(last.speed_rad_s * RPM_PER_RAD_S,
                                                             full_scale))
    first = data.columns["Image:format"][0][0]
    assert (first["width"], first["height"]) == (IMAGE_PROFILES, len(run["depths"]))
    first_image = np.frombuffer(bytes(data.columns["Image:buffer"][0][0]), dtype=np.uint8)
    assert np.all(first_image.reshape(first["height"], -1, 3)[:, :-1] == 255)   # t = 0 only
    earlier = by_stamp[int(data.time_ns[-1]) - 100_000_000 * (IMAGE_PROFILES - 1)]
    np.testing.assert_array_equal(image[:, 0], speed_colors(
        earlier.speed_rad_s * RPM_PER_RAD_S, full_scale))


def test_colour_scale_stops_and_clamping() -> None:
    stops = [(0, 0, 110), (30, 80, 220), (0, 200, 230), (60, 190, 60), (245, 225, 40),
             (230, 50, 30), (120, 0, 0)]           # dark blue .. dark red, evenly spaced
    at_stops = speed_colors(np.linspace(0.0, 150.0, 7), 150.0)
    np.testing.assert_array_equal(at_stops, stops)
    np.testing.assert_array_equal(speed_colors(np.array([-10.0, 900.0]), 150.0),
                                  [stops[0], stops[-1]])
    halfway = speed_colors(np.array([12.5]), 150.0)[0]          # between the first two
    np.testing.assert_array_equal(halfway, [15, 40, 165])
