"""Model parameters: the physical description and the six dimensionless groups.

Richard, Germay & Detournay (2007), J. Sound Vib. 305, 432-456 (RGD07 below):

* eq. (1): lumped mass ``M``, inertia ``I`` and torsional stiffness ``C`` of the drill string;
* eqs. (19)-(24): time scale ``t*``, length scale ``L*`` and the groups
  ``n, beta, lambda, psi, W0, omega0``.

Conversions run both ways: :func:`scale` maps a :class:`PhysicalParams` to
:class:`DimensionlessParams` plus :class:`Scales`; :func:`unscale` maps the groups
back to the bit/rock/operating quantities for a given drill string and bit.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields, replace
from typing import Any

from drill_sim_ros.model.errors import ParameterError
from drill_sim_ros.model.string import StringSpec, lumped_equivalent

RPM_PER_RAD_S = 60.0 / (2.0 * math.pi)
GROUPS = ("n", "psi", "beta", "lam", "w0", "omega0")   # the six groups, eqs. (23)-(24)


def _require(name: str, value: float, low: float, high: float = math.inf,
             low_open: bool = True) -> None:
    """Raise :class:`ParameterError` naming ``name`` unless ``value`` lies in range."""
    ok = math.isfinite(value) and (value > low if low_open else value >= low) and value <= high
    if not ok:
        bracket = "(" if low_open else "["
        raise ParameterError(
            f"parameter '{name}' = {value!r} is outside the allowed range "
            f"{bracket}{low:g}, {high:g}]"
        )


@dataclass(frozen=True)
class DimensionlessParams:
    """The six groups of RGD07 eqs. (23)-(24).

    n: number of blades; beta = mu*gamma*zeta; lam = sigma*l/(zeta*eps*L*) (bluntness);
    psi = zeta*eps*a*I/(M*C) (system number); w0 = W0/(zeta*eps*a*L*) (applied weight);
    omega0 = Omega0*t* (top-drive speed).
    """

    n: int = 6
    beta: float = 0.3
    lam: float = 5.0
    psi: float = 50.0
    w0: float = 7.0
    omega0: float = 5.0

    def __post_init__(self) -> None:
        validate_dimensionless(self)

    def with_(self, **changes: Any) -> DimensionlessParams:
        """Return a copy with ``changes`` applied (validated)."""
        return replace(self, **changes)


def validate_dimensionless(p: DimensionlessParams) -> None:
    """Check every group; the error names the first bad one and its allowed range."""
    if not isinstance(p.n, int) or isinstance(p.n, bool) or not 1 <= p.n <= 64:
        raise ParameterError(f"parameter 'n' = {p.n!r} must be an integer in [1, 64]")
    _require("beta", p.beta, 0.0, 10.0, low_open=False)
    _require("lam", p.lam, 0.0, 1e4, low_open=False)
    _require("psi", p.psi, 0.0, 1e7)
    _require("w0", p.w0, 0.0, 1e4, low_open=False)
    _require("omega0", p.omega0, 0.0, 1e4, low_open=False)


@dataclass(frozen=True)
class PhysicalParams:
    """Physical description of the drilling system, SI units throughout.

    Drill pipe (p) and bottom-hole assembly (b) are uniform tubes (RGD07 eq. 1).
    """

    pipe_outer_radius_m: float = 0.0635
    pipe_inner_radius_m: float = 0.0543
    pipe_length_m: float = 2500.0
    bha_outer_radius_m: float = 0.0857
    bha_inner_radius_m: float = 0.0357
    bha_length_m: float = 200.0
    density_kg_m3: float = 7850.0
    shear_modulus_pa: float = 79.3e9
    youngs_modulus_pa: float = 206.0e9
    bit_radius_m: float = 0.108
    n_blades: int = 6
    intrinsic_specific_energy_pa: float = 230e6
    zeta: float = 0.729
    mu_gamma: float = 0.48
    contact_stress_times_wearflat_n_per_m: float = 3.0e5
    applied_wob_n: float = 60e3
    surface_rpm: float = 60.0

    def __post_init__(self) -> None:
        validate_physical(self)

    def with_(self, **changes: Any) -> PhysicalParams:
        """Return a copy with ``changes`` applied (validated)."""
        return replace(self, **changes)


def validate_physical(p: PhysicalParams) -> None:
    """Check every physical input; the error names the first bad one."""
    for name in ("pipe_outer_radius_m", "pipe_length_m", "bha_outer_radius_m", "bha_length_m",
                 "density_kg_m3", "shear_modulus_pa", "youngs_modulus_pa", "bit_radius_m",
                 "intrinsic_specific_energy_pa", "zeta", "mu_gamma"):
        _require(name, float(getattr(p, name)), 0.0, 1e15)
    _require("pipe_inner_radius_m", p.pipe_inner_radius_m, 0.0, 1e15, low_open=False)
    _require("bha_inner_radius_m", p.bha_inner_radius_m, 0.0, 1e15, low_open=False)
    if p.pipe_inner_radius_m >= p.pipe_outer_radius_m:
        raise ParameterError(
            f"parameter 'pipe_inner_radius_m' = {p.pipe_inner_radius_m!r} must be smaller "
            f"than pipe_outer_radius_m = {p.pipe_outer_radius_m!r}")
    if p.bha_inner_radius_m >= p.bha_outer_radius_m:
        raise ParameterError(
            f"parameter 'bha_inner_radius_m' = {p.bha_inner_radius_m!r} must be smaller "
            f"than bha_outer_radius_m = {p.bha_outer_radius_m!r}")
    if not isinstance(p.n_blades, int) or not 1 <= p.n_blades <= 64:
        raise ParameterError(f"parameter 'n_blades' = {p.n_blades!r} must be an integer in "
                             "[1, 64]")
    _require("contact_stress_times_wearflat_n_per_m", p.contact_stress_times_wearflat_n_per_m,
             0.0, 1e15, low_open=False)
    _require("applied_wob_n", p.applied_wob_n, 0.0, 1e9, low_open=False)
    _require("surface_rpm", p.surface_rpm, 0.0, 1e4, low_open=False)


@dataclass(frozen=True)
class Structure:
    """Lumped drill-string properties of RGD07 eq. (1)."""

    mass_kg: float
    inertia_kg_m2: float
    stiffness_nm_per_rad: float


@dataclass(frozen=True)
class Scales:
    """Units that turn dimensionless results into SI (RGD07 eqs. 19-20).

    time_s = t*; length_m = L*; force_n = zeta*eps*a*L* (unit of W); torque_nm = C (unit of T).
    """

    time_s: float
    length_m: float
    force_n: float
    torque_nm: float

    def wob_n(self, w: float) -> float:
        return w * self.force_n

    def tob_nm(self, t: float) -> float:
        return t * self.torque_nm

    def rop_m_s(self, v: float) -> float:
        return v * self.length_m / self.time_s

    def rpm(self, omega: float) -> float:
        return omega / self.time_s * RPM_PER_RAD_S

    def omega_from_rpm(self, rpm: float) -> float:
        return rpm / RPM_PER_RAD_S * self.time_s

    def w_from_newton(self, wob_n: float) -> float:
        return wob_n / self.force_n

    def rad_s(self, omega: float) -> float:
        """Dimensionless angular speed -> rad/s."""
        return omega / self.time_s

    def omega_from_rad_s(self, rad_s: float) -> float:
        return rad_s * self.time_s

    def t_from_nm(self, torque_nm: float) -> float:
        """Torque in N m -> the paper's torque unit C."""
        return torque_nm / self.torque_nm


