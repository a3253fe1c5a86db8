"""The well path from a survey (model.survey, model.well's reader): minimum curvature
against closed forms of circular arcs, the old 2-D form, a survey CSV, and each bad survey
refused in one line naming the row and the column (the CSV: the file and its line)."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml

from drill_sim_ros.model.errors import ParameterError
from drill_sim_ros.model.presets import load_preset, preset_path
from drill_sim_ros.model.survey import Survey, read_survey_csv
from drill_sim_ros.model.well import well_from_dict


def test_a_build_is_a_circular_arc() -> None:
    """Vertical to 100 m, then 0 to 90 deg over 300 m at constant azimuth 30 deg: an arc of
    radius R = 300 / (pi / 2); at an angle a into it the depth is 100 + R sin a and the
    departure R (1 - cos a), along azimuth 30 deg (east = sin 30 deg of it)."""
    survey = Survey(((0.0, 0.0, 30.0), (100.0, 0.0, 30.0), (400.0, 90.0, 30.0)))
    radius = 300.0 / (math.pi / 2)
    md = np.linspace(100.0, 400.0, 31)
    angle = (md - 100.0) / radius
    pos = survey.positions_m(md)
    departure = radius * (1.0 - np.cos(angle))
    np.testing.assert_allclose(pos[:, 2], 100.0 + radius * np.sin(angle), atol=1e-9)
    np.testing.assert_allclose(pos[:, 0], departure * math.sin(math.radians(30)), atol=1e-9)
    np.testing.assert_allclose(pos[:, 1], departure * math.cos(math.radians(30)), atol=1e-9)
    assert survey.dogleg_severity_deg_per_30m() == pytest.approx([0.0, 9.0], abs=1e-12)


def test_the_curvature_vector_is_the_tangents_derivative() -> None:
    """dt/ds against central differences of the tangent on a build-and-turn leg; its size
    is the leg's dog-leg over its length, and in a build it points up (to the high side)."""
    survey = Survey(((0.0, 0.0, 0.0), (300.0, 20.0, 40.0), (600.0, 60.0, 120.0)))
    md, h = np.array([150.0, 350.0, 450.0, 590.0]), 1e-3
    numeric = (survey.tangent(md + h) - survey.tangent(md - h)) / (2.0 * h)
    np.testing.assert_allclose(survey.curvature_vector(md), numeric, atol=1e-8)
    dls = survey.dogleg_severity_deg_per_30m()
    size = np.linalg.norm(survey.curvature_vector(md), axis=1)
    np.testing.assert_allclose(size, np.radians(dls[[0, 1, 1, 1]]) / 30.0, rtol=1e-9)
    build = Survey(((0.0, 10.0, 0.0), (300.0, 40.0, 0.0)))
    assert build.curvature_vector(np.array([150.0]))[0, 2] < 0.0


def test_past_the_last_station_the_path_is_straight() -> None:
    survey = Survey(((0.0, 0.0, 0.0), (500.0, 30.0, 90.0)))
    inc, azi = survey.attitude_rad(np.array([600.0, 900.0]))
    np.testing.assert_allclose(np.degrees(inc), 30.0)
    np.testing.assert_allclose(np.degrees(azi), 90.0)
    assert np.all(survey.curvature_vector(np.array([600.0])) == 0.0)
    step = survey.positions_m(np.array([900.0])) - survey.positions_m(np.array([600.0]))
    np.testing.assert_allclose(step[0], 300.0 * survey.tangent(np.array([700.0]))[0])


def test_the_old_form_is_a_2d_well_linear_in_inclination() -> None:
    """{md_m, inclination_deg} stations: azimuth 0, and minimum curvature in one vertical
    plane is an arc whose inclination is linear in measured depth between stations."""
    well = well_from_dict({"survey": [{"md_m": 0, "inclination_deg": 0},
                                      {"md_m": 300, "inclination_deg": 0},
                                      {"md_m": 700, "inclination_deg": 40},
                                      {"md_m": 1250, "inclination_deg": 45}]})
    assert well.survey.two_dimensional
    md = np.linspace(0.0, 1250.0, 501)
    linear = np.radians(np.interp(md, [0, 300, 700, 1250], [0, 0, 40, 45]))
    np.testing.assert_allclose(well.survey.attitude_rad(md)[0], linear, atol=1e-12)


def test_a_preset_names_a_survey_csv_beside_it() -> None:
    preset = load_preset("field_8p5in_build_turn")
    well = preset.string.well
    assert well is not None
    text = (preset_path("field_8p5in_build_turn").parent
            / "field_8p5in_build_turn_survey.csv").read_text().splitlines()
    rows = [tuple(float(x) for x in line.split(",")) for line in text[1:]]
    assert well.survey.stations == tuple(rows)
    assert max(well.survey.dogleg_severity_deg_per_30m()) > 4.0


