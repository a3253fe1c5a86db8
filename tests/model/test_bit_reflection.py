"""The bit and BHA as the pipe's termination (model/bit_reflection.py) against independent
paths: the transfer-matrix modes (string.analytic_modes_hz), energy (a lossless reactive
termination returns all of a wave), the first-order modal damping (string.modal_inertias)
with a point damper at the bit, and the bit law's slope by hand."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from drill_sim_ros.model import bit_reflection as br
from drill_sim_ros.model import string as sg
from drill_sim_ros.model import string_instruments as si
from drill_sim_ros.model.bit_rock import LAW_WEAKENING_BIT, RGD07_LAW, BitLaw
from drill_sim_ros.model.presets import load_preset

SPEC = load_preset("field_8p5in_shale").string


def test_without_slope_or_losses_the_mode_is_the_transfer_matrix_one() -> None:
    """b = 0 and no losses: the loop's phase condition with a clamped top is the fixed-top,
    inertia-loaded-bit mode that the transfer matrices find, and the BHA, a pure reactance,
    returns all of every wave (|r_bit| = 1: energy)."""
    lossless = SPEC.undamped()
    f1 = br.first_mode_hz(lossless, 0.0, 0.0, 0.6)
    assert f1 is not None
    assert abs(f1 - sg.analytic_modes_hz(lossless, 1)[0]) < 1e-6
    f = np.geomspace(0.05, 20.0, 30)
    assert np.allclose(np.abs(br.bit_reflection(lossless, 0.0, 0.0, f)), 1.0, atol=1e-9)
    assert np.allclose(np.abs(br.pipe_round_trip(lossless, f)), 1.0, atol=1e-12)


def _modal_decay_per_s(slope_nm_s: float, f_hz: float) -> float:
    """sigma = zeta omega of the clamped-top first mode to first order: (sum of rate_i x
    kinetic energy_i - b u_bit^2) / (2 x modal inertia), from the undamped mode shape."""
    w = 2.0 * math.pi * f_hz
    weights = sg.modal_inertias(w, SPEC, False)
    u_bit2 = weights[-1] / SPEC.bit_inertia_kg_m2
    rates = [s.torsional_damping_per_s for s in SPEC.sections]
    lost = sum(g * m for g, m in zip(rates, weights[:-1], strict=True))
    return (lost - slope_nm_s * u_bit2) / (2.0 * sum(weights))


def test_the_loop_gain_gives_the_modal_decay_rate() -> None:
    """With the preset's losses and a negative damper b at the bit (no lag), the loop's
    shortfall per round trip, -ln|loop| over its group delay, is the first mode's decay rate
    that the modal energy balance gives to first order: the loop gain measures growth, and
    G > 1 exactly where the mode's damping turns negative."""
    for slope in (0.0, 50.0, 100.0):
        f1 = br.first_mode_hz(SPEC, slope, 0.0, 0.6)
        assert f1 is not None

        def loop(f: float, slope: float = slope) -> complex:
            x = np.array([f])
            return complex(br.bit_reflection(SPEC, slope, 0.0, x)[0]
                           * br.pipe_round_trip(SPEC, x)[0])

        df = 1e-5
        delay_s = -(np.angle(loop(f1 + df)) - np.angle(loop(f1 - df))) / (4 * math.pi * df)
        sigma = -math.log(abs(loop(f1))) / delay_s
        assert abs(sigma - _modal_decay_per_s(slope, f1)) < 2e-3, (slope, sigma)


def test_round_trip_attenuation_of_the_loss_form() -> None:
    """d w / dt = -rate w: a travelling wave keeps exp(-rate t / 2), so well above the rate
    the pipe's round trip (2 L / c) keeps exp(-rate L / c)."""
    pipe = SPEC.sections[0]
    expected = math.exp(-pipe.torsional_damping_per_s * pipe.length_m
                        / pipe.torsional_speed_m_s)
    assert abs(abs(br.pipe_round_trip(SPEC, np.array([5.0]))[0]) - expected) < 1e-4


