"""The bit and BHA as a termination of the drill pipe, small-signal, in the frequency domain.

ROS-free, numpy only. Used by ``drill_sim stability`` (control/stability.py) to predict
whether the first torsional mode grows about a steady drilling state (docs/string.md,
"Predicting the first mode's growth").

About a steady sliding state at the bit speed w0 the bit law's torque changes by
dT = -b dw_bar, with b = -dT/dw the law's slope at w0 (:func:`law_slope_nm_s`, by a
central difference of the law's own torque function) and w_bar the speed the law reads, the
bit's speed through a first-order lag of time constant tau (the law's ``response``). The
bit end then needs the torque

    Z_end(s) w = (I_b s - b / (1 + s tau)) w

from the string (I_b the bit's inertia beyond the collars): a negative damper, a source of
wave energy where b > 0. RGD07's own law adds nothing here: at a held WOB its steady torque
does not depend on the speed (b = 0); its axial-torsional coupling through the depth of cut
is not part of this termination.

Each section is a lossy transmission line. With the string's loss form (a viscous force per
unit length ``rate x inertia per metre x speed``, so d w/dt = -rate w for a rigid piece) a
section of inertia per metre m, stiffness S = G J and rate g has, in Laplace variable s,

    gamma(s) = sqrt(s (s + g)) / c,    Z(s) = Z0 sqrt((s + g) / s)

(c = sqrt(G / rho), Z0 = J sqrt(G rho)). A load Z_L seen through a section of length L is
Z_in = Z (Z_L + Z tanh(gamma L)) / (Z + Z_L tanh(gamma L)). For g << w a travelling wave
keeps |exp(-gamma x)| = exp(-g x / 2c) = exp(-g t / 2): over the pipe's round trip
(t = 2 L / c) it keeps exp(-g L / c).

Reflections are of torque waves, looking out of the pipe: r = (Z_L - Z) / (Z_L + Z), +1 at a
clamped end, -1 at a free one, |r| > 1 where the load's real part is negative (it feeds the
wave). The pipe's first mode then needs r_top r_bit exp(-2 gamma L_pipe) = 1.
"""

from __future__ import annotations

import math

import numpy as np

from drill_sim_ros.model.bit_rock import BitLaw
from drill_sim_ros.model.string import Section, StringSpec, line_properties

SLOPE_STEP = 1e-4        # central difference of the law, share of the speed


def law_slope_nm_s(law: BitLaw, doc: float, w_f: float, beta: float, omega: float,
                   torque_nm: float, time_s: float) -> float:
    """b = -dT/dw of ``law`` at the bit speed ``omega`` (kernel units, like ``doc`` and
    ``w_f``) in N m s: a central difference of the law's torque, in kernel units times
    C t* (T = C T_k, w = w_k / t*)."""
    h = SLOPE_STEP * max(abs(omega), 1e-3)
    rise = law.torque(doc, w_f, beta, omega + h) - law.torque(doc, w_f, beta, omega - h)
    return -rise / (2.0 * h) * torque_nm * time_s


def _s(f_hz: np.ndarray) -> np.ndarray:
    return 2j * np.pi * np.asarray(f_hz, dtype=float)


