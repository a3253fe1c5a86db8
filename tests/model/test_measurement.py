"""Rig sensors: off by default, seeded noise of the asked size, quantisation, whole-sample
delay, and the same measurements whatever the blocks the samples come in."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from drill_sim_ros.model import kernel as k
from drill_sim_ros.model.errors import ParameterError
from drill_sim_ros.model.measurement import (
    NOISE_BLOCK_SAMPLES,
    SIGNALS,
    RigSensors,
    SignalSpec,
)
from drill_sim_ros.model.presets import load_preset
from drill_sim_ros.model.simulator import SimConfig, Simulator
from drill_sim_ros.model.telemetry import field_scales, si_rows, surface_truth
from tests.model.measurement_reference import ReferenceSensors


def _truth(rows: int = 20_000) -> np.ndarray:
    t = np.arange(rows) * 0.01
    return np.column_stack([6.0 + np.sin(t), 3000.0 + 500.0 * np.cos(t), 2500.0 + 0.0 * t,
                            9e5 - 1e3 * np.sin(t)])


def test_perfect_sensors_by_default() -> None:
    truth = _truth()
    assert np.array_equal(RigSensors().measure(truth), truth)


def test_noise_has_the_asked_size_and_repeats_with_the_seed() -> None:
    truth = _truth(100_000)
    specs = {"motor_torque_nm": SignalSpec(noise_std=50.0)}
    measured = RigSensors(specs, seed=7).measure(truth)
    error = measured[:, 1] - truth[:, 1]
    assert error.std() == pytest.approx(50.0, rel=0.02)          # 1/sqrt(2N) = 0.2 %
    assert abs(error.mean()) < 4 * 50.0 / np.sqrt(error.size)
    assert np.array_equal(measured[:, [0, 2, 3]], truth[:, [0, 2, 3]])  # the others untouched
    assert np.array_equal(RigSensors(specs, seed=7).measure(truth), measured)
    assert not np.array_equal(RigSensors(specs, seed=8).measure(truth), measured)


def test_quantisation_rounds_to_the_quantum() -> None:
    truth = _truth()
    q = 0.05
    measured = RigSensors({"drive_speed_rad_s": SignalSpec(quantum=q)}).measure(truth)[:, 0]
    assert np.allclose(measured / q, np.round(measured / q), rtol=0, atol=1e-9)
    assert np.max(np.abs(measured - truth[:, 0])) <= q / 2 + 1e-12


def test_delay_in_whole_samples() -> None:
    truth = _truth()
    measured = RigSensors({"string_torque_nm": SignalSpec(delay_periods=3),
                           "motor_torque_nm": SignalSpec(delay_periods=1)}).measure(truth)
    assert np.array_equal(measured[3:, 2], truth[:-3, 2])
    assert np.array_equal(measured[:3, 2], np.full(3, truth[0, 2]))
    assert np.array_equal(measured[1:, 1], truth[:-1, 1])


def test_blocks_give_the_same_measurements_as_one_call() -> None:
    truth = _truth(5000)
    specs = {name: SignalSpec(noise_std=0.1, quantum=0.01, delay_periods=2) for name in SIGNALS}
    whole = RigSensors(specs, seed=3).measure(truth)
    sensors = RigSensors(specs, seed=3)
    parts = [sensors.measure(truth[a:b]) for a, b in ((0, 1), (1, 2), (2, 700), (700, 5000))]
    assert np.array_equal(np.vstack(parts), whole)


def test_surface_truth_of_the_field_preset_in_si() -> None:
    preset = load_preset("field_8p5in_shale_lumped")
    sim = Simulator(preset.params, SimConfig(dtau=preset.dtau), top_drive=preset.top_drive,
                    scales=preset.scales)
    rows = sim.advance(1000, every=100).data
    si = si_rows(rows, sim.offsets, field_scales(preset.scales), rows[:, k.C_TAU], 0.0)
    truth = surface_truth(si)
    assert truth[0, 0] == pytest.approx(2 * np.pi)               # 60 rpm
    assert truth[0, 2] == pytest.approx(sim.scales.tob_nm(rows[0, k.C_T_PIPE]))
    assert truth[0, 1] == pytest.approx(truth[0, 2])             # on the trivial solution


def test_bad_sensor_settings_are_named() -> None:
    with pytest.raises(ParameterError, match="noise_std"):
        SignalSpec(noise_std=-1.0)
    with pytest.raises(ParameterError, match="delay_periods"):
        SignalSpec(delay_periods=-2)
    with pytest.raises(ParameterError, match="bit_rpm"):
        RigSensors({"bit_rpm": SignalSpec()})


def test_hook_load_and_the_wob_estimate_of_a_session() -> None:
    """The load cell reads the hook load; the driller's WOB estimate is the submerged weight
    less the measured hook load, so its error is minus the load cell's noise."""
    from drill_sim_ros.model.session import SessionConfig, SimSession
    from drill_sim_ros.model.telemetry import TELEMETRY_INDEX as F
    preset = load_preset("field_8p5in_shale")
    weight_n = 1.2e6
    cfg = dict(preset=preset, dtau_max=preset.dtau, submerged_weight_n=weight_n)
    perfect = SimSession(SessionConfig(**cfg)).run(200).rows
    np.testing.assert_array_equal(perfect[:, F["hook_load_measured_n"]],
                                  perfect[:, F["hook_load_n"]])
    np.testing.assert_allclose(perfect[:, F["applied_wob_estimate_n"]],
                               weight_n - perfect[:, F["hook_load_measured_n"]], rtol=1e-15)
    noisy = SimSession(SessionConfig(**cfg, sensors=RigSensors(
        {"hook_load_n": SignalSpec(noise_std=500.0)}, seed=2))).run(5000).rows
    error = noisy[:, F["hook_load_measured_n"]] - noisy[:, F["hook_load_n"]]
    assert error.std() == pytest.approx(500.0, rel=0.05)         # 1/sqrt(2N) = 1 %
    np.testing.assert_allclose(noisy[:, F["applied_wob_estimate_n"]],
                               weight_n - noisy[:, F["hook_load_measured_n"]], rtol=1e-15)
    np.testing.assert_array_equal(noisy[:, F["string_torque_measured_nm"]],
                                  noisy[:, F["surface_torque_nm"]])      # the others perfect


