"""The drill string between the top drive and the bit: lumped (RGD07) or a wave guide.

* ``lumped``: RGD07 eq. (1) and (25), a torsional spring C with the BHA inertia I and mass M
  at the bit (the paper's model, bit for bit).
* ``distributed``: a chain of uniform hollow sections (drill pipe, heavy-weight pipe,
  collars, ...), each carrying torsional waves at c_t = sqrt(G / rho) and axial waves at
  c_a = sqrt(E / rho), with impedances Z_t = J_p sqrt(G rho) and Z_a = A sqrt(E rho).

The distributed string is solved by the method of characteristics. In a uniform lossless
section the Riemann invariants ``a = T + Z w`` (travelling down) and ``b = T - Z w``
(travelling up), with T the torque the upper part applies to the lower and w the angular
speed, are carried unchanged at the wave speed: a section whose travel time is a whole
number of steps is a pair of delay lines, exact, with no numerical dispersion or diffusion.
Section boundaries are rounded to whole steps on the cumulative travel time (each within
half a step). At a junction, speed is continuous and the torques balance; with a point
damper D there (torque D w), w = (a_in - b_in) / (Z_up + Z_down + D), and the outgoing waves
follow. Distributed viscous damping (force per length proportional to the local speed,
rate ``gamma`` = damping per unit mass, 1/s) is lumped into ``damping_points`` point dampers
per section, each at the middle of an equal part. A string in a well whose wall holds a
friction is cut instead into cells of one wave step (:func:`wall_cells`), and every junction
between two cells carries the damping and the wall's Coulomb friction of half of each
(:func:`to_junctions`): the friction's resolution is the wave step. Axial waves use the same
machinery with force and velocity; a torsional junction and the axial one nearest in depth
share one wall contact (:func:`junction_pairs`).

Everything compiled here works in the kernel's units (time t*, torque C, force unit
zeta eps a L*, length L*; RGD07 eqs. 19-20).
"""

from __future__ import annotations

import functools
import itertools
import math
from dataclasses import dataclass, field, replace

import numpy as np
from numba import njit

from drill_sim_ros.model.well import Well

STRING_LUMPED = 0
STRING_DISTRIBUTED = 1
STRING_MODELS = ("lumped", "distributed")

STEEL_DENSITY_KG_M3 = 7850.0
STEEL_SHEAR_MODULUS_PA = 79.3e9
STEEL_YOUNGS_MODULUS_PA = 206.0e9

# rows of the integer and float layout arrays of the delay lines
# int64 (W_INT_ROWS, parts): steps, buffer offset, slot, and the other line's part whose
# junction lies nearest in depth to this part's (the two motions of one wall contact)
W_LEN, W_OFF, W_POS, W_PAIR = 0, 1, 2, 3
W_INT_ROWS = 4
# float64 (W_ROWS, segments), per part, of the junction below it: impedance, point damper,
# the wall's static and dynamic friction limits (0: no wall contact), the stick band, the
# surface slip (m / t*) per unit of the line's speed (r_o; L*), and two rows of state: the
# junction's speed last step (the stick band's memory) and the friction power summed over
# the steps (x dtau: the work the wall took)
W_Z, W_D, W_FS, W_FD, W_VS, W_SLIP, W_LAST, W_WORK = 0, 1, 2, 3, 4, 5, 6, 7
W_ROWS = 8


# ---- sections (SI) ------------------------------------------------------------------------
def _bounds(low: float, high: float, low_open: bool = False) -> dict[str, tuple]:
    """A field's allowed range, kept in its metadata: the preset reader checks every key of
    a section or a string block against it (one definition of each range)."""
    return {"range": (low, high, low_open)}


@dataclass(frozen=True)
class Section:
    """One uniform hollow section of the string, SI.

    Radii and length in m; density kg/m^3; moduli Pa; damping rates in 1/s: the viscous
    force per unit length is ``rate x (mass or inertia per unit length) x local speed``, so
    a section moving rigidly would lose speed as exp(-rate t) and mode k of a uniform string
    has the damping ratio rate / (2 omega_k). The fields without a default are the ones a
    preset must give; each field's metadata holds its allowed range.
    """

    outer_radius_m: float = field(metadata=_bounds(0.0, 10.0, low_open=True))
    inner_radius_m: float = field(metadata=_bounds(0.0, 10.0))
    length_m: float = field(metadata=_bounds(0.0, 1e5, low_open=True))
    density_kg_m3: float = field(default=STEEL_DENSITY_KG_M3,
                                 metadata=_bounds(0.0, 1e5, low_open=True))
    shear_modulus_pa: float = field(default=STEEL_SHEAR_MODULUS_PA,
                                    metadata=_bounds(0.0, 1e13, low_open=True))
    youngs_modulus_pa: float = field(default=STEEL_YOUNGS_MODULUS_PA,
                                     metadata=_bounds(0.0, 1e13, low_open=True))
    torsional_damping_per_s: float = field(default=0.0, metadata=_bounds(0.0, 1e3))
    axial_damping_per_s: float = field(default=0.0, metadata=_bounds(0.0, 1e3))

    @property
    def polar_moment_m4(self) -> float:
        """J = pi/2 (ro^4 - ri^4) (RGD07, after eq. 1)."""
        return 0.5 * math.pi * (self.outer_radius_m**4 - self.inner_radius_m**4)

    @property
    def area_m2(self) -> float:
        return math.pi * (self.outer_radius_m**2 - self.inner_radius_m**2)

    @property
    def torsional_speed_m_s(self) -> float:
        return math.sqrt(self.shear_modulus_pa / self.density_kg_m3)

    @property
    def axial_speed_m_s(self) -> float:
        return math.sqrt(self.youngs_modulus_pa / self.density_kg_m3)

    @property
    def torsional_impedance_nm_s(self) -> float:
        """Z = J sqrt(G rho), N m per rad/s."""
        return self.polar_moment_m4 * math.sqrt(self.shear_modulus_pa * self.density_kg_m3)

    @property
    def axial_impedance_n_s_per_m(self) -> float:
        """Z = A sqrt(E rho), N per m/s."""
        return self.area_m2 * math.sqrt(self.youngs_modulus_pa * self.density_kg_m3)

    @property
    def torsional_stiffness_nm(self) -> float:
        """G J (N m^2 per rad): torque = G J x twist per metre."""
        return self.shear_modulus_pa * self.polar_moment_m4

    @property
    def axial_stiffness_n(self) -> float:
        """E A (N): force = E A x strain."""
        return self.youngs_modulus_pa * self.area_m2

    @property
    def mass_kg(self) -> float:
        return self.density_kg_m3 * self.area_m2 * self.length_m

    @property
    def inertia_kg_m2(self) -> float:
        return self.density_kg_m3 * self.polar_moment_m4 * self.length_m


