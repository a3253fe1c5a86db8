"""``drill_sim startup`` against an independent model of the same published physics.

The reference (:mod:`tests.model.startup_reference`) solves Aarsnes & Shor's off-bottom
model (J. Pet. Sci. Eng. 163, 2018, eqs. 1-10: the torsional wave equation with a
set-valued Coulomb inclusion along the string, a PI top drive) by another method: a chain of
lumped masses 2 m long, stepped by symplectic Euler with the friction as an impulse on
each mass. It was written without reading this package's kernel, and checks itself against
the closed forms (static break-away, twist, sliding torque). The kernel lumps the friction
at the wave guide's junctions and carries the waves exactly between them.

The package puts the wall's friction in every cell of its wave guide, one wave step long:
here ``bit_substeps`` 16, cells of 1.9 m torsionally, as fine as the reference's elements.

Inputs of their own: a 3000 m well, vertical to 500 m, built to 60 deg at 1500 m; 2800 m of
5-in drill pipe on 200 m of 6.5-in collars, mud 1200 kg/m^3, mu_s 0.35, mu_d 0.25, a stick
band of 0.05 rad/s; the field preset's drive. Both runs are scored by the same definitions
(``startup_scores``) on their own time series.
"""

from __future__ import annotations

import numpy as np
import pytest

from drill_sim_ros.model.presets import preset_from_dict
from drill_sim_ros.model.startup import StartupRun, run_startup, startup_scores
from tests.model.startup_reference import reference_startup

PIPE = {"outer_radius_m": 0.0635, "inner_radius_m": 0.054305, "length_m": 2800.0}
COLLARS = {"outer_radius_m": 0.08255, "inner_radius_m": 0.035719, "length_m": 200.0}
SURVEY = [{"md_m": 0, "inclination_deg": 0}, {"md_m": 500, "inclination_deg": 0},
          {"md_m": 1500, "inclination_deg": 60}, {"md_m": 3000, "inclination_deg": 60}]
FRICTION = {"static": 0.35, "dynamic": 0.25, "stick_speed_rad_s": 0.05}
DRIVE = {"inertia_kg_m2": 2900.0, "kp_nm_s": 23200.0, "ki_nm": 46400.0,
         "max_torque_nm": 50000.0}
DX_M = 2.0
SUBSTEPS = 16      # the wave step, 16 x 37 us = 0.59 ms: the wall's cells 1.9 m torsionally
RPM_PER_RAD_S = 60.0 / (2.0 * np.pi)


def preset():
    return preset_from_dict("own_well", {
        "physical": {"density_kg_m3": 7850.0, "shear_modulus_pa": 79.3e9,
                     "youngs_modulus_pa": 206e9, "bit_radius_m": 0.108, "n_blades": 6,
                     "intrinsic_specific_energy_pa": 230e6, "zeta": 0.729, "mu_gamma": 0.48,
                     "contact_stress_times_wearflat_n_per_m": 1e5, "applied_wob_n": 6e4,
                     "surface_rpm": 60.0},
        "string": {"model": "distributed", "sections": [PIPE, COLLARS],
                   "bit_inertia_kg_m2": 0.3, "bit_substeps": SUBSTEPS},
        "well": {"survey": SURVEY, "mud_density_kg_m3": 1200.0, "side_friction": FRICTION},
        "top_drive": {"mode": "speed", **DRIVE}, "numerics": {"dtau": 5e-5}})


