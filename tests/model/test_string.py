"""The distributed string: waves, modes, reflection, energy, and the lumped model unchanged.

Expected values come from physics: the travel time L / c, the transfer-matrix and closed-form
mode conditions, the reflection formula of an impedance Z_TD against the pipe's Z, the
energy balance, the lumped limit of RGD07 eq. (1); and, for the lumped kernel, from the
kernel as it was before the string existed (hashes of its output at commit 855bfb7).
"""

from __future__ import annotations

import cmath
import dataclasses
import hashlib
import json
import math
from pathlib import Path

import numpy as np
import pytest

from drill_sim_ros.model import kernel as k
from drill_sim_ros.model import string as sg
from drill_sim_ros.model import string_instruments as si
from drill_sim_ros.model.errors import NumericalFault, ParameterError
from drill_sim_ros.model.presets import load_preset, preset_from_dict
from drill_sim_ros.model.simulator import SimConfig, Simulator
from drill_sim_ros.model.top_drive import TopDrive

FIELD_PHYSICAL = {
    "density_kg_m3": 7850.0, "shear_modulus_pa": 79.3e9, "youngs_modulus_pa": 206e9,
    "bit_radius_m": 0.108, "n_blades": 6, "intrinsic_specific_energy_pa": 230e6,
    "zeta": 0.729, "mu_gamma": 0.48, "contact_stress_times_wearflat_n_per_m": 3.0e5,
    "applied_wob_n": 60e3, "surface_rpm": 60.0}
PIPE = {"outer_radius_m": 0.0635, "inner_radius_m": 0.0543}
COLLAR = {"outer_radius_m": 0.0857, "inner_radius_m": 0.0357}


def string_preset(sections: list[dict], physical: dict | None = None, **string_keys: object):
    return preset_from_dict("test", {
        "physical": {**FIELD_PHYSICAL, **(physical or {})}, "numerics": {"dtau": 5e-5},
        "string": {"model": "distributed", "sections": sections, **string_keys},
        "top_drive": {"mode": "speed", "inertia_kg_m2": 2900.0, "kp_nm_s": 23200.0,
                      "ki_nm": 46400.0, "max_torque_nm": 50000.0}})


# ---- the lumped model, bit for bit --------------------------------------------------------
def lumped_hash(name: str, mode: str, method: str) -> str:
    """The output of a fixed run, hashed (the columns and state entries that existed
    before the string)."""
    p = load_preset(name)
    sim = Simulator(p.params, SimConfig(dtau=p.dtau, method=method, n_nodes=p.n_nodes or 2048),
                    perturb_v=1e-3, top_drive=p.top_drive.with_(mode=mode), scales=p.scales)
    s = sim.advance(200_000 if method == "profile" else 50_000, every=97)
    if mode == "torque":
        sim.set_inputs(motor_torque=float(sim.state[k.S_MOTOR_TORQUE]) * 1.01)
    s2 = sim.advance(20_000, every=13)
    return hashlib.sha256(np.ascontiguousarray(s.data[:, :16]).tobytes()
                          + np.ascontiguousarray(s2.data[:, :16]).tobytes()
                          + sim.state[:16].tobytes() + sim.profile.tobytes()
                          + sim.accumulators.tobytes()).hexdigest()


HASHES = json.loads((Path(__file__).parent / "data" / "lumped_hashes_855bfb7.json").read_text())


@pytest.mark.parametrize("case", sorted(key for key in HASHES if not key.startswith("_")))
def test_paper_presets_unchanged_bit_for_bit(case: str) -> None:
    name, mode, method = case.split("/")
    assert lumped_hash(name, mode, method) == HASHES[case]


# ---- waves ----------------------------------------------------------------------------------
def test_pulse_arrives_after_l_over_c_and_returns_whole() -> None:
    """A pulse sent up from the bit on a uniform lossless string under a kinematic top: its
    peak reaches the top after L / c (within a step), and after the round trip top -> bit
    -> top (a fixed top keeps the torque's sign, the free bit flips it) it is back at the
    top after 3 L / c with its peak within 1 %."""
    preset = string_preset([{**PIPE, "length_m": 1500.0}, {**PIPE, "length_m": 1200.0}])
    sim = si.off_bottom_simulator(preset, TopDrive(mode="kinematic", inertia_ratio=14.0))
    dt_s = sim.config.dtau * preset.scales.time_s
    travel_s = preset.string.torsional_travel_s
    assert travel_s == pytest.approx(2700.0 / math.sqrt(79.3e9 / 7850.0), rel=1e-12)
    amplitude = 0.02 * preset.params.omega0 * float(sim.string_arrays()[2][sg.W_Z, 0])
    si.send_pulse_from_bit(sim, False, amplitude, width_steps=40.0)
    rows = sim.advance(sim.steps_for(3.3 * travel_s / preset.scales.time_s), every=1).data
    torque = rows[:, k.C_T_PIPE] - rows[0, k.C_T_PIPE]
    t_s = np.arange(len(torque)) * dt_s

    def peak(lo_s: float, hi_s: float, sign: float) -> tuple[float, float]:
        window = np.flatnonzero((t_s > lo_s) & (t_s < hi_s))
        i = window[np.argmax(sign * torque[window])]
        a, b, c = torque[i - 1], torque[i], torque[i + 1]
        shift = 0.5 * (a - c) / (a - 2.0 * b + c)
        return (i + shift) * dt_s, b - 0.25 * (a - c) * shift

    t1, p1 = peak(0.5 * travel_s, 1.5 * travel_s, 1.0)
    t3, p3 = peak(2.5 * travel_s, 3.2 * travel_s, -1.0)
    assert abs(t1 - travel_s) <= dt_s
    assert abs(t3 - 3.0 * travel_s) <= dt_s
    assert p1 == pytest.approx(amplitude, rel=0.01)   # the top doubles nothing: T = b + Z w
    assert -p3 == pytest.approx(p1, rel=0.01)