def line_of(section: Section, s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(gamma L, Z(s)) of ``section``'s torsional line at Laplace values ``s``."""
    line = line_properties(section, False)
    root = np.sqrt((s + line.damping_per_s) / s)
    return s * root * section.length_m / line.speed_m_s, line.impedance * root


def through(section: Section, load: np.ndarray, s: np.ndarray) -> np.ndarray:
    """The impedance ``load`` at the bottom of ``section`` as seen at its top."""
    gl, z = line_of(section, s)
    t = np.tanh(gl)
    return z * (load + z * t) / (z + load * t)


def end_impedance(bit_inertia_kg_m2: float, slope_nm_s: float, response_s: float,
                  s: np.ndarray) -> np.ndarray:
    """Z_end = I_b s - b / (1 + s tau), N m s (module doc), at Laplace values ``s``."""
    return bit_inertia_kg_m2 * s - slope_nm_s / (1.0 + s * response_s)


def bha_impedance(spec: StringSpec, slope_nm_s: float, response_s: float,
                  s: np.ndarray) -> np.ndarray:
    """What the pipe (the top section) sees below it at Laplace values ``s``: the bit end
    through every lower section, bottom up."""
    z = end_impedance(spec.bit_inertia_kg_m2, slope_nm_s, response_s, s)
    for section in reversed(spec.sections[1:]):
        z = through(section, z, s)
    return z


def below(section: Section, impedance_on_top: np.ndarray, s: np.ndarray) -> np.ndarray:
    """The load at the bottom of ``section`` that it shows as ``impedance_on_top`` at its
    top (the inverse of :func:`through`)."""
    gl, z = line_of(section, s)
    t = np.tanh(gl)
    return z * (impedance_on_top - z * t) / (z - impedance_on_top * t)


def reflection_of_load(section: Section, load: np.ndarray, s: np.ndarray) -> np.ndarray:
    """r = (Z_L - Z(s)) / (Z_L + Z(s)) of ``load`` at the bottom of ``section``."""
    z = line_of(section, s)[1]
    return (load - z) / (load + z)


def runs_away(spec: StringSpec, slope_nm_s: float, response_s: float,
              band_hz: float, points: int = 4000) -> bool:
    """True when the bit and BHA on an endless pipe (no wave ever comes back) are unstable
    by themselves below ``band_hz``: Z_BHA(s) + Z_pipe(s) has a zero with Re s > 0 there
    (then r_bit has a pole in the right half plane, and no loop gain at a mode describes the
    growth: it grows under any top). Counted by the argument principle around the rectangle
    1e-4 <= Re s <= 20 1/s, |Im s| <= 2 pi band_hz (the BHA's own poles, its clamped-top
    modes, lie above a low band)."""
    re_lo, re_hi, im_hi = 1e-4, 20.0, 2.0 * math.pi * band_hz
    edge = np.linspace(0.0, 1.0, points)
    path = np.concatenate((re_lo + (re_hi - re_lo) * edge - 1j * im_hi,      # bottom
                           re_hi + 1j * im_hi * (2.0 * edge - 1.0),           # right
                           re_hi - (re_hi - re_lo) * edge + 1j * im_hi,       # top
                           re_lo + 1j * im_hi * (1.0 - 2.0 * edge)))          # left
    total = bha_impedance(spec, slope_nm_s, response_s, path) + line_of(spec.sections[0],
                                                                        path)[1]
    turns = np.sum(np.diff(np.unwrap(np.angle(total)))) / (2.0 * math.pi)
    return bool(round(turns) != 0)


def bit_reflection(spec: StringSpec, slope_nm_s: float, response_s: float,
                   f_hz: np.ndarray) -> np.ndarray:
    """r_bit(f), complex: the torque wave's reflection by the BHA and bit, in the pipe just
    above the collars (module doc)."""
    return bit_reflection_at(spec, slope_nm_s, response_s, _s(f_hz))


def bit_reflection_at(spec: StringSpec, slope_nm_s: float, response_s: float,
                      s: np.ndarray) -> np.ndarray:
    """:func:`bit_reflection` at Laplace values ``s``."""
    return reflection_of_load(spec.sections[0],
                              bha_impedance(spec, slope_nm_s, response_s, s), s)


def pipe_round_trip(spec: StringSpec, f_hz: np.ndarray) -> np.ndarray:
    """exp(-2 gamma L) of the pipe (the top section), complex: its round trip's phase and
    attenuation."""
    return pipe_round_trip_at(spec, _s(f_hz))


def pipe_round_trip_at(spec: StringSpec, s: np.ndarray) -> np.ndarray:
    """:func:`pipe_round_trip` at Laplace values ``s``."""
    return np.exp(-2.0 * line_of(spec.sections[0], s)[0])


def first_crossing_hz(f_hz: np.ndarray, loop: np.ndarray) -> float | None:
    """The lowest frequency of ``f_hz`` (ascending) at which ``loop`` crosses the positive
    real axis (its phase a whole turn: a mode), linearly interpolated; None if none."""
    im, re = loop.imag, loop.real
    for i in range(f_hz.size - 1):
        if im[i] * im[i + 1] <= 0.0 and im[i] != im[i + 1] and re[i] + re[i + 1] > 0.0:
            return float(f_hz[i] + (f_hz[i + 1] - f_hz[i]) * im[i] / (im[i] - im[i + 1]))
    return None


def first_mode_hz(spec: StringSpec, slope_nm_s: float, response_s: float,
                  f_max_hz: float, points: int = 4000,
                  r_top: np.ndarray | float = 1.0) -> float | None:
    """The first frequency below ``f_max_hz`` at which the loop r_top r_bit exp(-2 gamma L)
    is real and positive: the phase condition of the first mode, with the bit law's
    termination and the top's reflection ``r_top`` (complex, on ``points`` frequencies
    evenly spaced up to ``f_max_hz``; default 1: a clamped top)."""
    f = np.linspace(f_max_hz / points, f_max_hz, points)
    loop = r_top * bit_reflection(spec, slope_nm_s, response_s, f) * pipe_round_trip(spec, f)
    return first_crossing_hz(f, loop)
