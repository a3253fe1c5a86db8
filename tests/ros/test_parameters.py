"""The parameter table: descriptors, validation reasons and preset-derived defaults."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from drill_sim_ros.control.bench import session_config, sim_node_parameters
from drill_sim_ros.control.scenario import Scenario
from drill_sim_ros.model.presets import load_preset, preset_from_dict, preset_path
from drill_sim_ros.model.session import SessionConfig, SimSession
from drill_sim_ros.model.telemetry import TELEMETRY_INDEX
from drill_sim_ros.model.top_drive import TopDrivePhysical, limit_of_setting, setting_of_limit
from drill_sim_ros.model.validate_input import read_preset_file
from drill_sim_ros.ros.parameters import (
    RUNTIME_DRIVE_PARAMETERS,
    SPEC_BY_NAME,
    SPECS,
    descriptor,
    submerged_string_weight_n,
    top_drive_of,
    validate,
    yaml_defaults,
)


def test_every_spec_has_a_description_and_numbers_have_a_range():
    for spec in SPECS:
        desc = descriptor(spec)
        assert desc.description
        if spec.kind == "double":
            assert desc.floating_point_range[0].from_value < desc.floating_point_range[0].to_value
        if spec.kind == "int":
            assert desc.integer_range


@pytest.mark.parametrize(("name", "value", "words"), [
    ("real_time_factor", -0.5, "outside"), ("real_time_factor", math.inf, "outside"),
    ("real_time_factor", "x", "number"), ("lockstep", 1, "true or false"),
    ("model.n_nodes", 2.5, "integer"), ("record.path", 3, "string")])
def test_bad_values_are_rejected_with_a_reason_naming_the_parameter(name, value, words):
    reason = validate(SPEC_BY_NAME[name], value)
    assert reason is not None and name in reason and words in reason


def test_integers_are_accepted_for_doubles():
    assert validate(SPEC_BY_NAME["run_seconds"], 10) is None


def test_submerged_weight_of_the_field_string_by_hand():
    # 2500 m of 5-in pipe (r 63.5/54.3 mm) + 200 m of 6.75-in collars (r 85.7/35.7 mm), steel
    # 7850 kg/m3 in 1200 kg/m3 mud.
    steel_m3 = math.pi * ((0.0635**2 - 0.0543**2) * 2500.0 + (0.0857**2 - 0.0357**2) * 200.0)
    expected = steel_m3 * 7850.0 * 9.80665 * (1.0 - 1200.0 / 7850.0)
    preset = load_preset("field_8p5in_shale_lumped")
    assert submerged_string_weight_n(preset) == pytest.approx(expected, rel=1e-12)
    assert submerged_string_weight_n(load_preset("fig5_8a")) == 0.0


def test_physical_defaults_come_from_the_preset():
    preset = load_preset("field_8p5in_shale_lumped")
    defaults = yaml_defaults(preset)
    assert defaults["model.applied_wob_n"] == pytest.approx(preset.physical.applied_wob_n)
    assert defaults["model.surface_rpm"] == pytest.approx(preset.physical.surface_rpm)


def test_the_drive_parameters_give_the_presets_drive_back() -> None:
    # sim_node's top_drive.* parameters default to the preset's SI drive and make it again,
    # field for field; the only mapping is the torque limit's 0 = none (a ROS double)
    for name in ("field_8p5in_shale", "field_8p5in_shale_lumped", "fig5_8a"):
        preset = load_preset(name)
        assert top_drive_of(yaml_defaults(preset)) == preset.drive, name
    unlimited = load_preset("fig5_8a")             # the paper's drive: no torque limit
    assert math.isinf(unlimited.drive.max_torque_nm)
    assert yaml_defaults(unlimited)["top_drive.max_torque_nm"] == 0.0
    assert yaml_defaults(unlimited)["top_drive.max_torque_rate_nm_s"] == 0.0
    assert limit_of_setting(0.0) == math.inf and setting_of_limit(math.inf) == 0.0
    assert limit_of_setting(setting_of_limit(8000.0)) == 8000.0


def test_every_drive_field_but_the_inertia_may_change_at_runtime() -> None:
    every = {f"top_drive.{f.name}" for f in dataclasses.fields(TopDrivePhysical)}
    assert every - {"top_drive.inertia_kg_m2"} == RUNTIME_DRIVE_PARAMETERS
    assert SPEC_BY_NAME["top_drive.inertia_kg_m2"].read_only      # fixed for a session


@pytest.mark.parametrize("drive", [{}, {"max_torque_nm": 8000.0}, {"motor_lag_s": 0.05},
                                   {"max_torque_nm": 20e3, "motor_lag_s": 0.01},
                                   {"max_torque_rate_nm_s": 2e6},
                                   {"max_torque_rate_nm_s": 0.0, "motor_lag_s": 0.0}])
@pytest.mark.parametrize("mode", ["speed", "torque"])
def test_the_bench_runs_the_drive_sim_node_makes_of_its_parameters(drive, mode) -> None:
    # two roads to one drive: sim_node's parameters for a scenario (over the preset's
    # defaults) and the in-process bench's session, built without them
    scenario = Scenario(preset="field_8p5in_shale_lumped", mode=mode, drive=drive)
    preset = scenario.load_preset()
    values = {**yaml_defaults(load_preset(scenario.preset)),
              **sim_node_parameters(scenario, preset)}
    assert session_config(scenario, preset).top_drive == top_drive_of(values)


def limit_off_the_round_trip(torque_unit_nm: float) -> float:
    """A torque limit (N m) that SI -> scaled -> SI does not give back bit for bit."""
    return next(x for x in (50_000.0 + 0.1 * i for i in range(1, 1000))
                if (x / torque_unit_nm) * torque_unit_nm != x)


def test_the_torque_limit_is_converted_once_and_clipped_once_on_either_road() -> None:
    # issue 48: a preset's max_torque_nm and sim_node's top_drive.max_torque_nm reach the
    # kernel through the one division by C, and the drive's step is the one clip
    name = "field_8p5in_shale_lumped"
    data = read_preset_file(preset_path(name))
    limit_nm = limit_off_the_round_trip(load_preset(name).scales.torque_nm)
    data["top_drive"]["max_torque_nm"] = limit_nm
    preset = preset_from_dict(name, data)
    assert preset.drive.max_torque_nm == limit_nm            # as the file gives it
    scaled = limit_nm / preset.scales.torque_nm
    values = {**yaml_defaults(preset), "top_drive.mode": "torque",
              "top_drive.motor_lag_s": 0.0, "top_drive.max_torque_rate_nm_s": 0.0}
    assert values["top_drive.max_torque_nm"] == limit_nm
    roads = {"preset": SimSession(SessionConfig(preset=preset)),
             "parameter": SimSession(SessionConfig(preset=preset, top_drive=top_drive_of(values)))}
    for road, session in roads.items():
        assert session.sim.top_drive.max_torque == scaled, road
    session = roads["parameter"]                 # no lag, no rate limit: the clip alone
    session.set_motor_torque_nm(3.0 * limit_nm)
    motor_nm = session.run(2).rows[1:, TELEMETRY_INDEX["motor_torque_nm"]]
    assert np.all(motor_nm == scaled * preset.scales.torque_nm)    # the limit, once clipped