@dataclass(frozen=True)
class StringSpec:
    """The string as a preset describes it (SI). ``sections`` top to bottom; the bottom one
    is the BHA for the lumped equivalent. ``bit_inertia_kg_m2``: lumped inertia at the bit
    beyond the sections. ``hook_wob_time_s``: time constant of the hook's WOB loop (the
    driller's brake / autodriller holding the top so that the weight on bit follows the
    applied-WOB command). ``damping_points``: point dampers per section of a string
    without wall friction (a walled string has an element in every cell). Off bottom the
    hook picks the string up at ``hook_pickup_m_s`` until the bit
    is ``off_bottom_clearance_m`` above the rock, and holds it there; tagging bottom again
    it lowers at most at ``hook_tag_m_s`` (the driller's slack-off). ``bit_substeps``:
    steps of the bit law and the drive per step of the wave guide (1: one step for all; n:
    the delay lines are sampled at n dtau, the waves arriving at the ends held over it, and
    the ends' mean speeds sent into the lines, kernel._held_means). ``well``: the hole
    around the string (:mod:`drill_sim_ros.model.well`; None: vertical, no wall contact)."""

    model: str = "lumped"
    sections: tuple[Section, ...] = ()
    bit_inertia_kg_m2: float = field(default=0.0, metadata=_bounds(0.0, 1e6))
    hook_wob_time_s: float = field(default=5.0, metadata=_bounds(0.0, 1e4, low_open=True))
    damping_points: int = field(default=4, metadata=_bounds(1, 64))
    off_bottom_clearance_m: float = field(default=0.5, metadata=_bounds(0.0, 100.0,
                                                                        low_open=True))
    hook_pickup_m_s: float = field(default=0.05, metadata=_bounds(0.0, 10.0, low_open=True))
    hook_tag_m_s: float = field(default=0.02, metadata=_bounds(0.0, 10.0, low_open=True))
    bit_substeps: int = field(default=1, metadata=_bounds(1, 64))
    well: Well | None = None

    @property
    def distributed(self) -> bool:
        return self.model == "distributed"

    @property
    def length_m(self) -> float:
        return sum(s.length_m for s in self.sections)

    def undamped(self) -> StringSpec:
        """The same string without losses (the exact wave tests and the instruments)."""
        return replace(self, sections=tuple(
            replace(s, torsional_damping_per_s=0.0, axial_damping_per_s=0.0)
            for s in self.sections))

    @property
    def torsional_travel_s(self) -> float:
        """One-way torsional travel time, top to bit."""
        return sum(s.length_m / s.torsional_speed_m_s for s in self.sections)


def lumped_equivalent(spec: StringSpec) -> tuple[float, float, float]:
    """(M, I, C) of RGD07 eq. (1) generalised to sections: the bottom section is the BHA
    (M = its mass, I = its inertia + a third of the others'), C = the others in series."""
    bha, pipes = spec.sections[-1], spec.sections[:-1]
    compliance = sum(s.length_m / s.torsional_stiffness_nm for s in pipes)
    inertia = bha.inertia_kg_m2 + sum(s.inertia_kg_m2 for s in pipes) / 3.0
    return bha.mass_kg, inertia + spec.bit_inertia_kg_m2, 1.0 / compliance


def axial_compliance_m_per_n(spec: StringSpec) -> float:
    """Static axial compliance of the string, hook to bit: sum of L / (E A)."""
    return sum(s.length_m / s.axial_stiffness_n for s in spec.sections)


def fastest_hook_loop_s(spec: StringSpec) -> float:
    """A ``hook_wob_time_s`` the hook's loop needs to exceed on a distributed string, s.

    The loop is tuned on the static stiffness K (kp = 2 / (t_w K), :func:`kernel_string`),
    but the top of a wave guide first answers the hook's speed with its axial impedance Z
    alone; the loop's gain on that direct path is kp Z = 2 Z / (K t_w), the axial round
    trip over t_w for a uniform string. Above 1 it runs away: measured on the field
    string, a non-finite state within a second at t_w = 0.7 s (gain 1.41), and the same at
    gains of 1.09-1.1 with a twentieth and a thirtieth of steel's E. Necessary, not
    sufficient: the echo from the bit adds to the direct path, so a string without axial
    losses needs about twice this (a uniform lossless one ran away at 1.2 times it and held
    at 1.95 times; the field string's losses halve the echo and it held at 1.0 s)."""
    return 2.0 * spec.sections[0].axial_impedance_n_s_per_m * axial_compliance_m_per_n(spec)


