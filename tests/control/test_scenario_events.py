"""Scenario events on the bench, each checked at the time it must take effect:

- the drive's speed ramp and WOB rate limits: a step of the setpoint becomes a ramp of the
  given slope, from the period the command arrives (the kinematics of a rate limit);
- the motor torque limit: below the trivial torque on bit T0 (RGD07: at steady state the bit
  torque is set by the WOB, whatever the speed) the drive cannot turn the bit: it stalls, and
  the scorecard says when, never a null;
- the command transport delay: a whole number of periods is the same as the controller
  sending its commands that many periods late (bit for bit); a fraction f of a period moves
  a motor torque step by f P inside the period, so the drive's speed gained over that period
  is (1 - f) of the undelayed gain (J d omega / dt = tau_m - T, the string torque nearly
  constant over 10 ms);
- features of the model core not there yet refuse to run with one line naming them.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from drill_sim_ros.control.bench import Bench, run_in_process
from drill_sim_ros.control.command import Command, SurfaceMeasurement
from drill_sim_ros.control.rig import rig_physics
from drill_sim_ros.control.scenario import Scenario, scenario_from_dict
from drill_sim_ros.control.scorecard import score
from drill_sim_ros.model import analysis
from drill_sim_ros.model.errors import ParameterError
from drill_sim_ros.model.presets import load_preset
from drill_sim_ros.model.telemetry import TELEMETRY_INDEX as F

PRESET = load_preset("field_8p5in_shale_lumped")
PERIOD_S = 0.01
# a sample is what the next integrator step records at its start: a ramp is one step ahead
STEP_S = PERIOD_S / Bench(Scenario(preset="field_8p5in_shale_lumped")).session.steps


def times(rows: np.ndarray) -> np.ndarray:
    return rows[:, F["sim_time_s"]]


def test_speed_ramp_limit_turns_a_step_into_a_ramp() -> None:
    rows = run_in_process(
        Scenario(
            preset="field_8p5in_shale_lumped",
            controller="none",
            duration_s=10.0,
            enable_at_s=0.0,
            schedule=({"t_s": 2.0, "rpm": 90.0},),
            drive={"accel_rpm_s": 10.0},
        )
    ).rows
    t, setpoint = times(rows), rows[:, F["speed_setpoint_rpm"]]
    expected = np.clip(60.0 + 10.0 * (t - 2.0), 60.0, 90.0)  # from the 2.00 s command
    np.testing.assert_allclose(setpoint, expected, rtol=0, atol=10.0 * STEP_S * 1.001)
    assert setpoint[t <= 2.0 + 1e-9].max() == pytest.approx(60.0)


def test_wob_rate_limit_turns_a_step_into_a_ramp() -> None:
    rows = run_in_process(
        Scenario(
            preset="field_8p5in_shale_lumped",
            controller="none",
            duration_s=20.0,
            enable_at_s=0.0,
            schedule=({"t_s": 3.0, "wob_n": 80e3},),
            drive={"wob_rate_n_s": 2000.0},
        )
    ).rows
    t = times(rows)
    expected = np.clip(60e3 + 2000.0 * (t - 3.0), 60e3, 80e3)
    applied = rows[:, F["applied_wob_n"]]
    np.testing.assert_allclose(applied, expected, rtol=0, atol=2000.0 * STEP_S * 1.001)
    # the driller's estimate (perfect load cell) follows it
    np.testing.assert_allclose(rows[:, F["applied_wob_estimate_n"]], applied, rtol=1e-9)


def test_a_torque_limit_below_the_bit_torque_stalls_the_bit() -> None:
    t0_nm = PRESET.scales.tob_nm(analysis.trivial_solution(PRESET.params).torque)
    limit = 0.7 * t0_nm
    scenario = Scenario(
        preset="field_8p5in_shale_lumped",
        controller="none",
        duration_s=60.0,
        enable_at_s=0.0,
        drive={"max_torque_nm": limit},
    )
    rows = run_in_process(scenario).rows
    motor = rows[1:, F["motor_torque_nm"]]
    assert np.abs(motor).max() == pytest.approx(limit, rel=1e-9)  # at the limit
    card = score(
        rows, 0.0, scenario.setpoints(PRESET), rig_physics(scenario.load_preset()), PERIOD_S
    )
    assert card["status"] == "stalled"
    stall_s = card["stall_time_s"]
    assert stall_s is not None and 0.0 < stall_s < 50.0
    t, stuck = times(rows), rows[:, F["mode"]] == 2
    assert stuck[t >= stall_s].all() and not stuck[t < stall_s][-1]


class TorqueStep:
    """Commands nothing until ``at_s``, then a motor torque ``torque_nm`` (torque mode)."""

    def __init__(self, at_s: float = 1.0, torque_nm: float = 20e3, **_: object) -> None:
        self.at_s, self.torque_nm = at_s, torque_nm

    def reset(self) -> None:
        pass

    def update(self, m: SurfaceMeasurement | None) -> Command:
        if m is not None and m.time_s >= self.at_s - 1e-9:
            return Command(motor_torque_nm=self.torque_nm)
        return Command()


def drive_speed(delay_s: float, at_s: float = 1.0, torque_nm: float = 20e3) -> np.ndarray:
    """Drive speed (rad/s) of each sample of a torque step at ``at_s`` delayed ``delay_s``."""
    scenario = Scenario(
        preset="field_8p5in_shale_lumped",
        mode="torque",
        duration_s=1.5,
        enable_at_s=0.0,
        # no motor (no lag, no rate limit): the step acts at once, the delay alone moves it
        drive={"command_delay_s": delay_s, "motor_lag_s": 0.0, "max_torque_rate_nm_s": 0.0},
    )
    bench = Bench(scenario)
    controller = TorqueStep(at_s, torque_nm)
    command = controller.update(None)
    while not bench.done:
        bench.step(command)
        command = controller.update(bench.measurement())
    return bench.rows[:, F["surface_rpm"]] * 2 * math.pi / 60


def test_a_delay_of_whole_periods_is_the_command_sent_that_much_later() -> None:
    late = drive_speed(2 * PERIOD_S)
    assert np.array_equal(late, drive_speed(0.0, at_s=1.0 + 2 * PERIOD_S))
    assert not np.array_equal(late, drive_speed(0.0))


@pytest.mark.parametrize("fraction", [0.25, 0.6])
def test_a_delay_within_a_period_moves_the_step_inside_it(fraction: float) -> None:
    k = 100  # the command reacts to the sample at 1.00 s
    never = drive_speed(0.0, at_s=99.0)
    gain = drive_speed(0.0)[k + 1] - never[k + 1]
    delayed = drive_speed(fraction * PERIOD_S)
    assert np.array_equal(delayed[: k + 1], never[: k + 1])  # nothing before it arrives
    inertia = rig_physics(PRESET).drive_inertia_kg_m2
    assert gain > 0.5 * (20e3 - 5e3) * PERIOD_S / inertia  # a real kick (T < 5 kN m)
    assert (delayed[k + 1] - never[k + 1]) / gain == pytest.approx(1 - fraction, abs=0.02)


def test_a_scenario_formation_reaches_the_bit_law_at_its_top() -> None:
    """A hard streak in the scenario file: above its top the run is the plain one bit for
    bit; from the period whose start finds the bit in it, T = (eps / eps_ref) delta +
    beta lambda in cutting (eq. 30 with the layer's rock)."""
    base = {
        "preset": "field_8p5in_shale_lumped",
        "controller": "none",
        "duration_s": 20.0,
        "enable_at_s": 0.0,
    }
    plain = run_in_process(scenario_from_dict(base)).rows
    depth = plain[:, F["bit_depth_m"]] - plain[0, F["bit_depth_m"]]
    top = float(0.5 * depth[-1])
    layered = scenario_from_dict(
        {**base, "formation": [{"top_m": top, "intrinsic_specific_energy_pa": 460e6}]}
    )
    assert layered.unsupported() == []
    rows = run_in_process(layered).rows
    below = np.flatnonzero(rows[:, F["bit_depth_m"]] - rows[0, F["bit_depth_m"]] >= top)
    assert below.size and np.array_equal(rows[: below[0] - 1], plain[: below[0] - 1])
    assert not np.array_equal(rows[below[0] + 1 :], plain[below[0] + 1 :])


def test_a_scenario_motor_lag_reaches_the_drive() -> None:
    lagged = scenario_from_dict(
        {
            "preset": "field_8p5in_shale_lumped",
            "mode": "torque",
            "controller": "stiff",
            "duration_s": 2.0,
            "enable_at_s": 0.0,
            "drive": {"motor_lag_s": 0.05},
        }
    )
    assert lagged.unsupported() == []
    assert Bench(lagged).session.sim.top_drive.motor_lag == pytest.approx(
        0.05 / PRESET.scales.time_s
    )
    # the controllers are tuned from the same drive (the soft drives' damper counts its lag)
    assert rig_physics(lagged.load_preset()).motor_lag_s == 0.05
    unlimited = lagged.with_(drive={"max_torque_rate_nm_s": 0.0})
    assert unlimited.load_preset().drive.max_torque_rate_nm_s == math.inf
    with pytest.raises(ParameterError, match="command_delay_s"):
        scenario_from_dict({"drive": {"command_delay_s": -1.0}})


def test_a_start_up_scenario_starts_off_bottom_at_rest_and_the_tag_drills() -> None:
    """The driller's schedule on the bench: picked up at t = 0 (everything still, no weight
    on the bit), rotation ramped by the schedule, then a tag: the hook slacks off at the tag
    speed v and the bit meets the rock after clearance / v, through the bit law's own
    contact: at first contact the weight on bit is the collars' impact force, at most their
    axial impedance A sqrt(E rho) times v (an elastic line meeting a wall), not a jump to
    the applied weight; then it drills."""
    preset = load_preset("field_8p5in_shale")
    spec = preset.string
    collars = spec.sections[-1]
    area_m2 = math.pi * (collars.outer_radius_m**2 - collars.inner_radius_m**2)
    impact_n = area_m2 * math.sqrt(collars.youngs_modulus_pa * collars.density_kg_m3) \
        * spec.hook_tag_m_s
    scenario = scenario_from_dict({
        "preset": "field_8p5in_shale", "duration_s": 45, "enable_at_s": 0,
        "controller": "none", "schedule": [
            {"t_s": 0, "rpm": 0, "wob_n": 60000, "off_bottom": True},
            {"t_s": 0.5, "rpm": 40, "ramp_s": 5}, {"t_s": 10, "off_bottom": False}]})
    rows = run_in_process(scenario).rows
    t, wob = times(rows), rows[:, F["wob_n"]]
    first = rows[0]
    assert first[F["bit_rpm"]] == 0.0 and first[F["surface_rpm"]] == 0.0
    assert first[F["wob_n"]] == 0.0 and first[F["surface_torque_nm"]] == 0.0
    contact = int(np.argmax(wob > 0.0))
    tag_s = spec.off_bottom_clearance_m / spec.hook_tag_m_s
    assert 10.0 + 0.9 * tag_s < t[contact] < 10.0 + 1.1 * tag_s
    assert 0.0 < wob[contact] <= 1.2 * impact_n
    assert np.mean(wob[t > t[contact] + 5.0]) > 0.5 * 60000.0        # drilling again


def test_off_bottom_on_the_lumped_string_is_refused_in_one_line() -> None:
    scenario = scenario_from_dict({
        "preset": "field_8p5in_shale_lumped", "duration_s": 5, "enable_at_s": 0,
        "controller": "none",
        "schedule": [{"t_s": 1, "off_bottom": True}]})
    with pytest.raises(ParameterError, match="needs a distributed string"):
        Bench(scenario)