@pytest.mark.parametrize("name", ["field_8p5in_shale", "field_8p5in_deviated"])
def test_field_losses_keep_eta_per_round_trip(name: str) -> None:
    """Aarsnes & van de Wouw's eta = 0.70 is the amplitude a torsional wave keeps over a
    round trip (their code: d omega/dt = -kt omega, kt = -ln eta per one-way travel time).
    A pulse on a uniform pipe of the field string's one-way travel time, damped at the
    field preset's torsional rate: its peak at the top after 3 L / c (one round trip after
    its first arrival) is 0.70 of the first, to the wake that viscous damping leaves."""
    field = load_preset(name).string
    rate = field.sections[0].torsional_damping_per_s
    length_m = field.torsional_travel_s * math.sqrt(79.3e9 / 7850.0)
    preset = string_preset([{**PIPE, "length_m": 0.5 * length_m}] * 2,
                           torsional_damping_per_s=rate, damping_points=64)
    sim = si.off_bottom_simulator(preset, TopDrive(mode="kinematic", inertia_ratio=14.0))
    dt_s = sim.config.dtau * preset.scales.time_s
    travel_s = preset.string.torsional_travel_s
    assert travel_s == pytest.approx(field.torsional_travel_s, rel=1e-9)
    amplitude = 0.02 * preset.params.omega0 * float(sim.string_arrays()[2][sg.W_Z, 0])
    si.send_pulse_from_bit(sim, False, amplitude, width_steps=40.0)
    rows = sim.advance(sim.steps_for(3.3 * travel_s / preset.scales.time_s), every=1).data
    torque = rows[:, k.C_T_PIPE] - rows[0, k.C_T_PIPE]
    t_s = np.arange(len(torque)) * dt_s
    first = np.max(torque[(t_s > 0.5 * travel_s) & (t_s < 1.5 * travel_s)])
    back = -np.min(torque[(t_s > 2.5 * travel_s) & (t_s < 3.2 * travel_s)])
    assert back / first == pytest.approx(0.70, abs=0.02)


def test_junction_transmits_as_the_impedances_say() -> None:
    """Pipe on collars: the pulse from the bit reaches the top with the transmission
    coefficient of a torque wave from Z_collar into Z_pipe, 2 Z_pipe / (Z_pipe + Z_collar)."""
    preset = string_preset([{**PIPE, "length_m": 2500.0}, {**COLLAR, "length_m": 200.0}])
    sim = si.off_bottom_simulator(preset, TopDrive(mode="kinematic", inertia_ratio=14.0))
    z_pipe, z_collar = (s.torsional_impedance_nm_s for s in preset.string.sections)
    amplitude = 1e-3
    si.send_pulse_from_bit(sim, False, amplitude, width_steps=40.0)
    travel_s = preset.string.torsional_travel_s
    rows = sim.advance(sim.steps_for(1.1 * travel_s / preset.scales.time_s), every=1).data
    arrived = np.max(rows[:, k.C_T_PIPE] - rows[0, k.C_T_PIPE])
    assert arrived == pytest.approx(amplitude * 2 * z_pipe / (z_pipe + z_collar), rel=0.01)


# ---- modes --------------------------------------------------------------------------------
def closed_form_two_section_hz(preset, axial: bool, bit_inertia: float = 0.0,
                               count: int = 3) -> list[float]:
    """Roots in omega of the two-section condition (one material, wave speed c, k = omega / c,
    fixed top, a lumped ``bit_inertia`` J at the bit, kg m^2 or kg): with u1 = A sin kx in the
    top section, u2 = B cos ky + C sin ky in the bottom one, continuity of u and of the
    force S u' at the junction and S2 u2'(L2) = J omega^2 u2(L2) at the bit give
    S1 cos cos - S2 sin sin - J omega c (sin1 cos2 + S1 / S2 cos1 sin2) = 0, which for J = 0
    is tan(k L1) tan(k L2) = S1 / S2; bracketed on a fine grid."""
    top, bottom = preset.string.sections
    c = top.axial_speed_m_s if axial else top.torsional_speed_m_s
    s1, s2 = ((top.axial_stiffness_n, bottom.axial_stiffness_n) if axial else
              (top.torsional_stiffness_nm, bottom.torsional_stiffness_nm))
    w = np.linspace(1e-4, 2 * math.pi * 5.0, 2_000_001)
    sin1, cos1 = np.sin(w * top.length_m / c), np.cos(w * top.length_m / c)
    sin2, cos2 = np.sin(w * bottom.length_m / c), np.cos(w * bottom.length_m / c)
    g = s1 * cos1 * cos2 - s2 * sin1 * sin2 \
        - bit_inertia * w * c * (sin1 * cos2 + s1 / s2 * cos1 * sin2)
    i = np.flatnonzero(np.sign(g[:-1]) != np.sign(g[1:]))[:count]
    roots = w[i] - g[i] * (w[i + 1] - w[i]) / (g[i + 1] - g[i])
    return list(roots / (2 * math.pi))