# ---- analytic modes (transfer matrices, fixed top, free or inertia-loaded bit) -------------
@dataclass(frozen=True)
class LineProperties:
    """What one kind of wave (torsional or axial) sees in a section, SI: wave speed m/s,
    stiffness (G J in N m^2, E A in N), inertia per metre (rho J in kg m, rho A in kg/m),
    impedance (N m s or N s/m) and damping rate 1/s."""

    speed_m_s: float
    stiffness: float
    inertia_per_m: float
    impedance: float
    damping_per_s: float


@functools.lru_cache(maxsize=1024)
def line_properties(s: Section, axial: bool) -> LineProperties:
    """The properties of ``s`` for torsional or axial waves (cached: the mode searches ask
    for them at every trial frequency)."""
    if axial:
        return LineProperties(s.axial_speed_m_s, s.axial_stiffness_n,
                              s.density_kg_m3 * s.area_m2, s.axial_impedance_n_s_per_m,
                              s.axial_damping_per_s)
    return LineProperties(s.torsional_speed_m_s, s.torsional_stiffness_nm,
                          s.density_kg_m3 * s.polar_moment_m4, s.torsional_impedance_nm_s,
                          s.torsional_damping_per_s)


def bit_inertia_of(spec: StringSpec, axial: bool) -> float:
    """The lumped inertia at the bit end of a line: the bit's (torsion), none (axial)."""
    return 0.0 if axial else spec.bit_inertia_kg_m2


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


# ---- the delay lines in kernel units --------------------------------------------------------
@dataclass(frozen=True)
class WaveLine:
    """One kind of wave (torsional or axial) along the string, in kernel units: per part
    (top to bottom) its travel time in tau, impedance, the point damper below it, its length
    in m, and the wall friction at the junction below it: the static and dynamic limits of
    its torque (force), the stick band and the surface slip per unit speed (the rows of
    ``wave_f``; empty: no wall contact)."""

    travel_tau: tuple[float, ...]
    impedance: tuple[float, ...]
    damper_below: tuple[float, ...]
    length_m: tuple[float, ...] = ()
    static_below: tuple[float, ...] = ()
    dynamic_below: tuple[float, ...] = ()
    stick_speed: tuple[float, ...] = ()
    slip_per_speed: tuple[float, ...] = ()


def section_parts(lossy: bool, damping_points: int) -> tuple[tuple[float, ...], int]:
    """How a section of a string without wall friction is cut into delay-line parts:
    lossless, one part; damped, ``damping_points`` point dampers, each at the middle of an
    equal share of the section carrying that share's damping, and the lines run from
    element to element, so the parts are a half share, ``damping_points - 1`` whole ones and
    a half (a junction with no element between two equal lines would only pass the waves
    on, and cost a step's work). Returns the parts' lengths in shares, and the shares in
    the section. (A walled string is cut into cells instead, :func:`wall_cells`.)"""
    if not lossy:
        return (1.0,), 1
    return (0.5, *([1.0] * (damping_points - 1)), 0.5), damping_points


def walled(spec: StringSpec) -> bool:
    """Whether ``spec`` lies in a well whose wall holds a friction: its lines are then cut
    into cells of one wave step (:func:`wall_cells`)."""
    return spec.well is not None and spec.well.has_friction


def wall_cells(spec: StringSpec, axial: bool, wave_step_s: float) -> list[int]:
    """The cells of each section of a walled string for one kind of wave: the sections'
    ends rounded to whole wave steps on the cumulative travel time (each within half a
    step, as every section end), and each section cut into as many equal cells as it then
    spans steps, so every cell is one step of the delay lines (line_steps gives 1 each:
    the cells' ends lie within half a step of the grid). At least one cell a section."""
    travel = np.cumsum([s.length_m / line_properties(s, axial).speed_m_s
                        for s in spec.sections])
    edges = np.rint(travel / wave_step_s).astype(np.int64)
    return [max(1, int(n)) for n in np.diff(np.concatenate(([0], edges)))]


def _cell_normals(spec: StringSpec, s: Section, top_m: float, cells: int) -> list[float]:
    """The wall's normal force on each of the ``cells`` equal cells of ``s`` (its top at
    measured depth ``top_m``), N: the one place the string asks the well for it
    (:meth:`Well.normal_force_n`)."""
    well, share = spec.well, s.length_m / cells
    return [well.normal_force_n(top_m + i * share, top_m + (i + 1) * share, s.area_m2,
                                s.density_kg_m3) for i in range(cells)]


def to_junctions(per_cell: list[float]) -> list[float]:
    """Per-cell quantities (a cell's damping, its friction limit) moved onto the junctions
    between the cells: each junction takes half of the cell above and half of the cell
    below it, the first and last junctions also the outer half of the end cells, so the sum
    is kept; the last entry (the line's bottom, no junction) is 0."""
    if len(per_cell) < 2:
        return [0.0] * len(per_cell)
    out = [0.5 * (a + b) for a, b in itertools.pairwise(per_cell)]
    out[0] += 0.5 * per_cell[0]
    out[-1] += 0.5 * per_cell[-1]
    return [*out, 0.0]


