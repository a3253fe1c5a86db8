"""``drill_sim startup`` against an independent model of the same published physics.

The reference (:mod:`tests.model.startup_reference`) solves Aarsnes & Shor's off-bottom
model (J. Pet. Sci. Eng. 163, 2018, eqs. 1-10: the torsional wave equation with a
set-valued Coulomb inclusion along the string, a PI top drive) by another method: a chain of
lumped masses 2 m long, stepped by symplectic Euler with the friction as an impulse on
each mass. It was written without reading this package's kernel, and checks itself against
the closed forms (static break-away, twist, sliding torque). The kernel lumps the friction
at the wave guide's junctions and carries the waves exactly between them.

The package runs with one wave-guide step per bit step (``bit_substeps`` 1, the default):
at 20 rpm this case lies where stick-slip and steady rotation coexist, and the held waves'
small loss at a coarser wave step tips it (docs/string.md, "One step for the waves, several
for the bit").

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
RPM_PER_RAD_S = 60.0 / (2.0 * np.pi)


def preset():
    return preset_from_dict("own_well", {
        "physical": {"density_kg_m3": 7850.0, "shear_modulus_pa": 79.3e9,
                     "youngs_modulus_pa": 206e9, "bit_radius_m": 0.108, "n_blades": 6,
                     "intrinsic_specific_energy_pa": 230e6, "zeta": 0.729, "mu_gamma": 0.48,
                     "contact_stress_times_wearflat_n_per_m": 1e5, "applied_wob_n": 6e4,
                     "surface_rpm": 60.0},
        "string": {"model": "distributed", "sections": [PIPE, COLLARS],
                   "bit_inertia_kg_m2": 0.3, "damping_points": 64},
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


@pytest.mark.xfail(strict=True, reason="with the bend term (2026-12-06) the lumped wall "
                   "friction's break-away turns at 64 points a section are 4.257 against "
                   "the reference's 4.014-4.140 (16 and 32 points: 4.174, 3.958, inside): "
                   "the lumping's non-convergence of issue 50, items 1-2; the mean motor "
                   "torque agrees to 0.05 %")
def test_the_break_away_matches_the_reference_within_a_few_per_cent() -> None:
    """60 rpm in 10 s: the string breaks free as the torque front reaches the collars. The
    bit leaves on one of two wave arrivals (about 8.7 s, 3.75 turns, 9.9 kN m, or about
    9.0 s, 4.0 turns, 10.4 kN m): the reference lands on either as its elements go from 4 to
    1 m (and back at 0.5 m), the package on either from 32 to 128 junctions. So the package's
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


@pytest.mark.xfail(strict=True, reason="with the bend term (2026-12-06) the same normal "
                   "force in both (to 2e-9) gives different cycles: at 20 rpm the package "
                   "sticks and slips (period 5.00 s) where the reference at 2 m rotates "
                   "steadily; at 15 rpm both stick and slip, periods 5.05 s (package, 32 "
                   "and 64 points) against 6.3-7.0 s (reference, 4-1 m); issue 50 items 1-2")
def test_off_bottom_stick_slip_and_its_period_match_the_reference() -> None:
    """20 rpm: the wall's static friction above its dynamic one makes the string stick and
    slip off bottom near the first mode's period, in both; the period within 10 %.

    The cycle is one of two states the undamped string can settle in (steady rotation is
    the other): which one a run reaches depends on its transient, so the reference at 1 m
    elements rotates steadily here, while at 2 m (its default, the size its closed-form
    checks pass at) it sticks and slips, as the package does at 32, 64 and 128 junctions
    (period 5.07 s at 64). Measured 2026-12-03 (docs/string.md, "Side friction along a
    deviated well")."""
    ours, ref = both(20.0, 5.0, 120.0)
    assert ref["stick_slip"] and ours["stick_slip"]
    assert ours["period_s"] == pytest.approx(ref["period_s"], rel=0.10)
    assert ours["stick_fraction"] == pytest.approx(ref["stick_fraction"], abs=0.05)
    assert ours["peak_motor_torque_nm"] == pytest.approx(ref["peak_motor_torque_nm"], rel=0.05)
