"""The parameter table: descriptors, validation reasons and preset-derived defaults."""

from __future__ import annotations

import math

import pytest

from drill_sim_ros.model.presets import load_preset
from drill_sim_ros.ros.parameters import (
    SPEC_BY_NAME,
    SPECS,
    descriptor,
    submerged_string_weight_n,
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