def _walled_line(spec: StringSpec, axial: bool, time_s: float, z_unit: float,
                 force_unit: float, speed_unit: float, wave_step_s: float) -> WaveLine:
    """:func:`wave_line` of a walled string: every cell of one wave step
    (:func:`wall_cells`) carries its viscous damping and the wall's Coulomb friction (static
    and dynamic limits of the torque r_o mu N, axially of the force mu N, N the cell's
    normal force), moved onto the junctions between the cells (:func:`to_junctions`); the
    stick band (rad/s; axially r_o omega_s m/s) and the surface slip per unit speed (r_o;
    1) of the cell above each junction."""
    mu = spec.well.side_friction
    travel, z, length, damp, fs, fd, band, slip = [], [], [], [], [], [], [], []
    top_m = 0.0
    for s, cells in zip(spec.sections, wall_cells(spec, axial, wave_step_s), strict=True):
        props = line_properties(s, axial)
        share, arm = s.length_m / cells, 1.0 if axial else s.outer_radius_m
        normal = _cell_normals(spec, s, top_m, cells)
        travel += [share / props.speed_m_s / time_s] * cells
        z += [props.impedance / z_unit] * cells
        length += [share] * cells
        damp += [props.damping_per_s * props.inertia_per_m * share / z_unit] * cells
        fs += [arm * mu.static * n / force_unit for n in normal]
        fd += [arm * mu.dynamic * n / force_unit for n in normal]
        band += [mu.stick_speed_rad_s * (s.outer_radius_m if axial else 1.0) / speed_unit
                 ] * cells
        slip += [(1.0 if axial else s.outer_radius_m) * speed_unit * time_s] * cells
        top_m += s.length_m
    return WaveLine(tuple(travel), tuple(z), tuple(to_junctions(damp)), tuple(length),
                    tuple(to_junctions(fs)), tuple(to_junctions(fd)), tuple(band),
                    tuple(slip))


def wave_line(spec: StringSpec, axial: bool, time_s: float, z_unit: float,
              force_unit: float, length_unit: float, wave_step_s: float = 0.0) -> WaveLine:
    """Parts of ``spec`` for one kind of wave. ``z_unit`` converts an SI impedance (and a
    damper, N m s/rad or N s/m) to kernel units, ``force_unit`` a torque (force),
    ``length_unit`` a length (the axial speed's unit L* / t*). A walled string
    (:func:`walled`) is cut into cells of ``wave_step_s`` (the wave guide's step, s;
    :func:`_walled_line`); any other into lossless sections and, where damped,
    ``damping_points`` point dampers per section (:func:`section_parts`)."""
    speed_unit = (length_unit if axial else 1.0) / time_s
    if walled(spec):
        return _walled_line(spec, axial, time_s, z_unit, force_unit, speed_unit,
                            wave_step_s)
    travel, z, damper, length = [], [], [], []
    for s in spec.sections:
        props = line_properties(s, axial)
        t_tau = s.length_m / props.speed_m_s / time_s
        shares, points = section_parts(props.damping_per_s > 0.0, spec.damping_points)
        d_share = props.damping_per_s * props.inertia_per_m * s.length_m / points / z_unit
        travel += [share * t_tau / points for share in shares]
        z += [props.impedance / z_unit] * len(shares)
        damper += [d_share] * (len(shares) - 1) + [0.0]
        length += [share * s.length_m / points for share in shares]
    return WaveLine(tuple(travel), tuple(z), tuple(damper), tuple(length))


def section_part_counts(spec: StringSpec, axial: bool, wave_step_s: float) -> list[int]:
    """The delay-line parts of each section for one kind of wave (:func:`wave_line`)."""
    if walled(spec):
        return wall_cells(spec, axial, wave_step_s)
    return [len(section_parts(line_properties(s, axial).damping_per_s > 0.0,
                              spec.damping_points)[0]) for s in spec.sections]


def line_steps(line: WaveLine, dtau: float) -> np.ndarray:
    """Whole steps per part: boundaries rounded on the cumulative travel time, so each one
    lies within half a step of its true place. ParameterError-free: the caller checks >= 1."""
    edges = np.rint(np.cumsum(line.travel_tau) / dtau).astype(np.int64)
    return np.diff(np.concatenate(([0], edges)))


def _rows(line: WaveLine, name: str) -> np.ndarray:
    """A per-part tuple of ``line`` as an array (zeros where the line has none)."""
    values = getattr(line, name)
    return np.asarray(values, dtype=float) if values else np.zeros(len(line.travel_tau))


def junction_pairs(lines: tuple[WaveLine, ...]) -> np.ndarray:
    """For every part of the two ``lines`` (torsional, axial), the column of the other
    line's part whose junction (its bottom) lies nearest in depth to this part's: the
    torsional and the axial motion of one wall contact, which slides on their joint slip
    (:func:`wall_slips`). Lines cut alike pair part j with part j of the other line."""
    bottoms = [np.cumsum(line.length_m) for line in lines]
    offsets = (len(lines[0].travel_tau), 0)
    pairs = []
    for own, other, offset in ((bottoms[0], bottoms[1], offsets[0]),
                               (bottoms[1], bottoms[0], offsets[1])):
        inner = other[:-1] if other.size > 1 else other
        right = np.clip(np.searchsorted(inner, own), 0, inner.size - 1)
        left = np.clip(right - 1, 0, inner.size - 1)
        nearest = np.where(np.abs(inner[left] - own) <= np.abs(inner[right] - own), left,
                           right)
        pairs.append(nearest + offset)
    return np.concatenate(pairs)


def build_lines(lines: tuple[WaveLine, ...], dtau: float
                ) -> tuple[np.ndarray, np.ndarray, np.ndarray, tuple[int, ...]]:
    """The layout of the delay lines of ``lines`` (torsional first): ``(wave_i, wave_f,
    wave, counts)`` with ``wave_i`` int64 (W_INT_ROWS, parts) rows W_LEN, W_OFF, W_POS,
    W_PAIR (:func:`junction_pairs`), ``wave_f`` float64 (W_ROWS, parts) rows W_Z .. W_WORK
    (the state rows zero), an empty buffer, and the parts per line."""
    lens = np.concatenate([line_steps(line, dtau) for line in lines])
    wave_i = np.zeros((W_INT_ROWS, lens.size), dtype=np.int64)
    wave_i[W_LEN] = lens
    wave_i[W_OFF] = np.concatenate(([0], np.cumsum(2 * lens)[:-1]))
    wave_i[W_PAIR] = junction_pairs(lines)
    wave_f = np.zeros((W_ROWS, lens.size))
    for row, name in ((W_Z, "impedance"), (W_D, "damper_below"), (W_FS, "static_below"),
                      (W_FD, "dynamic_below"), (W_VS, "stick_speed"),
                      (W_SLIP, "slip_per_speed")):
        wave_f[row] = np.concatenate([_rows(line, name) for line in lines])
    return wave_i, wave_f, np.zeros(int(2 * lens.sum())), tuple(len(x.travel_tau)
                                                                 for x in lines)


