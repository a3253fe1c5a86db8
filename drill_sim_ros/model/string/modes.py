"""The string's analytic modes: transfer matrices of uniform sections, fixed at the top,
free or inertia-loaded at the bit (natural frequencies, modal inertias, damping ratios)."""

from __future__ import annotations

import math

from drill_sim_ros.model.string.spec import (
    Section,
    StringSpec,
    bit_inertia_of,
    line_properties,
)


def _mode_tops(omega_rad_s: float, spec: StringSpec, axial: bool
               ) -> list[tuple[float, float]]:
    """(displacement, force) at the top of every section and, last, at the bit, for the
    fixed-top string vibrating at ``omega`` with unit force at the top: the transfer of a
    uniform section of wavenumber k = omega / c and stiffness S over its length L,
    u(x) = u0 cos kx + F0 sin(kx) / (S k), F(x) = -u0 S k sin kx + F0 cos kx."""
    tops = [(0.0, 1.0)]                        # fixed top: no displacement, unit force
    for s in spec.sections:
        line = line_properties(s, axial)
        disp, force = tops[-1]
        k = omega_rad_s / line.speed_m_s
        kl = k * s.length_m
        tops.append((disp * math.cos(kl) + force * math.sin(kl) / (line.stiffness * k),
                     -disp * line.stiffness * k * math.sin(kl) + force * math.cos(kl)))
    return tops


def _mode_residual(omega_rad_s: float, spec: StringSpec, axial: bool) -> float:
    """End condition of the fixed-top string at ``omega``: the torque (force) at the bit
    minus what the bit inertia needs, for unit force at the top; zero at a natural
    frequency (:func:`_mode_tops`)."""
    disp, force = _mode_tops(omega_rad_s, spec, axial)[-1]
    return force - bit_inertia_of(spec, axial) * omega_rad_s**2 * disp


def modal_inertias(omega_rad_s: float, spec: StringSpec, axial: bool) -> list[float]:
    """Twice the kinetic energy over omega^2 of the mode shape of :func:`_mode_tops` in each
    section, then at the bit: the section's inertia per metre times the integral of u(x)^2
    over its length, and the bit inertia times u_bit^2 (kg m^2 or kg, for unit force at the
    top)."""
    tops = _mode_tops(omega_rad_s, spec, axial)
    out = [line_properties(s, axial).inertia_per_m
           * _squared_shape_integral(u0, f0, omega_rad_s, s, axial)
           for s, (u0, f0) in zip(spec.sections, tops[:-1], strict=True)]
    return [*out, bit_inertia_of(spec, axial) * tops[-1][0] ** 2]


def _squared_shape_integral(u0: float, f0: float, omega_rad_s: float, s: Section,
                            axial: bool) -> float:
    """Integral over the section of u(x)^2 = (u0 cos kx + b sin kx)^2, b = F0 / (S k), in
    closed form: u0^2 (L/2 + sin 2kL / 4k) + b^2 (L/2 - sin 2kL / 4k)
    + u0 b (1 - cos 2kL) / 2k."""
    line = line_properties(s, axial)
    k = omega_rad_s / line.speed_m_s
    b, half, two_kl = f0 / (line.stiffness * k), 0.5 * s.length_m, 2.0 * k * s.length_m
    return (u0 * u0 * (half + math.sin(two_kl) / (4.0 * k))
            + b * b * (half - math.sin(two_kl) / (4.0 * k))
            + u0 * b * (1.0 - math.cos(two_kl)) / (2.0 * k))


def analytic_damping_ratios(spec: StringSpec, modes_hz: list[float],
                            axial: bool = False) -> list[float]:
    """The damping ratio of each mode at ``modes_hz`` to first order in the damping:
    zeta_k = sum_i gamma_i T_ik / (2 omega_k sum T_ik), T_ik the kinetic energy of mode k
    in section i (:func:`modal_inertias`; the bit inertia counts in the sum, undamped).
    For one rate gamma along a string without bit inertia it is gamma / (2 omega_k), the
    exact value for mass-proportional damping."""
    rates = [line_properties(s, axial).damping_per_s for s in spec.sections]
    out = []
    for f_hz in modes_hz:
        omega = 2.0 * math.pi * f_hz
        weights = modal_inertias(omega, spec, axial)
        damped = sum(g * w for g, w in zip(rates, weights[:-1], strict=True))
        out.append(damped / (2.0 * omega * sum(weights)))
    return out


def analytic_modes_hz(spec: StringSpec, count: int = 3, axial: bool = False,
                      f_max_hz: float = 50.0) -> list[float]:
    """The first ``count`` natural frequencies of the string, fixed at the top and free at
    the bit (with its lumped inertia), by bracketing and bisection of the transfer-matrix
    end condition (for two sections of one material: tan(k L1) tan(k L2) = S1 / S2)."""
    found: list[float] = []
    step = 2.0 * math.pi * 1e-3
    w, prev = step, _mode_residual(step, spec, axial)
    while len(found) < count and w < 2.0 * math.pi * f_max_hz:
        w_next = w + step
        cur = _mode_residual(w_next, spec, axial)
        if prev == 0.0 or prev * cur < 0.0:
            lo, hi = w, w_next
            for _ in range(80):
                mid = 0.5 * (lo + hi)
                if _mode_residual(lo, spec, axial) * _mode_residual(mid, spec, axial) <= 0.0:
                    hi = mid
                else:
                    lo = mid
            found.append(0.5 * (lo + hi) / (2.0 * math.pi))
        w, prev = w_next, cur
    return found