def reference_run(rpm: float, ramp_s: float, seconds: float, like: StartupRun,
                  dx_m: float = DX_M) -> StartupRun:
    """The reference's time series at elements of ``dx_m``, scored as the package's (the
    cut-off of ``like``)."""
    res = reference_startup({
        "sections": [PIPE, COLLARS], "density_kg_m3": 7850.0, "shear_modulus_pa": 79.3e9,
        "torsional_damping_per_s": 0.0, "bit_inertia_kg_m2": 0.3, "survey": SURVEY,
        "mud_density_kg_m3": 1200.0, "side_friction": FRICTION, "top_drive": DRIVE,
        "rpm": rpm, "ramp_s": ramp_s, "seconds": seconds, "sample_hz": 100,
        "dx_m": dx_m, "return_series": True})
    s = res["_series"]
    phi = np.asarray(s["phi_td"])
    return StartupRun(t_s=np.asarray(s["t"]), bit_rpm=np.asarray(s["w_bit"]) * RPM_PER_RAD_S,
                      drive_rpm=np.asarray(s["w_td"]) * RPM_PER_RAD_S,
                      setpoint_rpm=np.zeros_like(phi), motor_torque_nm=np.asarray(s["motor"]),
                      surface_torque_nm=np.asarray(s["T_top"]),
                      twist_turns=np.asarray(s["twist_turns"]),
                      drive_turns=(phi - phi[0]) / (2.0 * np.pi), cutoff_hz=like.cutoff_hz)


def both(rpm: float, ramp_s: float, seconds: float) -> tuple[dict, dict]:
    ours = run_startup(preset(), rpm, ramp_s, seconds)
    return startup_scores(ours), startup_scores(reference_run(rpm, ramp_s, seconds, ours))


def test_the_break_away_matches_the_reference_within_a_few_per_cent() -> None:
    """60 rpm in 10 s: the string breaks free as the torque front reaches the collars. The
    bit leaves on one of two wave arrivals (about 8.7 s, 3.75 turns, 9.9 kN m, or about
    9.0 s, 4.0 turns, 10.4 kN m): the reference lands on either as its elements go from 4 to
    1 m (and back at 0.5 m). So the package's
    break-away, drive turns, torque, first slip and peak motor torque must lie within the
    reference's own spread over 4, 2 and 1 m, widened by 2 %: within 3-7 % of either."""
    ours = startup_scores(run_startup(preset(), 60.0, 10.0, 30.0))
    refs = []
    for dx_m in (4.0, 2.0, 1.0):
        run = reference_run(60.0, 10.0, 30.0, run_startup(preset(), 60.0, 10.0, 0.05),
                            dx_m)
        refs.append(startup_scores(run))
    for key in ("breakaway_s", "breakaway_turns", "breakaway_torque_nm", "first_slip_s",
                "peak_motor_torque_nm"):
        values = [r[key] for r in refs]
        assert 0.98 * min(values) <= ours[key] <= 1.02 * max(values), (key, ours[key], values)
    assert ours["motor_torque_nm"]["mean"] == pytest.approx(
        refs[1]["motor_torque_nm"]["mean"], rel=0.01)


def test_at_20_rpm_both_rotate_steadily_after_the_same_break_away() -> None:
    """20 rpm: the string breaks free and then turns steadily, in both. The break-away here
    moves by a few per cent with the resolution in both models, as the torque front meets
    the wall's sticks on one wave arrival or the next (measured 2026-12-06 with the bend
    term: the reference at 2 / 1 / 0.5 m breaks away at 14.45 / 14.46 / 15.26 s with
    11.85 / 11.90 / 12.55 kN m, peak motor torque 12.88 / 13.33 / 13.51 kN m; the package at
    cells of 1.9 / 0.95 m at 14.94 / 14.49 s, 12.32 / 12.13 kN m, 13.78 / 13.21 kN m). So the
    package's figures must lie within the reference's own spread over 2 and 1 m widened by
    5 %, the size of that sensitivity (the lumped wall missed by 15-20 %), and both rotate
    steadily (stuck within 0.05)."""
    ours = startup_scores(run_startup(preset(), 20.0, 5.0, 120.0))
    like = run_startup(preset(), 20.0, 5.0, 0.05)
    refs = [startup_scores(reference_run(20.0, 5.0, 120.0, like, dx_m)) for dx_m in (2.0, 1.0)]
    assert not ours["stick_slip"] and not any(r["stick_slip"] for r in refs)
    assert ours["stick_fraction"] <= 0.05
    for key in ("breakaway_s", "breakaway_torque_nm", "first_slip_s", "peak_motor_torque_nm"):
        values = [r[key] for r in refs]
        assert 0.95 * min(values) <= ours[key] <= 1.05 * max(values), (key, ours[key], values)