def test_field_modes_identified_from_the_ring_down() -> None:
    """The field string's modes with its bit inertia (torsion; the axial line has no lumped
    bit mass): transfer matrices against the closed form, and the ring-down finds them."""
    preset = load_preset("field_8p5in_shale")
    modes = si.identify_modes(preset)
    bit = preset.string.bit_inertia_kg_m2
    assert bit > 0.0                          # the closed form's inertia term is exercised
    for axial, identified, analytic in ((False, modes.torsional_identified_hz,
                                         modes.torsional_analytic_hz),
                                        (True, modes.axial_identified_hz,
                                         modes.axial_analytic_hz)):
        closed = closed_form_two_section_hz(preset, axial, 0.0 if axial else bit)
        assert analytic == pytest.approx(closed, rel=1e-5)
        assert len(identified) == 3
        assert identified == pytest.approx(analytic, rel=0.005)
    # the figures for this string (fixed top, free bit, E = 206 GPa)
    free = dataclasses.replace(preset.string, bit_inertia_kg_m2=0.0)
    assert sg.analytic_modes_hz(free, 3, axial=False) == pytest.approx(
        [0.2115, 0.7276, 1.3211], abs=1e-4)
    assert modes.axial_analytic_hz == pytest.approx([0.3616, 1.1983, 2.1463], abs=1e-4)


def test_modes_of_a_three_section_string_with_a_bit_inertia() -> None:
    """Drill pipe, heavy-weight pipe, collars and a lumped bit inertia: the ring-down finds
    the transfer-matrix modes (which include the bit inertia)."""
    hwdp = {"outer_radius_m": 0.0635, "inner_radius_m": 0.0381, "length_m": 150.0}
    preset = string_preset([{**PIPE, "length_m": 1800.0}, hwdp,
                            {**COLLAR, "length_m": 120.0}], bit_inertia_kg_m2=40.0)
    modes = si.identify_modes(preset)
    assert modes.torsional_identified_hz == pytest.approx(modes.torsional_analytic_hz,
                                                          rel=0.005)
    assert modes.axial_identified_hz == pytest.approx(modes.axial_analytic_hz, rel=0.005)
    # no damping: the formula gives 0 and the fit of the free response finds ~0
    for analytic, identified in ((modes.torsional_analytic_damping_ratio,
                                  modes.torsional_identified_damping_ratio),
                                 (modes.axial_analytic_damping_ratio,
                                  modes.axial_identified_damping_ratio)):
        assert analytic == [0.0, 0.0, 0.0]
        assert len(identified) == 3 and all(abs(z) < 1e-4 for z in identified)


def test_a_wave_guide_stepped_every_8_bit_steps_keeps_its_modes_and_reflection() -> None:
    """string.bit_substeps = 8: the delay lines move every 8 steps of the bit law (the waves
    arriving at the ends held between), so the travel times are rounded to 8 dtau. The
    three-section string's ring-down still finds the transfer-matrix modes within 0.5 %
    (its parts span 13 to 1070 wave steps), and the drive's loop still reflects as the
    formula says, within 0.03 as with one step for all (a held wave delays an end by half a
    wave step: 0.15 ms, 1e-3 rad of phase at 1 Hz)."""
    hwdp = {"outer_radius_m": 0.0635, "inner_radius_m": 0.0381, "length_m": 150.0}
    preset = string_preset([{**PIPE, "length_m": 1800.0}, hwdp,
                            {**COLLAR, "length_m": 120.0}], bit_inertia_kg_m2=40.0,
                           bit_substeps=8)
    assert preset.kernel_string.substeps == 8
    modes = si.identify_modes(preset)
    assert modes.torsional_identified_hz == pytest.approx(modes.torsional_analytic_hz,
                                                          rel=0.005)
    assert modes.axial_identified_hz == pytest.approx(modes.axial_analytic_hz, rel=0.005)
    result = si.measure_reflection(preset, seconds=60.0)
    assert np.max(np.abs(np.array(result.r_measured) - result.r_analytic)) < 0.03


@pytest.mark.parametrize(("value", "pieces"), [
    (0, ("string.bit_substeps", "0", "[1, 64]")),
    (2.5, ("string.bit_substeps", "2.5", "integer")),
    (64, ("string.bit_substeps", "wave", "64"))])
def test_bad_bit_substeps_are_one_line_naming_the_key(value: object,
                                                      pieces: tuple[str, ...]) -> None:
    """Out of range, not whole, or so coarse that a part of the string (the collars' half
    part, 120 m / 16 / 2 axially: 0.73 ms, 20 steps) is shorter than one wave step: one
    ParameterError line that names the key."""
    with pytest.raises(ParameterError) as err:
        preset = string_preset([{**PIPE, "length_m": 1800.0}, {**COLLAR, "length_m": 120.0}],
                               bit_substeps=value, torsional_damping_per_s=0.5,
                               axial_damping_per_s=0.5, damping_points=16)
        Simulator(preset.params, SimConfig(dtau=preset.dtau), top_drive=preset.top_drive,
                  scales=preset.scales, string=preset.kernel_string)
    message = str(err.value)
    assert "\n" not in message and all(p in message for p in pieces), message