UNIT_SCALES = Scales(time_s=1.0, length_m=1.0, force_n=1.0, torque_nm=1.0)


def structure(p: PhysicalParams, string: StringSpec | None = None) -> Structure:
    """M, I, C of RGD07 eq. (1); I includes one third of the pipe inertia. With a
    ``string`` of sections, its lumped equivalent (string.lumped_equivalent) instead."""
    if string is not None and string.sections:
        return Structure(*lumped_equivalent(string))
    j_pipe = 0.5 * math.pi * (p.pipe_outer_radius_m**4 - p.pipe_inner_radius_m**4)
    j_bha = 0.5 * math.pi * (p.bha_outer_radius_m**4 - p.bha_inner_radius_m**4)
    mass = p.density_kg_m3 * math.pi * (p.bha_outer_radius_m**2 - p.bha_inner_radius_m**2) \
        * p.bha_length_m
    inertia = p.density_kg_m3 * (j_bha * p.bha_length_m + j_pipe * p.pipe_length_m / 3.0)
    stiffness = p.shear_modulus_pa * j_pipe / p.pipe_length_m
    return Structure(mass, inertia, stiffness)


def scales(p: PhysicalParams, string: StringSpec | None = None) -> Scales:
    """t* and L* of RGD07 eq. (19), with the force and torque units of eq. (20)."""
    s = structure(p, string)
    t_star = math.sqrt(s.inertia_kg_m2 / s.stiffness_nm_per_rad)
    l_star = 2.0 * s.stiffness_nm_per_rad / (p.intrinsic_specific_energy_pa * p.bit_radius_m**2)
    force = p.zeta * p.intrinsic_specific_energy_pa * p.bit_radius_m * l_star
    return Scales(t_star, l_star, force, s.stiffness_nm_per_rad)