@njit(cache=True, inline="always")
def wall_slips(wave_f: np.ndarray, j: int, pair: int, own_speed: float,
               other_speed: float) -> tuple[float, float, bool]:
    """The surface slips (m per t*) of junction ``j``'s own motion and of the other line's
    at the same junction ``pair``, and whether the contact slides: the two motions share one
    contact, which is stuck while its total slip sqrt(u^2 + o^2) is within the stick band
    r_o omega_s (Karnopp) and slides outside it."""
    u = abs(own_speed) * wave_f[W_SLIP, j]
    o = abs(other_speed) * wave_f[W_SLIP, pair]
    band = wave_f[W_VS, j] * wave_f[W_SLIP, j]
    return u, o, u * u + o * o > band * band


def steady_friction(wave_f: np.ndarray, j: int, pair: int, speed: float,
                    other_speed: float) -> float:
    """The wall's friction at junction ``j`` moving steadily at ``speed`` (the other line
    at ``other_speed``): none at rest; within the stick band the static limit; sliding, the
    dynamic force's share along this line, u / sqrt(u^2 + o^2) (:func:`wall_slips`)."""
    if speed == 0.0 or wave_f[W_FS, j] == 0.0:
        return 0.0
    u, o, sliding = wall_slips(wave_f, j, pair, speed, other_speed)
    if not sliding:
        return math.copysign(wave_f[W_FS, j], speed)
    return math.copysign(wave_f[W_FD, j] * u / math.sqrt(u * u + o * o), speed)


def fill_steady(wave: np.ndarray, wave_i: np.ndarray, wave_f: np.ndarray, lo: int, hi: int,
                end_force: float, speed: float, other_speed: float = 0.0) -> float:
    """Parts ``lo..hi-1`` turning (moving) steadily at ``speed``, the other line at
    ``other_speed`` (its junction W_PAIR beside each junction): each part carries
    the force at the bottom end, ``end_force``, plus the drag D x speed of every point
    damper and the wall's friction (:func:`steady_friction`) of every junction below its
    top (the elements below part j sit at its bottom), so no element sheds a wave. Every
    junction's speed memory is ``speed``. Returns the force at the top, what the drive (the
    hook) must hold."""
    wall = np.array([steady_friction(wave_f, j, int(wave_i[W_PAIR, j]), speed, other_speed)
                     for j in range(lo, hi)])
    drag_below = (np.cumsum(wave_f[W_D, lo:hi][::-1])[::-1] * speed
                  + np.cumsum(wall[::-1])[::-1])
    for j in range(lo, hi):
        n, off, z = wave_i[W_LEN, j], wave_i[W_OFF, j], wave_f[W_Z, j]
        force = end_force + float(drag_below[j - lo])
        wave[off:off + n] = force + z * speed
        wave[off + n:off + 2 * n] = force - z * speed
    wave_f[W_LAST, lo:hi] = speed
    return end_force + speed * float(wave_f[W_D, lo:hi].sum()) + float(wall.sum())


@dataclass(frozen=True)
class KernelString:
    """A string in kernel units, what the simulator builds its arrays from.

    ``model``: STRING_LUMPED or STRING_DISTRIBUTED; ``lines``: (torsional, axial);
    ``bit_inertia``: J_bit / I; ``hook_kp``, ``hook_ki``: the WOB loop's gains (hook speed
    per unit force error, and per unit force error and tau); ``bha_part``: the torsional
    part at whose top the BHA speed is read; ``spec``: the SI description; ``pickup``,
    ``clearance``: the hook's pick-up speed off bottom and the bit's clearance then;
    ``tag_speed``: its lowering speed's cap when it tags bottom again; ``substeps``: the
    bit law's steps per wave-guide step (StringSpec.bit_substeps)."""

    model: int
    lines: tuple[WaveLine, ...] = ()
    bit_inertia: float = 0.0
    hook_kp: float = 0.0
    hook_ki: float = 0.0
    bha_part: int = 0
    spec: StringSpec | None = None
    pickup: float = 0.0
    clearance: float = 0.0
    tag_speed: float = 0.0
    substeps: int = 1


LUMPED = KernelString(STRING_LUMPED)


def kernel_string(spec: StringSpec, time_s: float, torque_nm: float, length_m: float,
                  force_n: float, wave_dtau: float = 0.0) -> KernelString:
    """``spec`` in kernel units: time t*, torque C, length L*, force zeta eps a L*
    (RGD07 eqs. 19-20). The hook loop is critically damped with time constant
    ``hook_wob_time_s`` on the string's static axial stiffness. ``wave_dtau``: the wave
    guide's step in tau (numerics.dtau x bit_substeps), which a walled string's cells span
    (:func:`wall_cells`; a string without wall friction ignores it)."""
    if not spec.distributed:
        return KernelString(STRING_LUMPED, spec=spec)
    if walled(spec) and wave_dtau <= 0.0:
        raise ValueError("a walled string is cut into cells of the wave step: give wave_dtau")
    z_torsion = torque_nm * time_s                     # N m s/rad per kernel unit
    z_axial = force_n * time_s / length_m               # N s/m per kernel unit
    step_s = wave_dtau * time_s
    torsion = wave_line(spec, False, time_s, z_torsion, torque_nm, length_m, step_s)
    axial = wave_line(spec, True, time_s, z_axial, force_n, length_m, step_s)
    stiffness = length_m / force_n / axial_compliance_m_per_n(spec)
    t_w = spec.hook_wob_time_s / time_s
    bha_part = len(torsion.travel_tau) - section_part_counts(spec, False, step_s)[-1]
    return KernelString(STRING_DISTRIBUTED, (torsion, axial),
                        spec.bit_inertia_kg_m2 / (torque_nm * time_s**2),
                        2.0 / (t_w * stiffness), 1.0 / (t_w**2 * stiffness), bha_part, spec,
                        spec.hook_pickup_m_s * time_s / length_m,
                        spec.off_bottom_clearance_m / length_m,
                        spec.hook_tag_m_s * time_s / length_m, spec.bit_substeps)