def test_a_hook_loop_faster_than_the_axial_round_trip_is_refused() -> None:
    """The hook's WOB loop is tuned on the string's static stiffness; the top of the wave
    guide first answers with its impedance alone, so the loop's gain on that path is
    round trip / hook_wob_time_s for one uniform section (2 L / c_a, c_a = sqrt(E / rho)).
    Below the round trip the preset is one line naming the key, and the refusal is needed:
    the same string built past the check with a loop at 0.8 of the round trip runs away.
    This string has no axial losses, so the echo from the bit comes back whole and can
    double the direct path's gain: at 2.5 round trips (gain 0.4, doubled 0.8) it drills
    with the mean WOB at the applied weight."""
    length_m = 2500.0                      # one pipe, in two sections (a preset needs two)
    uniform = [{**PIPE, "length_m": 2000.0}, {**PIPE, "length_m": 500.0}]
    round_trip_s = 2.0 * length_m / math.sqrt(FIELD_PHYSICAL["youngs_modulus_pa"]
                                              / FIELD_PHYSICAL["density_kg_m3"])
    with pytest.raises(ParameterError) as err:
        string_preset(uniform, hook_wob_time_s=0.9 * round_trip_s)
    message = str(err.value)
    assert "\n" not in message and "string.hook_wob_time_s" in message, message
    assert f"{round_trip_s:.3g} s" in message, message

    def drill(preset, spec: sg.StringSpec, seconds: float) -> np.ndarray:
        sc = preset.scales
        sim = Simulator(preset.params, SimConfig(dtau=preset.dtau), top_drive=preset.top_drive,
                        scales=sc, string=sg.kernel_string(spec, sc.time_s, sc.torque_nm,
                                                           sc.length_m, sc.force_n))
        steps = round(seconds / (sc.time_s * preset.dtau))
        return sim.advance(steps, every=steps // 100).column(k.C_WOB) * sc.force_n

    steady = string_preset(uniform, hook_wob_time_s=2.5 * round_trip_s)
    wob_n = drill(steady, steady.string, 20.0)
    assert np.all(np.isfinite(wob_n))
    assert wob_n[50:].mean() == pytest.approx(FIELD_PHYSICAL["applied_wob_n"], rel=0.1)
    fast = dataclasses.replace(steady.string, hook_wob_time_s=0.8 * round_trip_s)
    with pytest.raises(NumericalFault):
        drill(steady, fast, 20.0)


def test_peaks_are_named_after_the_mode_they_sit_near() -> None:
    """On a walled string the wall can damp axial mode 1 out of the ring-down: the lowest
    peaks found (1.19 and 2.14 Hz on the deviated preset's free axial modes 0.36, 1.20,
    2.15) are modes 2 and 3, not 1 and 2; a peak 25 % off every mode names none."""
    modes_hz = [0.3616, 1.1983, 2.1463]
    assert si.peaks_by_mode([1.19, 2.14], modes_hz) == [None, 1.19, 2.14]
    assert si.peaks_by_mode([0.36 * 1.25, 1.2, 1.21, 2.1463], modes_hz) == [None, 1.2, 2.1463]
    assert si.peaks_by_mode([], modes_hz) == [None, None, None]


def test_light_pipe_on_a_heavy_bha_approaches_the_lumped_model() -> None:
    """A pipe much lighter than its BHA: mode 1 tends to sqrt(C / I) / 2 pi of RGD07 eq. (1),
    both in the formula and in the simulated ring-down."""
    thin = {**PIPE, "length_m": 2000.0}                       # 186 kg m^2
    heavy = {"outer_radius_m": 0.2, "inner_radius_m": 0.05, "length_m": 100.0}  # 1963
    preset = string_preset([thin, heavy], physical={"bit_radius_m": 0.25})   # a bit round it
    _mass, inertia, stiffness = sg.lumped_equivalent(preset.string)
    lumped_hz = math.sqrt(stiffness / inertia) / (2 * math.pi)
    modes = si.identify_modes(preset, count=1)
    assert modes.torsional_analytic_hz[0] == pytest.approx(lumped_hz, rel=0.01)
    assert modes.torsional_identified_hz[0] == pytest.approx(lumped_hz, rel=0.01)


# ---- damping ratios ---------------------------------------------------------------------
PIPE_55 = {"outer_radius_m": 0.0699, "inner_radius_m": 0.0605}   # 5.5-in 21.9 lb/ft
COLLAR_8 = {"outer_radius_m": 0.1016, "inner_radius_m": 0.0397}  # 8-in collars
HWDP = {"outer_radius_m": 0.0635, "inner_radius_m": 0.0381}


def exact_damped_pole(spec: sg.StringSpec, axial: bool, s0: complex) -> complex:
    """The complex natural frequency s of the continuous damped string near ``s0``, by a
    path of its own: in a section with mass-proportional damping gamma,
    m (s^2 + gamma s) u = S u'', so u = u0 cosh(kappa x) + F0 sinh(kappa x) / (S kappa) with
    kappa = sqrt(s^2 + gamma s) / c; fixed top, and at the bit F + J_bit s^2 u = 0 (no bit
    inertia axially); secant iterations on that end condition."""
    def end(s: complex) -> complex:
        u, f = 0j, 1.0 + 0j
        for sec in spec.sections:
            if axial:
                c, stiff, gamma = (sec.axial_speed_m_s, sec.axial_stiffness_n,
                                   sec.axial_damping_per_s)
            else:
                c, stiff, gamma = (sec.torsional_speed_m_s, sec.torsional_stiffness_nm,
                                   sec.torsional_damping_per_s)
            kappa = cmath.sqrt(s * s + gamma * s) / c
            x = kappa * sec.length_m
            u, f = (u * cmath.cosh(x) + f * cmath.sinh(x) / (stiff * kappa),
                    u * stiff * kappa * cmath.sinh(x) + f * cmath.cosh(x))
        return f + (0.0 if axial else spec.bit_inertia_kg_m2) * s * s * u

    s_prev, s = s0, s0 * (1.0 + 1e-4)
    for _ in range(100):
        s_prev, s = s, s - end(s) * (s - s_prev) / (end(s) - end(s_prev))
        if abs(s - s_prev) < 1e-13 * abs(s):
            break
    return s


def exact_damping_ratios(spec: sg.StringSpec, axial: bool, modes_hz: list[float],
                         guesses: list[float]) -> list[float]:
    """sigma / |s| of :func:`exact_damped_pole` near each undamped mode, started from the
    damping ratios ``guesses``."""
    out = []
    for f, zeta in zip(modes_hz, guesses, strict=True):
        w = 2 * math.pi * f
        s = exact_damped_pole(spec, axial, complex(-zeta * w, w * math.sqrt(1 - zeta**2)))
        out.append(-s.real / abs(s))
    return out


@pytest.mark.parametrize("axial", [False, True])
def test_one_rate_gives_every_mode_gamma_over_two_omega(axial: bool) -> None:
    """Mass-proportional damping with one rate: every mode decays at gamma / 2, so
    zeta_k = gamma / (2 omega_k) exactly; the energy-weighted formula reduces to it, and
    the complex modes of the continuous string have it too."""
    gamma = 0.7
    preset = string_preset([{**PIPE_55, "length_m": 3000.0}, {**HWDP, "length_m": 150.0},
                            {**COLLAR_8, "length_m": 200.0}],
                           torsional_damping_per_s=gamma, axial_damping_per_s=gamma)
    modes_hz = sg.analytic_modes_hz(preset.string, 6, axial=axial)
    expected = [gamma / (4 * math.pi * f) for f in modes_hz]
    analytic = sg.analytic_damping_ratios(preset.string, modes_hz, axial)
    assert analytic == pytest.approx(expected, rel=1e-12)
    assert exact_damping_ratios(preset.string, axial, modes_hz, expected) == pytest.approx(
        expected, rel=1e-9)


def per_section_preset(scale: float):
    """Drill pipe, heavy-weight pipe and collars, each with its own rates (x ``scale``),
    and an undamped bit inertia."""
    rates = ((0.02, 0.2), (0.08, 0.05), (0.2, 0.01))
    sections = [{**PIPE, "length_m": 1800.0}, {**HWDP, "length_m": 150.0},
                {**COLLAR, "length_m": 120.0}]
    return string_preset([{**sec, "torsional_damping_per_s": scale * t,
                           "axial_damping_per_s": scale * a}
                          for sec, (t, a) in zip(sections, rates, strict=True)],
                         bit_inertia_kg_m2=40.0)


@pytest.mark.parametrize("axial", [False, True])
def test_per_section_rates_give_the_first_order_damping_ratio(axial: bool) -> None:
    """Rates that differ from section to section, and a bit inertia that has none: the
    formula is the first-order term of the exact complex modes, so what it misses falls as
    the square of the rates (10 x smaller rates, about 100 x smaller error)."""
    errors = []
    for scale in (1.0, 0.1):
        spec = per_section_preset(scale).string
        modes_hz = sg.analytic_modes_hz(spec, 6, axial=axial)
        analytic = sg.analytic_damping_ratios(spec, modes_hz, axial)
        exact = exact_damping_ratios(spec, axial, modes_hz, analytic)
        errors.append(max(abs(a / e - 1) for a, e in zip(analytic, exact, strict=True)))
    assert errors[0] < 1e-3
    assert errors[1] < 0.03 * errors[0]


def test_a_damped_string_turns_steadily_once_twisted_for_its_dampers() -> None:
    """Off bottom under a kinematic top, the damped string as hang_off_bottom leaves it
    (each part carrying the drag D w of every damper below it, string.fill_steady) stays as
    it is; filled untwisted (the same speed, no drag carried), it rings."""
    preset = per_section_preset(10.0)
    drive = TopDrive(mode="kinematic", inertia_ratio=14.0)
    speeds = []
    for twisted in (True, False):
        sim = si.off_bottom_simulator(preset, drive)
        if not twisted:
            wave, wave_i, wave_f, parts = sim.string_arrays()
            no_drag = wave_f.copy()
            no_drag[sg.W_D] = 0.0
            sg.fill_steady(wave, wave_i, no_drag, 0, parts[0], 0.0,
                           float(sim.state[k.S_OMEGA_S]))
        rows = sim.advance(sim.steps_for(3.0), every=1).data
        speeds.append(np.abs(rows[:, k.C_OMEGA] / preset.params.omega0 - 1).max())
    assert speeds[0] < 1e-12
    assert speeds[1] > 1e-3


def test_drilling_starts_steady_on_the_damped_string() -> None:
    """At t = 0 the damped field string carries the trivial bit torque plus the drag of
    its dampers (rate x inertia x speed, summed: the viscous torque of the whole string),
    and the drive's loop holds that torque: the drive's speed does not move in the first
    0.1 s (no damper sheds a wave before the bit's own motion reaches the top, 0.85 s)."""
    preset = load_preset("field_8p5in_shale")
    sim = Simulator(preset.params, SimConfig(dtau=preset.dtau), top_drive=preset.top_drive,
                    scales=preset.scales, string=preset.kernel_string)
    omega0 = preset.params.omega0
    drag = sum(s.torsional_damping_per_s * s.inertia_kg_m2 for s in preset.string.sections)
    drag_scaled = drag * omega0 / (preset.scales.torque_nm * preset.scales.time_s)
    assert sim.state[k.S_MOTOR_TORQUE] == pytest.approx(sim.trivial.torque + drag_scaled,
                                                       rel=1e-12)
    rows = sim.advance(sim.steps_for(0.1 / preset.scales.time_s), every=1).data
    assert np.abs(rows[:, k.C_OMEGA_S] / omega0 - 1).max() < 1e-12


DAMPED_STRINGS = {
    # 1000 m of 5-in pipe on 300 m of 6.75-in collars, one rate: zeta_1 = 0.37 and 0.21
    "short_heavy": ([{**PIPE, "length_m": 1000.0}, {**COLLAR, "length_m": 300.0}],
                    {"torsional_damping_per_s": 1.5, "axial_damping_per_s": 1.5}),
    # 4000 m of 5.5-in pipe on 100 m of 8-in collars, light rates
    "long_light": ([{**PIPE_55, "length_m": 4000.0}, {**COLLAR_8, "length_m": 100.0}],
                   {"torsional_damping_per_s": 0.3, "axial_damping_per_s": 0.5}),
    # pipe, heavy-weight pipe, collars, each its own rates: zeta_1 = 0.45 torsional
    "per_section": ([{**PIPE, "length_m": 2000.0, "torsional_damping_per_s": 0.4,
                      "axial_damping_per_s": 0.6},
                     {**HWDP, "length_m": 150.0, "torsional_damping_per_s": 0.8,
                      "axial_damping_per_s": 1.0},
                     {**COLLAR_8, "length_m": 200.0, "torsional_damping_per_s": 1.2,
                      "axial_damping_per_s": 1.4}], {}),
}


@pytest.mark.parametrize("name", sorted(DAMPED_STRINGS))
def test_identified_damping_ratios_match_the_analytic(name: str) -> None:
    """The damping ratios fitted to the damped string's simulated free response agree with
    the analytic ones within 10 % for the first 3 modes of each kind (the kernel lumps the
    damping into 4 point dampers per section; measured within 5 %). The expectation is
    gamma / (2 omega_k) for one rate and the exact complex modes for per-section rates."""
    sections, rates = DAMPED_STRINGS[name]
    preset = string_preset(sections, **rates)
    modes = si.identify_modes(preset)
    for axial, modes_hz, analytic, identified in (
            (False, modes.torsional_analytic_hz, modes.torsional_analytic_damping_ratio,
             modes.torsional_identified_damping_ratio),
            (True, modes.axial_analytic_hz, modes.axial_analytic_damping_ratio,
             modes.axial_identified_damping_ratio)):
        key = "axial_damping_per_s" if axial else "torsional_damping_per_s"
        if key in rates:
            expected = [rates[key] / (4 * math.pi * f) for f in modes_hz]
        else:
            expected = exact_damping_ratios(preset.string, axial, modes_hz, analytic)
        assert analytic == pytest.approx(expected, rel=0.01)     # first order: 0.4 %
        assert None not in identified
        assert identified == pytest.approx(expected, rel=0.10)


# ---- reflection ------------------------------------------------------------------------
def test_reflection_of_the_speed_loop_matches_the_formula() -> None:
    preset = load_preset("field_8p5in_shale")
    result = si.measure_reflection(preset, seconds=60.0)
    assert len(result.f_hz) >= 8 and min(result.f_hz) <= 0.05 and max(result.f_hz) >= 2.0
    assert np.max(np.abs(np.array(result.r_measured) - result.r_analytic)) < 0.03


def test_reflection_through_the_bench() -> None:
    """The drive's own loop through the closed-loop bench (sampled at 100 Hz) gives the
    formula too. At the string's first torsional mode the emulated drives of soft_torque
    (a damper 2 Z there: |r| = 1/3) and z_torque (Z there: r = 0) absorb at least half of a
    wave (the issue's bar, |r| <= 0.5), where the stiff loop reflects nearly all of it."""
    from drill_sim_ros.control.reflection import measure_reflection_with
    from tests.control.native_reflection import native_reflection
    preset = load_preset("field_8p5in_shale")
    # measure_reflection_with(FIELD, "none", seconds=60.0): its runs, shared with
    # tests/control/test_stability.py
    native_f_hz = si.reflection_frequencies()
    native_r = np.abs(native_reflection(native_f_hz))
    drive = preset.top_drive.physical(preset.scales)
    z = preset.string.sections[0].torsional_impedance_nm_s
    formula = si.analytic_reflection(z, drive.inertia_kg_m2, drive.kp_nm_s, drive.ki_nm,
                                     native_f_hz)
    assert np.max(np.abs(native_r - formula)) < 0.03
    first_mode = np.array(sg.analytic_modes_hz(preset.string, 1))
    r_first = {name: measure_reflection_with("field_8p5in_shale", name, seconds=60.0,
                                             f_hz=first_mode).r_measured[0]
               for name in ("stiff", "soft_torque", "z_torque")}
    assert r_first["soft_torque"] <= 0.5 and r_first["z_torque"] <= 0.5, r_first
    assert r_first["stiff"] > 0.95, r_first


def hold_deficit(inertia_fraction: float, period_s: float) -> float:
    """|r| - 1 of a drive emulating J_v = inertia_fraction J through a setpoint held over
    period_s, on the field preset: 2 Z (P / 2)(1 / J_v - 1 / J)
    (controllers.SoftDrive.droop_per_nm_s)."""
    preset = load_preset("field_8p5in_shale")
    z = preset.string.sections[0].torsional_impedance_nm_s
    j = preset.top_drive.physical(preset.scales).inertia_kg_m2
    return 2.0 * z * 0.5 * period_s * (1.0 / (inertia_fraction * j) - 1.0 / j)


def preset_without_motor(tmp_path: Path) -> str:
    """The field preset's file with its drive's motor taken out (no lag, no torque rate
    limit: the drive the hold's formulas assume), written into ``tmp_path``."""
    from drill_sim_ros.model.presets import preset_path
    from drill_sim_ros.model.validate_input import read_preset_file
    data = read_preset_file(preset_path("field_8p5in_shale"))
    data["top_drive"] = {**data["top_drive"], "motor_lag_s": 0.0}
    del data["top_drive"]["max_torque_rate_nm_s"]
    path = tmp_path / "field_no_motor.yaml"
    path.write_text(json.dumps(data))              # JSON is YAML
    return str(path)


def test_the_reference_controllers_are_passive_through_the_collars_ring(tmp_path: Path
                                                                         ) -> None:
    """|r| <= 1 from 0.05 Hz to a sixth of the control rate (16.7 Hz at 100 Hz, past the
    collars' c / L = 15.9 Hz) for stiff, soft_torque and z_torque, on the field drive with
    its motor (0.8 ms lag: the soft drives' series damper counts it,
    controllers.SoftDrive.droop_per_nm_s) and without it. Without their series damper
    (hold_margin -> 0) the emulated drives on the drive without a motor return more than
    they receive above a few Hz, by the hold's deficit: |r| - 1 -> 2 Z (P / 2)(1 / J_v -
    1 / J), 0.0041 and 0.0058 on the field drive; that figure comes from the formula, and
    the measured excess must match it."""
    from drill_sim_ros.control.reflection import measure_reflection_with
    f_hz = np.array([0.05, 0.2115, 0.5, 1.0, 2.0, 4.0, 8.0, 12.0, 16.0, 16.7])
    no_motor = preset_without_motor(tmp_path)

    def reflection(name: str, preset: str = no_motor, **params: float) -> np.ndarray:
        return np.array(measure_reflection_with(preset, name, seconds=40.0, settle_s=10.0,
                                                f_hz=f_hz, params=params).r_measured)

    assert np.all(reflection("stiff") <= 1.0)
    assert np.all(reflection("stiff", "field_8p5in_shale") <= 1.0)
    for name, fraction in (("soft_torque", 0.2), ("z_torque", 0.15)):
        r = reflection(name)
        assert np.all(r <= 1.0), (name, r)
        bare = reflection(name, hold_margin=1e-9)
        assert np.max(bare) - 1.0 == pytest.approx(hold_deficit(fraction, 0.01), rel=0.15), \
            (name, bare)
        motor = reflection(name, "field_8p5in_shale")
        assert np.all(motor <= 1.0), (name, motor)


def test_the_series_damper_moves_the_holds_excess_above_a_quarter_of_the_control_rate(
        tmp_path: Path) -> None:
    """Near the control's Nyquist rate the emulated drives return more than they receive,
    and the series damper makes it more, not less: it acts with a delay of a period P, so
    its real admittance goes as cos(w P), negative above a quarter of the control rate.
    With the hold's deficit d = 2 Z (P / 2)(1 / J_v - 1 / J) and the damper's admittance m
    times it (m = hold_margin, 2 on a drive without a motor lag), |r| - 1 = d (1 - m
    cos(w P)): 2.9 d at 45 Hz (controllers.SoftDrive.droop_per_nm_s; docs/closed-loop.md)."""
    from drill_sim_ros.control.reflection import band_top_hz, measure_reflection_with
    period_s, margin = 0.01, 2.0
    f_hz = np.array([0.7 * band_top_hz(1.0 / period_s), band_top_hz(1.0 / period_s)])
    no_motor = preset_without_motor(tmp_path)
    for name, fraction in (("soft_torque", 0.2), ("z_torque", 0.15)):
        r = np.array(measure_reflection_with(no_motor, name, seconds=40.0,
                                             settle_s=10.0, f_hz=f_hz).r_measured)
        expected = hold_deficit(fraction, period_s) \
            * (1.0 - margin * np.cos(2.0 * np.pi * f_hz * period_s))
        assert r - 1.0 == pytest.approx(expected, rel=0.15), (name, r)


def test_an_impedance_matched_drive_reflects_nothing() -> None:
    """A drive whose loop is a pure damper equal to the pipe's Z (kp = Z, ki = 0, a tiny
    inertia): |r| = |Z - kp - i w J| / |Z + kp + i w J| -> nearly 0 at low frequency."""
    preset = load_preset("field_8p5in_shale")
    z = preset.string.sections[0].torsional_impedance_nm_s
    f = np.array([0.1, 0.3, 1.0])
    r = si.analytic_reflection(z, 1.0, z, 0.0, f)
    assert np.all(r < 0.02)


# ---- energy ------------------------------------------------------------------------------
def energy_residual(dtau: float) -> float:
    """Motor work minus (drive kinetic energy + string energy changes + bit-rock
    dissipation) in the torsional line, relative to the motor work, over a speed step."""
    preset = string_preset([{**PIPE, "length_m": 2500.0}, {**COLLAR, "length_m": 200.0}])
    sim = Simulator(preset.params, SimConfig(dtau=dtau), perturb_v=1e-3,
                    top_drive=preset.top_drive, scales=preset.scales,
                    string=preset.kernel_string)
    wave, wave_i, wave_f, parts = sim.string_arrays()
    j = preset.top_drive.inertia_ratio

    def stored() -> float:
        omega_s = float(sim.state[k.S_OMEGA_S])
        return (sg.line_energy(wave, wave_i, wave_f, 0, parts[0], dtau)
                + 0.5 * j * omega_s**2)

    e0 = stored()
    sim.set_inputs(omega_s=1.3 * preset.params.omega0)
    rows = sim.advance(sim.steps_for(8.0), every=1).data
    omega_s_next = np.append(rows[1:, k.C_OMEGA_S], sim.state[k.S_OMEGA_S])
    omega_bit_next = np.append(rows[1:, k.C_OMEGA], sim.state[k.S_OMEGA])
    work = float(np.sum(rows[:, k.C_MOTOR_TORQUE] * omega_s_next) * dtau)
    dissipated = float(np.sum(rows[:, k.C_TOB] * omega_bit_next) * dtau)
    return abs(work - (stored() - e0) - dissipated) / abs(work)


def test_energy_balances_with_no_damping_to_a_tolerance_that_shrinks_with_the_step() -> None:
    coarse, fine = energy_residual(1e-4), energy_residual(2.5e-5)
    assert coarse < 1e-2
    assert fine < 0.5 * coarse


def test_damping_rate_sets_the_mode_damping_ratio() -> None:
    """Mass-proportional damping rate gamma gives every mode the damping ratio
    gamma / (2 omega_k): the ring-down of mode 1 decays per cycle by exp(-2 pi zeta)."""
    gamma = 0.05
    thin = {**PIPE, "length_m": 2500.0}
    preset = string_preset([thin, {**COLLAR, "length_m": 200.0}],
                           torsional_damping_per_s=gamma)
    sim = si.off_bottom_simulator(preset, TopDrive(mode="kinematic", inertia_ratio=14.0))
    z0 = float(sim.string_arrays()[2][sg.W_Z, 0])
    si.send_pulse_from_bit(sim, False, 0.02 * preset.params.omega0 * z0, width_steps=2000.0)
    data, hz = si._ring_down(sim, 120.0, (k.C_OMEGA,))
    omega1 = 2 * math.pi * si.identify_modes(preset, count=1).torsional_analytic_hz[0]
    # envelope of mode 1: the signal low-passed well below mode 2, amplitude per cycle
    x = data[:, 0] - data[:, 0].mean()
    spectrum = np.fft.rfft(x)
    f = np.fft.rfftfreq(x.size, 1 / hz)
    spectrum[f > 0.45] = 0.0
    mode1 = np.fft.irfft(spectrum, x.size)
    t = np.arange(x.size) / hz
    late = (t > 20) & (t < 100)
    envelope = np.abs(mode1[late])
    peaks_t = t[late][1:-1][(envelope[1:-1] > envelope[:-2]) & (envelope[1:-1] >= envelope[2:])]
    peaks_a = envelope[1:-1][(envelope[1:-1] > envelope[:-2]) & (envelope[1:-1] >= envelope[2:])]
    rate = -np.polyfit(peaks_t, np.log(peaks_a), 1)[0]
    assert rate == pytest.approx(gamma / 2, rel=0.1)          # zeta omega1 = gamma / 2
    assert omega1 > 0


def test_the_end_sample_leaves_the_distributed_string_untouched() -> None:
    """advance_into with sample_end takes one step on the side and undoes it: the run goes
    on exactly as one that never sampled."""
    preset = load_preset("field_8p5in_shale")
    sims = [Simulator(preset.params, SimConfig(dtau=1e-4), perturb_v=1e-3,
                      top_drive=preset.top_drive, scales=preset.scales,
                      string=preset.kernel_string) for _ in range(2)]
    out = np.empty((400, k.N_COLS))
    for _ in range(20):
        sims[0].advance_into(out, 136, 136, sample_end=True)
        sims[1].advance(136)
    assert np.array_equal(sims[0].state, sims[1].state)
    assert np.array_equal(sims[0].string_arrays()[0], sims[1].string_arrays()[0])
    assert np.array_equal(sims[0].string_arrays()[1], sims[1].string_arrays()[1])
    end = out[1]                                  # the end sample of the last run
    step = sims[1].advance(1, every=1).data[0]    # what the next step records at its start
    assert np.array_equal(end, step)
