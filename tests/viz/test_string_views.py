"""The string views of the dashboard: a run of the distributed field preset (the real
session), written as MCAP by mcap_ros2's Writer with drill/string/torsion JointStates,
through mcap_to_rerun, read back by rerun's own reader: the bar charts, and the depth x time
picture's layout, its colours centred on the mean speed, its depth axis and colour bar."""

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
from drill_sim_ros.viz import entities as ent
from drill_sim_ros.viz.string_views import (
    FRAME_BOUNDS,
    IMAGE_PROFILES,
    LABEL_DROP,
    MIDDLE_COLOUR,
    NO_DATA,
    PICTURE_HEIGHT,
    ColourScale,
    palette,
)
from tests.viz import expected as ex
from tests.viz.rrd_read import read_recording, view_bounds, view_origins
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
            "data": read_recording(rrd), "info": sim.run_info()}


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


def images(data) -> tuple[np.ndarray, list[np.ndarray]]:
    """The stamps and RGB arrays of an image entity's rows (rows without an image left out)."""
    rows = [(t, fmt[0], buf[0]) for t, fmt, buf in zip(
        data.time_ns, data.columns["Image:format"], data.columns["Image:buffer"], strict=True)
        if buf is not None]
    return np.array([t for t, _, _ in rows]), [
        np.frombuffer(bytes(buf), dtype=np.uint8).reshape(fmt["height"], fmt["width"], 3)
        for _, fmt, buf in rows]


def window_rpm(run: dict, image_ns: int) -> np.ndarray:
    """(depths, profiles) speeds rpm of the profiles an image at ``image_ns`` shows: the last
    IMAGE_PROFILES up to it."""
    shown = [s for s in run["strings"] if s.stamp_ns <= image_ns][-IMAGE_PROFILES:]
    return np.array([s.speed_rad_s for s in shown]).T * RPM_PER_RAD_S


def test_depth_time_picture_rows_are_depths_columns_the_last_profiles(run: dict) -> None:
    stamps, pictures = images(run["data"][ent.STRING_PICTURE])
    times_s = stamps * 1e-9
    assert len(times_s) == pytest.approx(SECONDS, abs=1)           # one per second
    assert np.all(np.diff(times_s) >= 1.0 - 1e-9)
    image = pictures[-1]
    assert image.shape == (len(run["depths"]), IMAGE_PROFILES, 3)
    shown = window_rpm(run, int(stamps[-1]))
    assert shown.shape[1] == IMAGE_PROFILES
    scale = ColourScale.of(shown)
    np.testing.assert_array_equal(image[:, -1], scale.colours(shown[:, -1]))
    np.testing.assert_array_equal(image[:, 0], scale.colours(shown[:, 0]))
    assert pictures[0].shape == (len(run["depths"]), IMAGE_PROFILES, 3)
    assert np.all(pictures[0][:, :-1] == NO_DATA)                      # t = 0 only
    # the rows are scaled to the frame's height, whatever the number of depths
    scales = [v[0] for v in run["data"][ent.STRING_PICTURE].columns["Transform3D:scale"]
              if v is not None]
    assert scales == [pytest.approx([1.0, PICTURE_HEIGHT / len(run["depths"]), 1.0])]


