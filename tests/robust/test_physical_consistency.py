"""Values that are each in range but impossible together (model.consistency) are refused at
load, from a preset file, a scenario's overrides, sim_node's parameters and `startup`'s
flags alike: one line naming both keys and their values (issue 52, point 1)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest
import yaml

from drill_sim_ros.model.errors import ParameterError
from drill_sim_ros.model.presets import load_preset, submerged_string_weight_n
from drill_sim_ros.ros.parameters import check_operating_point
from tests.robust.helpers import ROOT, one_error_line, run_cli

DEVIATED = "field_8p5in_deviated"
LUMPED = "field_8p5in_shale_lumped"


def _changed(tmp_path: Path, name: str, change: dict[str, dict[str, Any]]) -> Path:
    """Preset ``name`` with ``change`` = {section: {key: value}} merged in, as a file."""
    data = yaml.safe_load((ROOT / f"config/presets/{name}.yaml").read_text())
    for section, values in change.items():
        data[section].update(values)
    path = tmp_path / f"{name}_changed.yaml"
    path.write_text(yaml.safe_dump(data))
    return path


def _sections(density_kg_m3: float) -> dict[str, Any]:
    return {"sections": [
        {"outer_radius_m": 0.0635, "inner_radius_m": 0.0543, "length_m": 2500.0},
        {"outer_radius_m": 0.0857, "inner_radius_m": 0.0357, "length_m": 200.0,
         "density_kg_m3": density_kg_m3}]}


@pytest.mark.parametrize(("name", "change", "names"), [
    # the unit slip of the issue: g/cm3 for kg/m3
    (DEVIATED, {"physical": {"density_kg_m3": 7.85}},
     ("'physical.density_kg_m3' = 7.85", "'well.mud_density_kg_m3' = 1200", "g/cm3",
      "7850 kg/m3")),
    (DEVIATED, {"string": _sections(7.85)},
     ("'string.sections[1].density_kg_m3' = 7.85", "'well.mud_density_kg_m3' = 1200")),
    # lighter than the hook load's default mud, without a well (the 785)
    (LUMPED, {"physical": {"density_kg_m3": 785.0}},
     ("'physical.density_kg_m3' = 785", "MUD_DENSITY_KG_M3", "= 1200")),
    (DEVIATED, {"well": {"mud_density_kg_m3": 1.2}},
     ("'well.mud_density_kg_m3' = 1.2", "g/cm3", "0 for air")),
    (DEVIATED, {"physical": {"density_kg_m3": 78500.0}},
     ("'physical.density_kg_m3' = 78500", "denser than any")),
    (DEVIATED, {"physical": {"bit_radius_m": 0.08}},
     ("'string.sections[1].outer_radius_m' = 0.0857", "'physical.bit_radius_m' = 0.08")),
    (LUMPED, {"physical": {"bit_radius_m": 0.08}},
     ("'physical.bha_outer_radius_m' = 0.0857", "'physical.bit_radius_m' = 0.08")),
    (DEVIATED, {"physical": {"applied_wob_n": 2.0e6}},
     ("'physical.applied_wob_n' = 2e+06", "buoyed weight")),
    (DEVIATED, {"physical": {"surface_rpm": 5.0}},
     ("'physical.surface_rpm' = 5", "'well.side_friction.stick_speed_rad_s' = 0.9")),
    (DEVIATED, {"well": {"side_friction": {"stick_speed_rad_s": 0.5}}},
     ("'well.side_friction.stick_speed_rad_s' = 0.5", "no effect")),
    (LUMPED, {"physical": {"pipe_inner_radius_m": 0.07}},
     ("pipe_inner_radius_m", "0.07", "pipe_outer_radius_m")),
])
def test_an_impossible_preset_is_one_line_naming_both_keys(
        capsys: pytest.CaptureFixture[str], tmp_path: Path, name: str,
        change: dict[str, dict[str, Any]], names: tuple[str, ...]) -> None:
    path = _changed(tmp_path, name, change)
    rc, out, err = run_cli(capsys, "info", str(path))
    one_error_line(rc, err, str(path), *names)
    assert out == ""


def test_the_unit_slip_in_a_scenario_override_is_refused_before_the_run(
        capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    path = tmp_path / "slip.yaml"
    path.write_text(f"preset: {DEVIATED}\nduration_s: 5\nenable_at_s: 1\ncontroller: stiff\n"
                    "overrides: {physical: {density_kg_m3: 7.85}}\n")
    rc, out, err = run_cli(capsys, "closed-loop", "--scenario", str(path), "--no-baseline",
                           "--json")
    one_error_line(rc, err, "overrides", "'physical.density_kg_m3' = 7.85",
                   "'well.mud_density_kg_m3' = 1200", "g/cm3")
    assert out == ""


def test_startup_inside_the_stick_band_is_refused(capsys: pytest.CaptureFixture[str]) -> None:
    rc, out, err = run_cli(capsys, "startup", "--params", DEVIATED, "--rpm", "5",
                           "--seconds", "1")
    one_error_line(rc, err, "--rpm = 5", "'well.side_friction.stick_speed_rad_s' = 0.9")
    assert out == ""


def _sim_node_values(**changes: float) -> dict[str, float]:
    preset = load_preset(DEVIATED)
    values = {"model.submerged_string_weight_n": submerged_string_weight_n(preset),
              "model.applied_wob_n": 60e3, "model.surface_rpm": 35.0}
    return {**values, **changes}


@pytest.mark.parametrize(("changes", "names"), [
    ({"model.applied_wob_n": 1e6}, ("'model.applied_wob_n' = 1e+06", "buoyed weight")),
    ({"model.surface_rpm": 3.0}, ("'model.surface_rpm' = 3",
                                  "'well.side_friction.stick_speed_rad_s' = 0.9")),
])
def test_sim_node_start_values_against_the_string(changes: dict[str, float],
                                                  names: tuple[str, ...]) -> None:
    """The check sim_node's declare_all runs on the parameters in use."""
    with pytest.raises(ParameterError) as caught:
        check_operating_point(load_preset(DEVIATED), _sim_node_values(**changes))
    message = str(caught.value)
    assert "\n" not in message
    for name in names:
        assert name in message, (name, message)


def test_the_shipped_operating_points_pass() -> None:
    check_operating_point(load_preset(DEVIATED), _sim_node_values())
    check_operating_point(load_preset(DEVIATED), _sim_node_values(**{"model.surface_rpm": 0.0}))
