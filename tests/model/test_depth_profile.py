"""String profiles along depth (drill/string/torsion's data), the BHA speed and the string in
the run info, on the field preset (distributed) and its lumped twin."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
import yaml

from drill_sim_ros.model.depth_profile import (
    DepthSampler,
    Interpolation,
    depth_name,
    sample_depths_m,
)
from drill_sim_ros.model.errors import ParameterError
from drill_sim_ros.model.params import RPM_PER_RAD_S
from drill_sim_ros.model.presets import load_preset, preset_from_dict, preset_path
from drill_sim_ros.model.session import SessionConfig, SimSession
from drill_sim_ros.model.telemetry import TELEMETRY_INDEX as F

FIELD, LUMPED = "field_8p5in_shale", "field_8p5in_shale_lumped"
STEEL_C_M_S = math.sqrt(79.3e9 / 7850.0)      # torsional wave speed sqrt(G / rho)


def session(name: str = FIELD, **kwargs) -> SimSession:
    return SimSession(SessionConfig(preset=load_preset(name), **kwargs))


def lossless_field():
    """The field preset with its string's losses set to 0 (docs/string.md: lossless stays
    available for the exact wave tests)."""
    with open(preset_path(FIELD)) as stream:
        data = yaml.safe_load(stream)
    data["string"].update(torsional_damping_per_s=0.0, axial_damping_per_s=0.0)
    return preset_from_dict(f"{FIELD}_lossless", data)


def test_sampler_interpolates_linearly_between_cell_middles() -> None:
    cells = np.array([5.0, 15.0, 25.0, 35.0])
    sampler = DepthSampler(cells, 40.0, 2)
    np.testing.assert_allclose(sampler.depths_m, [10.0, 30.0])
    sample = sampler.sample((cells, 2.0 * cells, -cells), 7)
    np.testing.assert_allclose(sample.speed_rad_s, [20.0, 60.0])
    np.testing.assert_allclose(sample.torque_nm, [-10.0, -30.0])
    assert sample.stamp_ns == 7
    assert sampler.names == ["string_0010.0m", "string_0030.0m"]
    assert len(DepthSampler(cells, 40.0, 64).depths_m) == 4      # at most one per cell


def test_interpolation_is_np_interp_bit_for_bit_and_reads_only_its_nodes() -> None:
    rng = np.random.default_rng(4)
    xp = np.cumsum(rng.uniform(0.1, 3.0, 50))
    # between nodes, on nodes, on the ends and beyond them
    x = np.concatenate((rng.uniform(xp[0] - 2.0, xp[-1] + 2.0, 200), xp[[0, 7, 49]],
                        [xp[0] - 1.0, xp[-1] + 1.0]))
    interpolation = Interpolation.at(x, xp)
    for _ in range(5):
        y = rng.normal(0.0, 1e3, xp.size) * rng.uniform(1e-6, 1e6)
        assert np.array_equal(interpolation(y[interpolation.nodes]), np.interp(x, xp, y))
    inner = Interpolation.at(np.array([2.5]), np.array([1.0, 2.0, 3.0, 4.0]))
    np.testing.assert_array_equal(inner.nodes, [1, 2])


def test_reading_the_sampled_cells_gives_the_full_profiles_values() -> None:
    """After waves have run up and down the string (a speed step at the top), the cells a
    sampler reads (Simulator.string_cells) hold what string_profile gives there, and the
    samples equal np.interp of the whole profile, bit for bit."""
    sim = session(string_rate_hz=10.0, string_depths=64, perturb_v=1e-2)
    first = sim.run(20)
    sim.set_surface_rpm(first.rows[-1][F["surface_rpm"]] * 1.3)
    block = sim.run(230)
    depth, speed, torque = sim.sim.string_profile()
    sampler = DepthSampler(depth, load_preset(FIELD).string.length_m, 64)
    cell_speed, cell_torque = sim.sim.string_cells(sampler.cells)
    assert np.array_equal(cell_speed, speed[sampler.cells])
    assert np.array_equal(cell_torque, torque[sampler.cells])
    assert sampler.cells.size <= 128 < depth.size
    last = block.strings[-1]
    assert last.stamp_ns == sim.sim_time_ns
    assert np.array_equal(last.speed_rad_s, np.interp(sampler.depths_m, depth, speed))
    assert np.array_equal(last.torque_nm, np.interp(sampler.depths_m, depth, torque))
    assert np.ptp(last.speed_rad_s) > 1e-3          # not a steady string


def test_depth_names_and_count_range() -> None:
    assert depth_name(2678.90625) == "string_2678.9m"
    np.testing.assert_allclose(sample_depths_m(2700.0, 64)[[0, -1]],
                               [2700 / 128, 2700 - 2700 / 128])
    for bad in (0, 65):
        with pytest.raises(ParameterError, match=r"string.depths = .* \[1, 64\]"):
            session(string_rate_hz=10.0, string_depths=bad)


def test_profiles_come_at_the_rate_on_sample_stamps_and_t0_is_the_steady_state() -> None:
    sim = session(string_rate_hz=10.0)          # publish 100 Hz: every 10th sample
    first = sim.current()
    assert [s.stamp_ns for s in first.strings] == [0]
    row, profile = first.rows[0], first.strings[0]
    # the string starts in steady rotation: the drive's speed everywhere, and the bit's
    # torque plus the viscous drag of the string below each depth (rate x inertia x speed:
    # all of it near the top; none below the last damper, 25 m above the bit)
    omega = row[F["surface_rpm"]] / RPM_PER_RAD_S
    np.testing.assert_allclose(profile.speed_rad_s, omega, rtol=1e-12)
    spec = load_preset(FIELD).string
    drag_nm = sum(s.torsional_damping_per_s * s.inertia_kg_m2 for s in spec.sections) * omega
    torque = np.asarray(profile.torque_nm)
    assert torque[0] == pytest.approx(row[F["tob_nm"]] + drag_nm, rel=1e-9)
    assert torque[-1] == pytest.approx(row[F["tob_nm"]], rel=1e-9)
    assert np.all(np.diff(torque) <= 1e-9 * torque[0])
    block = sim.run(25)
    assert [s.stamp_ns for s in block.strings] == [100_000_000, 200_000_000]
    assert set(s.stamp_ns for s in block.strings) <= set(block.stamps_ns.tolist())
    assert [s.stamp_ns for s in sim.run(5).strings] == [300_000_000]
    assert sim.string_depths_m.shape == (64,)


def test_profile_sampling_leaves_the_samples_unchanged() -> None:
    plain, sampled = session(), session(string_rate_hz=30.0)     # every 3rd sample
    a, b = plain.run(50), sampled.run(50)
    np.testing.assert_array_equal(a.rows, b.rows)
    assert len(b.strings) == 16 and not a.strings
    # the profile at a stamp is the string's state then: compare a run stopped there
    again = session()
    again.run(30)
    depth, speed, _ = again.sim.string_profile()
    np.testing.assert_allclose(b.strings[9].speed_rad_s,
                               np.interp(sampled.string_depths_m, depth, speed), rtol=1e-12)


def test_a_speed_step_at_the_top_travels_down_at_the_wave_speed() -> None:
    preset = lossless_field()
    nominal_rpm = preset.physical.surface_rpm
    drive = dataclasses.replace(preset.top_drive.physical(preset.scales), mode="kinematic")
    sim = SimSession(SessionConfig(preset=preset, top_drive=drive, string_rate_hz=100.0,
                                   perturb_v=0.0))
    sim.current()
    sim.set_surface_rpm(nominal_rpm + 30.0)
    profiles = sim.run(80).strings              # 0.8 s, one profile per 10 ms
    depths = sim.string_depths_m
    for j in (8, 24, 40):                       # about 360, 1040 and 1710 m
        moved = [s.stamp_ns * 1e-9 for s in profiles
                 if abs(s.speed_rad_s[j] * RPM_PER_RAD_S - nominal_rpm) > 1.0]
        arrival_s = depths[j] / STEEL_C_M_S
        assert moved and abs(moved[0] - arrival_s) <= 0.02, (depths[j], moved[:1], arrival_s)


def test_lumped_string_has_no_profiles_and_the_bha_is_the_bit() -> None:
    sim = session(LUMPED, string_rate_hz=10.0)
    block = sim.run(20)
    assert not block.strings and sim.string_depths_m.size == 0
    np.testing.assert_array_equal(block.rows[:, F["bha_rpm"]], block.rows[:, F["bit_rpm"]])
    assert sim.run_info()["string"] == {"model": "lumped"}


def test_bha_speed_follows_the_bottom_of_the_string() -> None:
    sim = SimSession(SessionConfig(preset=lossless_field(), string_rate_hz=10.0))
    block = sim.run(1000)
    last = block.strings[-1]
    row = block.rows[block.stamps_ns.tolist().index(last.stamp_ns)]
    # the deepest depth is 21 m above the bit, inside the collars: within a few rpm
    assert abs(last.speed_rad_s[-1] * RPM_PER_RAD_S - row[F["bha_rpm"]]) < 3.0
    assert not np.array_equal(block.rows[:, F["bha_rpm"]], block.rows[:, F["surface_rpm"]])


def test_run_info_carries_the_sections_of_the_preset_file() -> None:
    with open(preset_path(FIELD)) as stream:
        written = yaml.safe_load(stream)["string"]
    info = session(string_rate_hz=10.0).run_info()["string"]
    assert info["model"] == written["model"] == "distributed"
    for section, spec in zip(info["sections"], written["sections"], strict=True):
        for key, value in spec.items():
            assert section[key] == pytest.approx(value), key
        assert section["shear_modulus_pa"] > 0 and section["density_kg_m3"] > 0
    assert info["length_m"] == pytest.approx(sum(s["length_m"] for s in written["sections"]))
    assert len(info["profile_depths_m"]) == 64 and info["profile_period_ns"] == 100_000_000