def test_depth_time_colours_are_centred_on_the_mean_speed(run: dict) -> None:
    """White (the middle colour) where the speed is the mean of the profiles shown, blue
    where it is well below it, red where well above; the colour bar's middle label is the
    mean, and its middle row the middle colour."""
    stamps, pictures = images(run["data"][ent.STRING_PICTURE])
    for stamp, image in zip(stamps[-10:], pictures[-10:], strict=True):
        shown = window_rpm(run, int(stamp))
        picture = image[:, IMAGE_PROFILES - shown.shape[1]:].astype(np.int64)
        deviation = shown - shown.mean()
        reach = np.abs(deviation).max()
        assert reach > 5.0                          # the string is not steady here
        near = np.abs(deviation) < 0.01 * reach
        assert near.sum() > 10
        assert np.abs(picture[near] - MIDDLE_COLOUR).max() <= 6
        red, blue = picture[..., 0], picture[..., 2]
        slow, fast = deviation < -0.3 * reach, deviation > 0.3 * reach
        assert slow.any() and fast.any()
        assert np.all(blue[slow] > red[slow]) and np.all(red[fast] > blue[fast])
    labels = run["data"][ent.STRING_SCALE_LABELS]
    values = labels.columns["Points2D:labels"][-1]
    assert values[-1] == "rpm"
    ticks = np.array([float(v) for v in values[:-1]])                # fast at the top
    assert np.all(np.diff(ticks) < 0)
    assert ticks[len(ticks) // 2] == pytest.approx(window_rpm(run, int(stamps[-1])).mean(),
                                                   abs=0.5)           # labels to 1 rpm
    np.testing.assert_allclose(ticks - ticks[len(ticks) // 2],
                               -(ticks[::-1] - ticks[len(ticks) // 2]), atol=1.0)
    bar = images(run["data"][ent.STRING_COLOUR_BAR])[1][-1]
    assert tuple(bar[len(bar) // 2, 0]) == MIDDLE_COLOUR
    assert bar[0, 0, 0] > bar[0, 0, 2] and bar[-1, 0, 2] > bar[-1, 0, 0]   # red top, blue


def test_depth_time_view_has_a_depth_axis_in_metres(run: dict) -> None:
    """Tick labels in m at their depths below the top of the string (its length from the
    preset's sections), the axis titled, and the view framed by FRAME_BOUNDS."""
    length_m = sum(section["length_m"] for section in run["info"]["string"]["sections"])
    axis = run["data"][ent.STRING_DEPTH_AXIS]
    labels = axis.columns["Points2D:labels"][-1]
    positions = np.array(axis.columns["Points2D:positions"][-1])
    assert labels[-1] == "depth [m]"
    depths = np.array([float(v) for v in labels[:-1]])
    assert labels[0] == "0" and depths[-1] <= length_m and len(depths) >= 4
    np.testing.assert_allclose(positions[:-1, 1] + LABEL_DROP,
                               depths / length_m * PICTURE_HEIGHT, atol=1e-3)
    assert np.all(positions[:-1, 0] < 0.0)                             # left of the picture
    bounds = view_bounds(run["rrd"])[ent.STRING_DEPTH_TIME]
    assert bounds == (pytest.approx(list(FRAME_BOUNDS[0])), pytest.approx(list(FRAME_BOUNDS[1])))


def test_the_palette_diverges_from_white() -> None:
    """Dark blue at 0, white in the middle, dark red at 1; clamped beyond; the luminance
    falls from the middle to both ends, which are both dark (a diverging map)."""
    ends = palette(np.array([0.0, 0.5, 1.0, -3.0, 7.0]))
    np.testing.assert_array_equal(ends, [(5, 48, 97), MIDDLE_COLOUR, (103, 0, 31),
                                         (5, 48, 97), (103, 0, 31)])
    assert MIDDLE_COLOUR == (247, 247, 247)
    steps = np.linspace(0.0, 0.5, 26)
    lightness = palette(np.concatenate((0.5 - steps, 0.5 + steps))).astype(float) @ (
        0.2126, 0.7152, 0.0722)
    below, above = lightness[:26], lightness[26:]
    assert np.all(np.diff(below) <= 0) and np.all(np.diff(above) <= 0)
    assert max(below[-1], above[-1]) < 0.2 * below[0]
    halfway = palette(np.array([0.05]))[0]                  # between the first two stops
    np.testing.assert_array_equal(halfway, [19, 75, 134])
    scale = ColourScale(centre_rpm=60.0, half_span_rpm=20.0)
    np.testing.assert_array_equal(scale.colours(np.array([40.0, 60.0, 80.0, 200.0])),
                                  palette(np.array([0.0, 0.5, 1.0, 1.0])))