# ---- compiled: the string's step (the kernel's seam) ------------------------------------
# The kernel sees the string through three calls per step: ``ends`` (what the string
# presents at the bit, in the bit law's affine form, and at the top), ``advance`` (one step
# on between the new end speeds) and ``bha_speed`` (for the sample). ``lay`` is the
# distributed string's layout for a run, from :func:`layout`. A lumped string (``wave``
# None) is RGD07's spring, compiled apart. An element at the junctions (a point damper;
# wall friction, a shock sub) is a row of ``wave_f``, a term of :func:`junction_speed` and
# its share of the steady twist in :func:`fill_steady`.
@njit(cache=True, inline="always")
def layout(wave_i: np.ndarray | None, parts_t: int, bit_inertia: float, echo: float,
           bha_part: int) -> tuple[int, int, float, float, int]:
    """The distributed string's layout for a run: the torsional parts (the axial ones
    follow), all parts, the bit's lumped inertia, the torsional bottom's echo (1: the bit;
    0: anechoic) and the part at whose top the BHA speed is read."""
    return (parts_t, 0 if wave_i is None else wave_i.shape[1], bit_inertia, echo, bha_part)


@njit(cache=True, inline="always")
def ends(wave: np.ndarray | None, wave_i: np.ndarray | None, wave_f: np.ndarray | None,
         lay: tuple, psi: float, dt: float, phi_s: float, phi: float, v: float, omega: float,
         w_app: float, omega_s: float, v_hook: float) -> tuple[float, ...]:
    """What the string presents over this step: at the bit, the affine forms of the bit law
    (bit_rock) ``v0, kick_v, f_ext, omega0, kick_w, t_ext``; at the top, the torque at the
    quill and the force at the hook above the hanging weight."""
    if wave is None:
        return _lumped_ends(psi, dt, phi_s, phi, v, omega, w_app)
    return _distributed_ends(wave, wave_i, wave_f, lay, dt, omega_s, v, omega, v_hook)


@njit(cache=True, inline="always")
def advance(wave: np.ndarray | None, wave_i: np.ndarray | None, wave_f: np.ndarray | None,
            lay: tuple, omega_top: float, v_top: float, omega_bit: float,
            v_bit: float) -> None:
    """The string one step on between the speeds over the step at its ends (the drive's
    and the hook's at the top, the bit's at the bottom); the lumped spring keeps no waves.
    (No early return: in an inlined function it cost the distributed step 7 %, measured.)"""
    if wave is not None:
        drive_line(wave, wave_i, wave_f, 0, lay[0], omega_top, omega_bit, lay[3])
        drive_line(wave, wave_i, wave_f, lay[0], lay[1], v_top, v_bit, 1.0)


@njit(cache=True, inline="always")
def bha_speed(wave: np.ndarray | None, wave_i: np.ndarray | None, wave_f: np.ndarray | None,
              lay: tuple, omega: float) -> float:
    """The BHA's angular speed now: the bit's ``omega`` in the lumped string, else the speed
    at the top of the BHA's part."""
    return omega if wave is None else speed_at_top_of(wave, wave_i, wave_f, lay[4])


@njit(cache=True, inline="always")
def _lumped_ends(psi: float, dt: float, phi_s: float, phi: float, v: float, omega: float,
                 w_app: float) -> tuple[float, ...]:
    """:func:`ends` of RGD07's lumped string (eq. 25): the spring torque PHI_S - PHI and
    psi dtau on the applied weight at the bit; at the top the same torque and the applied
    weight."""
    t_pipe = phi_s - phi                      # pipe torque C (PHI_S - PHI), scaled
    return v, psi * dt, w_app, omega, dt, t_pipe, t_pipe, w_app


@njit(cache=True, inline="always")
def _distributed_ends(wave: np.ndarray, wave_i: np.ndarray, wave_f: np.ndarray, lay: tuple,
                      dt: float, omega_s: float, v: float, omega: float,
                      v_hook: float) -> tuple[float, ...]:
    """:func:`ends` of the wave guide: the arriving waves and the end impedances, with the
    bit's lumped inertia; at the top b + Z w with the drive's and the hook's speeds."""
    parts_t, parts, bit_inertia, _, _ = lay
    b_top_t, a_bot_t = arriving(wave, wave_i, 0, parts_t)
    b_top_a, a_bot_a = arriving(wave, wave_i, parts_t, parts)
    v0, kick_v, f_ext = bottom_end(a_bot_a, wave_f[W_Z, parts - 1], 0.0, v, dt)
    omega0, kick_w, t_ext = bottom_end(a_bot_t, wave_f[W_Z, parts_t - 1], bit_inertia,
                                       omega, dt)
    return (v0, kick_v, f_ext, omega0, kick_w, t_ext, b_top_t + wave_f[W_Z, 0] * omega_s,
            b_top_a + wave_f[W_Z, parts_t] * v_hook)