def test_law_slope_by_hand() -> None:
    """RGD07's law has no slope; the whole-bit weakening T0 (floor + (1 - floor) e^(-w/ws))
    has b = T0 (1 - floor) / ws e^(-w/ws), in SI with T = C T_k and w = w_k / t*."""
    torque_nm, time_s = 376.95, 0.741
    assert br.law_slope_nm_s(RGD07_LAW, 2.0, 5.0, 0.3, 4.0, torque_nm, time_s) == 0.0
    floor, speed = 0.5, 7.0 * time_s
    law = BitLaw(LAW_WEAKENING_BIT, floor, speed, 0.0)
    doc, w_f, beta, omega = 2.0, 5.0, 0.3, 3.0
    t0 = (doc + beta * w_f) * torque_nm
    expected = t0 * (1 - floor) / (speed / time_s) * math.exp(-omega / speed)
    got = br.law_slope_nm_s(law, doc, w_f, beta, omega, torque_nm, time_s)
    assert abs(got - expected) < 1e-6 * expected


def test_a_bit_on_an_endless_pipe_runs_away_when_its_slope_beats_the_pipe() -> None:
    """One lossless section and the bit's inertia I with the lagged negative damper: on an
    endless pipe (I s + Z)(1 + s tau) - b = 0, i.e. I tau s^2 + (I + Z tau) s + Z - b = 0,
    has a root in the right half plane exactly when b > Z (Routh-Hurwitz)."""
    lossless = SPEC.undamped()
    spec = replace(lossless, sections=lossless.sections[:1], bit_inertia_kg_m2=100.0)
    z = spec.sections[0].torsional_impedance_nm_s
    for tau in (0.0, 0.06):
        assert not br.runs_away(spec, 0.95 * z, tau, 0.6)
        assert br.runs_away(spec, 1.05 * z, tau, 0.6)


def test_the_time_domain_measurement_of_a_free_bha_is_the_formula() -> None:
    """The instrument (string_instruments.measure_bit_reflection) on the bit hanging free:
    the BHA's reflection, measured through the simulator's delay lines, is the lossy-line
    formula at s = 0.6 + 2 pi i f, within 0.02 up to 0.5 Hz and 0.1 to 2 Hz (the kernel's
    stepped losses depart from the continuous line's at the higher frequencies)."""
    preset = load_preset("field_8p5in_shale")
    sc = preset.scales
    f = np.array([0.1, 0.2, 0.3, 0.5, 1.0, 2.0])
    s = 0.6 + 2j * np.pi * f
    measured = si.measure_bit_reflection(preset, sc.omega_from_rpm(35.0),
                                         sc.w_from_newton(60e3), s, on_bottom=False)
    formula = br.bit_reflection_at(preset.string, 0.0, 0.0, s)
    error = np.abs(measured - formula)
    assert np.all(error[:4] < 0.02) and np.all(error < 0.1), error


def test_the_measured_reflection_of_a_drilling_bit_is_near_the_small_signal_one() -> None:
    """On bottom at 100 rpm and 60 kN (b = 46 N m s, a steady state that holds over the
    record) the measured r_bit is the small-signal termination's within 0.06 from 0.1 to
    1 Hz at Re s = 0.6 1/s; what is left is RGD07's depth-of-cut coupling, not in the
    formula."""
    from drill_sim_ros.control import stability as st
    preset = load_preset("field_8p5in_shale")
    sc = preset.scales
    f = np.array([0.1, 0.2, 0.3, 0.5, 1.0])
    s = 0.6 + 2j * np.pi * f
    measured = si.measure_bit_reflection(preset, sc.omega_from_rpm(100.0),
                                         sc.w_from_newton(60e3), s)
    slope = st.bit_slope_nm_s(preset, 100.0, 60e3)
    formula = br.bit_reflection_at(preset.string, slope, st.response_s(preset), s)
    assert np.max(np.abs(measured - formula)) < 0.06