def test_the_hook_carries_the_weight_less_what_the_string_leans_on() -> None:
    """Drilling steadily, the hook's loop holds the string's force at the top at the applied
    WOB, so the hook load is the buoyed weight less the applied WOB (mean within 0.5 kN of
    the 60 kN over 10 s; the axial vibration moves it by a few kN). Picked up off bottom,
    the string leans on nothing and the hook carries all of the weight (within 0.5 %, the
    string's axial ringing dying out), whatever the applied-WOB command still says.
    (Measured 2026-12-07: 743.81 kN drilling against 803.81 - 60; 803.81 kN picked up. Until
    then the hook load was the weight less the command, 743.81 kN also off bottom.)"""
    from drill_sim_ros.model.presets import submerged_string_weight_n
    from drill_sim_ros.model.session import SessionConfig, SimSession
    from drill_sim_ros.model.telemetry import TELEMETRY_INDEX as F
    preset = load_preset("field_8p5in_shale")
    weight_n = submerged_string_weight_n(preset)
    session = SimSession(SessionConfig(preset=preset, dtau_max=preset.dtau,
                                       submerged_weight_n=weight_n))
    drilling = session.run(1000).rows                     # 10 s at 100 Hz
    applied_n = drilling[:, F["applied_wob_n"]]
    assert np.all(applied_n == preset.physical.applied_wob_n)
    assert drilling[:, F["hook_load_n"]].mean() == pytest.approx(
        weight_n - preset.physical.applied_wob_n, abs=500.0)
    session.set_off_bottom(True)
    lifted = session.run(3000).rows[-500:]                # the last 5 s of 30
    assert np.all(lifted[:, F["mode"]] == k.MODE_OFF_BOTTOM)
    assert np.all(lifted[:, F["applied_wob_n"]] == preset.physical.applied_wob_n)
    np.testing.assert_allclose(lifted[:, F["hook_load_n"]], weight_n, rtol=5e-3)


MIXED = {"drive_speed_rad_s": SignalSpec(noise_std=0.02, quantum=0.001),
         "motor_torque_nm": SignalSpec(noise_std=100.0, delay_periods=1),
         "string_torque_nm": SignalSpec(noise_std=150.0, quantum=25.0, delay_periods=7),
         "hook_load_n": SignalSpec(quantum=500.0, delay_periods=3)}


@pytest.mark.parametrize("cuts", [
    [1] * 300,                                       # a sample per call, as the gym measures
    [1, 1, 4094, 1, 1, 5000, 3],                     # across and beyond the noise blocks
    [NOISE_BLOCK_SAMPLES * 3 + 5],                   # one block longer than the noise block
    [1000, 3500, 2000],                              # refills that keep an undrawn tail
])
def test_the_sensors_give_the_reference_measurements_bit_for_bit(cuts: list[int]) -> None:
    """The compiled sensors against the plain block-by-block path (measurement_reference),
    whatever the blocks: the same noise stream, rounding and delay, to the last bit."""
    truth = _truth(sum(cuts))
    fast, slow = RigSensors(MIXED, seed=5), ReferenceSensors(MIXED, seed=5)
    edges = np.cumsum([0, *cuts])
    for a, b in itertools.pairwise(edges):
        np.testing.assert_array_equal(fast.measure(truth[a:b]), slow.measure(truth[a:b]))


def test_reset_restarts_the_noise_and_the_delay_lines() -> None:
    truth = _truth(50)
    sensors = RigSensors(MIXED, seed=5)
    first = sensors.measure(truth)
    sensors.measure(truth[::-1])
    sensors.reset()
    np.testing.assert_array_equal(sensors.measure(truth), first)


def test_measure_into_measures_the_named_columns_in_place() -> None:
    truth = _truth(40)
    rows = np.zeros((40, 9))
    columns = np.array([8, 2, 5, 0], dtype=np.int64)
    rows[:, columns] = truth
    RigSensors(MIXED, seed=1).measure_into(rows, columns)
    np.testing.assert_array_equal(rows[:, columns], ReferenceSensors(MIXED, seed=1).measure(truth))
    assert not rows[:, [1, 3, 4, 6, 7]].any()