@njit(cache=True, inline="always")
def junction_speed(wave_f: np.ndarray, j: int, a_in: float, b_in: float,
                   pair: int) -> float:
    """The speed of the junction below part ``j``, from the waves arriving at it (``a_in``
    from above, ``b_in`` from below): continuous across it, with the torques balanced on
    its elements, the point damper D (torque D w) and the wall's friction F:
    (a_in - Z_j w) - (b_in + Z_j+1 w) = D w + F. Without wall contact (W_FS 0) that is
    w = (a_in - b_in) / (Z_j + Z_j+1 + D), the lossless scattering and its damper."""
    if wave_f[W_FS, j] == 0.0:
        return (a_in - b_in) / (wave_f[W_Z, j] + wave_f[W_Z, j + 1] + wave_f[W_D, j])
    return wall_junction(wave_f, j, a_in - b_in, pair)


@njit(cache=True, inline="always")
def wall_junction(wave_f: np.ndarray, j: int, push: float, pair: int) -> float:
    """:func:`junction_speed` with the wall's Coulomb friction (model.well), implicit in the
    new speed w, with Z = Z_j + Z_j+1 + D. The contact (:func:`wall_slips`, from the last
    speeds of this junction and the other line's ``pair``):

    * within the stick band, or sliding with the other line still: set-valued, as the bit's
      stick (eq. 32): held still while the unbalanced torque ``push`` = a_in - b_in is
      within the limit (static in the band, dynamic outside it: Karnopp), else
      w Z = push - limit sign(push);
    * sliding with both lines moving: the dynamic force lies along the slip velocity, so
      this line feels F = F_d u / sqrt(u^2 + o^2) = c w, c = F_d s / sqrt(u^2 + o^2) (s the
      slip per unit speed), taken with the last slip in the root: w = push / (Z + c). A
      string that rotates drags axially as a viscous c = F_d / (r_o omega), and the other
      way round. Written with one division, the step's dearest operation: with
      k = F_d s and r = sqrt(u^2 + o^2), w = push r / (Z r + k), and the power
      c w^2 = k w push / (Z r + k).

    Keeps the speed for the band, and the friction power summed in W_WORK."""
    u, o, sliding = wall_slips(wave_f, j, pair, wave_f[W_LAST, j], wave_f[W_LAST, pair])
    z = wave_f[W_Z, j] + wave_f[W_Z, j + 1] + wave_f[W_D, j]
    if sliding and o > 0.0:
        k = wave_f[W_FD, j] * wave_f[W_SLIP, j]
        r = math.sqrt(u * u + o * o)
        per_z = push / (z * r + k)
        w = per_z * r
        wave_f[W_WORK, j] += k * w * per_z
    else:
        limit = wave_f[W_FD, j] if sliding else wave_f[W_FS, j]
        w = 0.0
        if abs(push) > limit:
            w = (push - math.copysign(limit, push)) / z
        wave_f[W_WORK, j] += limit * abs(w)
    wave_f[W_LAST, j] = w
    return w


# ---- compiled: one step of a line -------------------------------------------------------
@njit(cache=True, inline="always")
def drive_line(wave: np.ndarray, wave_i: np.ndarray, wave_f: np.ndarray, lo: int, hi: int,
               w_top: float, w_bottom: float, echo: float) -> None:
    """A line (parts ``lo`` .. ``hi``) one step on, driven at its ends by the speeds over the
    step: a = b + 2 Z w_top enters at the top, b = (a - 2 Z w_bottom) x ``echo`` at the
    bottom (``echo`` 1; 0: an anechoic bottom that sends nothing back)."""
    b_top, a_bottom = arriving(wave, wave_i, lo, hi)
    scatter(wave, wave_i, wave_f, lo, hi, b_top + 2.0 * wave_f[W_Z, lo] * w_top,
            (a_bottom - 2.0 * wave_f[W_Z, hi - 1] * w_bottom) * echo)


@njit(cache=True, inline="always")
def arriving(wave: np.ndarray, wave_i: np.ndarray, lo: int, hi: int) -> tuple[float, float]:
    """The waves arriving now at the two ends of a line: (b at the top, a at the bottom)."""
    b_top = wave[wave_i[W_OFF, lo] + wave_i[W_LEN, lo] + wave_i[W_POS, lo]]
    a_bottom = wave[wave_i[W_OFF, hi - 1] + wave_i[W_POS, hi - 1]]
    return b_top, a_bottom


@njit(cache=True, inline="always")
def scatter(wave: np.ndarray, wave_i: np.ndarray, wave_f: np.ndarray, lo: int, hi: int,
            a_top: float, b_bottom: float) -> None:
    """One step of a line: ``a_top`` enters at the top, ``b_bottom`` at the bottom, every
    inner junction scatters what arrives (continuous speed, torques balanced with its point
    damper), and the delay lines move on by one step. Reads each slot before writing it.
    Indexes the layout arrays in place: row views would cost reference counting every step
    (about a tenth of the distributed string's step, measured). The junctions' law is
    :func:`junction_speed`; the other line's junction beside junction j is W_PAIR (the one
    nearest in depth, :func:`junction_pairs`)."""
    a_slot = wave_i[W_OFF, lo] + wave_i[W_POS, lo]
    a_in = wave[a_slot]                      # arriving at the bottom of part lo
    wave[a_slot] = a_top
    for j in range(lo, hi - 1):
        b_slot = wave_i[W_OFF, j + 1] + wave_i[W_LEN, j + 1] + wave_i[W_POS, j + 1]
        b_in = wave[b_slot]                  # arriving at the top of part j + 1
        w = junction_speed(wave_f, j, a_in, b_in, wave_i[W_PAIR, j])
        wave[wave_i[W_OFF, j] + wave_i[W_LEN, j] + wave_i[W_POS, j]] = \
            a_in - 2.0 * wave_f[W_Z, j] * w
        a_slot = wave_i[W_OFF, j + 1] + wave_i[W_POS, j + 1]
        a_next = wave[a_slot]
        wave[a_slot] = b_in + 2.0 * wave_f[W_Z, j + 1] * w
        a_in = a_next
    wave[wave_i[W_OFF, hi - 1] + wave_i[W_LEN, hi - 1] + wave_i[W_POS, hi - 1]] = b_bottom
    for j in range(lo, hi):
        pos = wave_i[W_POS, j] + 1
        wave_i[W_POS, j] = pos if pos < wave_i[W_LEN, j] else 0