GOOD = "md_m,inclination_deg,azimuth_deg\n0,0,0\n500,10,45\n1000,30,60\n"
BAD_CSV = [
    ("md_m,inclination_deg,azimuth_deg\n0,0,0\n500,10,45\n400,30,60\n",
     ["line 4 column md_m", "= 400 must be greater than the station before (500)"]),
    ("md_m,inclination_deg,azimuth_deg\n0,0,0\n500,190,45\n",
     ["line 3 column inclination_deg", "'190'", "[0, 180]"]),
    ("md_m,inclination_deg,azimuth_deg\n0,0,0\n500,10,-5\n",
     ["line 3 column azimuth_deg", "'-5'", "[0, 360]"]),
    ("md_m,inclination_deg,azimuth_deg\n0,0,0\n500,10,361\n",
     ["line 3 column azimuth_deg", "'361'", "[0, 360]"]),
    ("md_m,azimuth_deg\n0,0\n500,10\n", ["line 1: missing column(s) inclination_deg"]),
    ("md_m,inclination_deg,azimuth_deg\n0,0,0\n500,nan,45\n",
     ["line 3 column inclination_deg", "'nan' is not a number"]),
    ("md_m,inclination_deg,azimuth_deg\n0,0,0\n500,ten,45\n",
     ["line 3 column inclination_deg", "'ten' is not a number"]),
    ("md_m,inclination_deg,azimuth_deg\n0,0,0\n500,,45\n",
     ["line 3 column inclination_deg is missing"]),
    ("md_m,inclination_deg,azimuth_deg\n0,0,0\n\n500,10\n",
     ["line 4 column azimuth_deg"]),
    ("md_m,inclination_deg,azimuth_deg\n10,0,0\n500,10,45\n",
     ["line 2 column md_m", "must be 0"]),
    ("md_m,inclination_deg,azimuth_deg\n", ["has no stations"]),
]


def test_a_good_csv_loads(tmp_path: Path) -> None:
    path = tmp_path / "survey.csv"
    path.write_text(GOOD)
    assert read_survey_csv(path).stations == ((0.0, 0.0, 0.0), (500.0, 10.0, 45.0),
                                              (1000.0, 30.0, 60.0))


@pytest.mark.parametrize(("text", "pieces"), BAD_CSV)
def test_a_bad_csv_is_one_line_naming_file_line_and_column(tmp_path: Path, text: str,
                                                           pieces: list[str]) -> None:
    """A short last row has no azimuth (None): that too is named, not taken as 0."""
    path = tmp_path / "survey.csv"
    path.write_text(text)
    message = _one_line(lambda: read_survey_csv(path))
    assert str(path) in message
    for piece in pieces:
        assert piece in message, (piece, message)


def test_a_missing_csv_is_named(tmp_path: Path) -> None:
    message = _one_line(lambda: well_from_dict({"survey": "nowhere.csv"}, tmp_path))
    assert str(tmp_path / "nowhere.csv") in message and "cannot read it" in message


BAD_LIST = [
    ([{"md_m": 0, "inclination_deg": 0, "azimuth_deg": 400}],
     ["'well.survey[0].azimuth_deg' = 400", "[0, 360]"]),
    ([{"md_m": 0, "inclination_deg": 0}, {"md_m": 100, "inclination_deg": float("nan")}],
     ["'well.survey[1].inclination_deg' = nan is not a number"]),
    ([{"md_m": 0, "inclination_deg": 0}, {"md_m": "x", "inclination_deg": 3}],
     ["'well.survey[1].md_m' = 'x' is not a number"]),
    ([{"md_m": 0, "inclination_deg": 0}, {"md_m": 100, "inclination_deg": -1}],
     ["'well.survey[1].inclination_deg' = -1 is out of range", "[0, 180]"]),
    ([{"md_m": 0, "inclination_deg": 0}, {"md_m": 50, "inclination_deg": 1},
      {"md_m": 20, "inclination_deg": 3}],
     ["'well.survey[2].md_m' = 20 must be greater than the station before (50)"]),
    ([{"inclination_deg": 0}], ["'well.survey[0].md_m' is missing"]),
    (["0, 0, 0"], ["'well.survey[0]' must be a mapping"]),
]


@pytest.mark.parametrize(("survey", "pieces"), BAD_LIST)
def test_a_bad_survey_list_is_one_line_naming_row_and_column(survey: list[Any],
                                                             pieces: list[str]) -> None:
    message = _one_line(lambda: well_from_dict({"survey": survey}))
    for piece in pieces:
        assert piece in message, (piece, message)


def test_a_bad_csv_in_a_preset_is_named_with_the_preset(tmp_path: Path) -> None:
    data = yaml.safe_load(preset_path("field_8p5in_build_turn").read_text())
    data["well"]["survey"] = "bad.csv"
    (tmp_path / "bad.csv").write_text("md_m,inclination_deg,azimuth_deg\n0,0,0\n9,200,0\n")
    path = tmp_path / "mine.yaml"
    path.write_text(yaml.safe_dump(data))
    message = _one_line(lambda: load_preset(str(path)))
    assert str(path) in message and "bad.csv line 3 column inclination_deg" in message


def _one_line(call: Any) -> str:
    with pytest.raises(ParameterError) as err:
        call()
    message = str(err.value)
    assert "\n" not in message
    return message
