"""The drill string as a preset describes it, SI: its uniform hollow sections, the spec
of the whole string (lumped or distributed, the hook, the well around it), the lumped
equivalent and what each kind of wave sees in a section (:class:`LineProperties`)."""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field, replace

from drill_sim_ros.model.well import Well

STRING_LUMPED = 0
STRING_DISTRIBUTED = 1
STRING_MODELS = ("lumped", "distributed")

STEEL_DENSITY_KG_M3 = 7850.0
STEEL_SHEAR_MODULUS_PA = 79.3e9
STEEL_YOUNGS_MODULUS_PA = 206.0e9


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