def scale(p: PhysicalParams, string: StringSpec | None = None
          ) -> tuple[DimensionlessParams, Scales]:
    """Physical description -> the six groups of RGD07 eqs. (23)-(24), plus the scales
    (of the lumped equivalent of ``string`` when it has sections)."""
    s = structure(p, string)
    sc = scales(p, string)
    eps, zeta, a = p.intrinsic_specific_energy_pa, p.zeta, p.bit_radius_m
    groups = DimensionlessParams(
        n=p.n_blades,
        beta=p.mu_gamma * zeta,
        lam=p.contact_stress_times_wearflat_n_per_m / (zeta * eps * sc.length_m),
        psi=zeta * eps * a * s.inertia_kg_m2 / (s.mass_kg * s.stiffness_nm_per_rad),
        w0=p.applied_wob_n / sc.force_n,
        omega0=p.surface_rpm / RPM_PER_RAD_S * sc.time_s,
    )
    return groups, sc


def unscale(groups: DimensionlessParams, base: PhysicalParams) -> PhysicalParams:
    """Inverse of :func:`scale` for the bit/rock/operating quantities.

    The drill string, bit radius, eps and zeta are taken from ``base``; mu*gamma, sigma*l,
    the applied WOB and the surface rpm are solved from beta, lam, w0 and omega0. psi and n
    must agree with ``base`` (psi is fixed by the structure), else ParameterError.
    """
    _, sc = scale(base)
    psi_base = scale(base)[0].psi
    if not math.isclose(groups.psi, psi_base, rel_tol=1e-9):
        raise ParameterError(f"parameter 'psi' = {groups.psi!r} differs from the drill "
                             f"string's psi = {psi_base!r}; change the structure instead")
    eps, zeta = base.intrinsic_specific_energy_pa, base.zeta
    return base.with_(
        n_blades=groups.n,
        mu_gamma=groups.beta / zeta,
        contact_stress_times_wearflat_n_per_m=groups.lam * zeta * eps * sc.length_m,
        applied_wob_n=groups.w0 * sc.force_n,
        surface_rpm=groups.omega0 / sc.time_s * RPM_PER_RAD_S,
    )


def physical_from_dict(values: dict[str, Any]) -> PhysicalParams:
    """Build :class:`PhysicalParams` from a mapping; unknown keys are an error naming them."""
    known = {f.name for f in fields(PhysicalParams)}
    unknown = sorted(set(values) - known)
    if unknown:
        raise ParameterError(f"unknown physical parameter(s) {unknown}; known: {sorted(known)}")
    cast = {k: (int(v) if k == "n_blades" else float(v)) for k, v in values.items()}
    return PhysicalParams(**cast)


def dimensionless_from_dict(values: dict[str, Any]) -> DimensionlessParams:
    """Build :class:`DimensionlessParams` from a mapping; unknown keys name themselves."""
    known = {f.name for f in fields(DimensionlessParams)}
    unknown = sorted(set(values) - known)
    if unknown:
        raise ParameterError(f"unknown dimensionless parameter(s) {unknown}; known: "
                             f"{sorted(known)}")
    cast = {k: (int(v) if k == "n" else float(v)) for k, v in values.items()}
    return DimensionlessParams(**cast)
