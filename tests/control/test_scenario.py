"""Scenario files and setpoint schedules: by hand, round trip, errors that name the input."""

from __future__ import annotations

import pytest

from drill_sim_ros.control.bench import run_in_process
from drill_sim_ros.control.rig import rig_physics
from drill_sim_ros.control.scenario import (
    load_scenario,
    save_scenario,
    scenario_from_dict,
    scenario_path,
)
from drill_sim_ros.control.schedule import schedule_from_list
from drill_sim_ros.model.errors import ParameterError


def test_steps_and_ramps() -> None:
    s = schedule_from_list([{"t_s": 0, "rpm": 50}, {"t_s": 10, "rpm": 70},
                            {"t_s": 20, "rpm": 90, "ramp_s": 10}, {"t_s": 25, "wob_n": 1e3}],
                           60.0, 5e4)
    assert [s.rpm_at(t) for t in (0, 9.99, 10, 20, 25, 30, 99)] == \
        pytest.approx([50, 50, 70, 70, 80, 90, 90])
    assert s.wob_at(24.9) == 5e4 and s.wob_at(25) == 1e3


def test_round_trip(tmp_path) -> None:
    scenario = scenario_from_dict({"controller": "z_torque", "mode": "torque",
                                   "duration_s": 30, "enable_at_s": 5,
                                   "params": {"impedance_nm_s": 250.0},
                                   "schedule": [{"t_s": 10, "rpm": 70, "ramp_s": 2}],
                                   "sensors": {"seed": 4,
                                               "string_torque_nm": {"noise_std": 10.0}}})
    path = tmp_path / "s.yaml"
    save_scenario(scenario, path)
    assert load_scenario(path) == scenario
    assert scenario.rig_sensors().seed == 4
    assert scenario.periods == 3000


@pytest.mark.parametrize(("data", "names"), [
    ({"controler": "stiff"}, "controler"),
    ({"duration_s": -1}, "duration_s"),
    ({"duration_s": 10, "enable_at_s": 20}, "enable_at_s"),
    ({"schedule": [{"t_s": 10, "rpm": 1}, {"t_s": 5, "rpm": 2}]}, "t_s"),
    ({"schedule": [{"t_s": 0, "rpm": -3}]}, "rpm"),
    ({"sensors": {"bit_rpm": {"noise_std": 1}}}, "bit_rpm"),
])
def test_errors_name_the_bad_input(data, names) -> None:
    with pytest.raises(ParameterError, match=names):
        scenario = scenario_from_dict(data)
        scenario.setpoints(scenario.load_preset())
        scenario.rig_sensors()


def test_off_bottom_is_an_action_at_its_time() -> None:
    s = schedule_from_list([{"t_s": 0, "rpm": 0, "off_bottom": True},
                            {"t_s": 1, "rpm": 60, "ramp_s": 10},
                            {"t_s": 40, "off_bottom": False},
                            {"t_s": 50, "off_bottom": True}], 35.0, 6e4)
    assert [s.off_bottom_at(t) for t in (0, 39.99, 40, 42, 49.9, 50, 99)] == \
        [True, True, False, False, False, True, True]
    assert s.rpm_at(6.0) == pytest.approx(30.0)          # the rpm ramps; the action does not
    assert not schedule_from_list([{"t_s": 3, "rpm": 50}], 35.0, 6e4).off_bottom_at(9.0)


@pytest.mark.parametrize("value", [1, "yes", None])
def test_off_bottom_must_be_true_or_false(value) -> None:
    with pytest.raises(ParameterError, match=r"'schedule\[0\].off_bottom' = .* must be true or "
                                             "false"):
        schedule_from_list([{"t_s": 5, "off_bottom": value}], 35.0, 6e4)


def test_the_lumped_first_mode_scenario_ranks_the_controllers() -> None:
    """The league's ranking scenario (docs/league.md): on RGD07's lumped string the stiff
    drive lets the first-mode stick-slip through, with the period field stick-slip has
    (0.8-2.5 T1, T1 from the rig's own first mode), and the two soft drives end it
    without touching their torque limit."""
    base = load_scenario(scenario_path("lumped_first_mode"))
    t1_s = 1.0 / rig_physics(base.load_preset()).torsional_modes_hz[0]
    cards = {controller: run_in_process(base.with_(controller=controller)).score()
             for controller in ("stiff", "soft_torque", "z_torque")}
    stiff = cards.pop("stiff")
    assert stiff["status"] == "stick-slip" and stiff["ssi_mean"] >= 0.8
    assert 0.8 * t1_s <= stiff["period_s"] <= 2.5 * t1_s
    for name, card in cards.items():
        assert card["status"] == "ok", name
        assert card["ssi_last"] <= 0.15, name
        assert card["saturation_fraction"] <= 0.05, name


def test_overrides_of_a_preset_naming_a_survey_file_build_from_any_directory(
        tmp_path, monkeypatch) -> None:
    """The survey CSV is named relative to the preset's directory, not the working one."""
    monkeypatch.chdir(tmp_path)
    scenario = scenario_from_dict({"preset": "field_8p5in_build_turn",
                                   "overrides": {"physical": {"surface_rpm": 45.0}}})
    preset = scenario.load_preset()
    assert preset.physical.surface_rpm == 45.0
    assert len(preset.string.well.survey.md_m) > 2       # the CSV's stations