@njit(cache=True, inline="always")
def speed_at_top_of(wave: np.ndarray, wave_i: np.ndarray, wave_f: np.ndarray,
                    j: int) -> float:
    """Speed at the top of part ``j`` now: (a entering last step - b arriving) / 2 Z."""
    off, n, pos = wave_i[W_OFF, j], wave_i[W_LEN, j], wave_i[W_POS, j]
    last = pos - 1 if pos > 0 else n - 1
    return (wave[off + last] - wave[off + n + pos]) / (2.0 * wave_f[W_Z, j])


@njit(cache=True, inline="always")
def bottom_end(a_in: float, z: float, mass: float, v: float,
               dt: float) -> tuple[float, float, float]:
    """The bit end of a line in the bit law's affine form (see :mod:`bit_rock`):
    ``(v0, kick, f_ext)`` with a lumped ``mass`` (inertia) at the bit moving at ``v``;
    implicit in the string's impedance, exact for ``mass = 0`` (the end moves at
    (a - F) / Z)."""
    denom = mass + dt * z
    return mass * v / denom, dt / denom, a_in


# ---- Python-side readings ------------------------------------------------------------------
def line_state(wave: np.ndarray, wave_i: np.ndarray, wave_f: np.ndarray, lo: int,
               hi: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(force, speed, impedance) of every cell of parts lo..hi-1, top to bottom, now."""
    cells = int(wave_i[W_LEN, lo:hi].sum())
    force, speed, z = np.empty(cells), np.empty(cells), np.empty(cells)
    _line_state_into(wave, wave_i, wave_f, lo, hi, force, speed, z)
    return force, speed, z


@njit(cache=True)
def _line_state_into(wave: np.ndarray, wave_i: np.ndarray, wave_f: np.ndarray, lo: int,
                     hi: int, force: np.ndarray, speed: np.ndarray, zs: np.ndarray) -> None:
    """:func:`line_state` into the caller's arrays. The slot pos - 1 - k holds the a that
    entered k steps ago (k cells below the top); the b at k cells below the top entered
    n - 1 - k steps ago at the bottom (slot pos + k)."""
    i = 0
    for j in range(lo, hi):
        n, off, pos, z = wave_i[W_LEN, j], wave_i[W_OFF, j], wave_i[W_POS, j], wave_f[W_Z, j]
        ia = pos - 1 if pos > 0 else n - 1     # walks down the a slots, wrapping
        ib = pos                               # walks up the b slots, wrapping
        for _ in range(n):
            a, b = wave[off + ia], wave[off + n + ib]
            force[i] = 0.5 * (a + b)
            speed[i] = (a - b) / (2.0 * z)
            zs[i] = z
            i += 1
            ia = ia - 1 if ia > 0 else n - 1
            ib = ib + 1 if ib + 1 < n else 0


def cells_state(wave: np.ndarray, wave_i: np.ndarray, wave_f: np.ndarray, lo: int,
                cells: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(force, speed) of the ``cells`` (ascending indices among the cells that
    :func:`line_state` lists for the line whose parts start at column ``lo``) now, the same
    values it gives there, reading no other cell."""
    force, speed = np.empty(cells.size), np.empty(cells.size)
    _cells_state_into(wave, wave_i, wave_f, lo, cells, force, speed)
    return force, speed


@njit(cache=True)
def _cells_state_into(wave: np.ndarray, wave_i: np.ndarray, wave_f: np.ndarray, lo: int,
                      cells: np.ndarray, force: np.ndarray, speed: np.ndarray) -> None:
    """:func:`cells_state` into the caller's arrays: cell k of a part (k below its top)
    holds the a in slot pos - 1 - k and the b in slot pos + k, wrapping (see
    :func:`_line_state_into`)."""
    j, top = lo, 0                 # the part of cells[i], and the index of its first cell
    for i in range(cells.size):
        cell = cells[i]
        while cell >= top + wave_i[W_LEN, j]:
            top += wave_i[W_LEN, j]
            j += 1
        n, off, pos, z = wave_i[W_LEN, j], wave_i[W_OFF, j], wave_i[W_POS, j], wave_f[W_Z, j]
        k = cell - top
        a, b = wave[off + (pos - 1 - k) % n], wave[off + n + (pos + k) % n]
        force[i] = 0.5 * (a + b)
        speed[i] = (a - b) / (2.0 * z)


def cell_depths_m(line: WaveLine, wave_i: np.ndarray, lo: int) -> np.ndarray:
    """Depth below the top of the middle of every cell of a line (its parts start at
    column ``lo`` of ``wave_i``), m."""
    depths, top = [], 0.0
    for j, length in enumerate(line.length_m):
        n = int(wave_i[W_LEN, lo + j])
        depths.append(top + (np.arange(n) + 0.5) * (length / n))
        top += length
    return np.concatenate(depths)


def line_energy(wave: np.ndarray, wave_i: np.ndarray, wave_f: np.ndarray, lo: int, hi: int,
                dtau: float) -> float:
    """Kinetic + strain energy of a line, sum of (a^2 + b^2) dtau / (4 Z) over its cells."""
    total = 0.0
    for j in range(lo, hi):
        n, off, z = int(wave_i[W_LEN, j]), int(wave_i[W_OFF, j]), float(wave_f[W_Z, j])
        total += float(np.sum(wave[off:off + 2 * n] ** 2)) * dtau / (4.0 * z)
    return total
