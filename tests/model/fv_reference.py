"""An independent finite-volume solver of the off-bottom start-up with side friction per cell.

Written for issue 50 from the equations, importing nothing from ``drill_sim_ros`` (it reads a
preset's YAML with PyYAML only, to take the same inputs). numpy only, vectorised over cells.

**The equations** (SI; x measured depth, down; per section steel G, E, rho, polar moment J,
area A, outer radius r_o; T the torque and F the axial force the string above a cut applies
to the string below, w the angular and v the axial speed, down positive):

    torsion   rho J dw/dt = -dT/dx - gamma_t rho J w - q_t,    dT/dt = -G J dw/dx
    axial     rho A dv/dt = -dF/dx - gamma_a rho A v - q_a,    dF/dt = -E A dv/dx

about the string's static hanging state (the buoyed weight's axial component is carried by
the static tension, so the wall holds nothing at rest). ``gamma`` is the viscous loss per
unit inertia (1/s), ``q`` the wall's Coulomb friction per metre: the string lies on the low
side, pressed by N(x) = (rho - rho_mud) A g sin(inc(x)) (:func:`normal_force_n_per_m`, the
one place a bend's tension x curvature term would be added), inclination linear in measured
depth between survey points and constant past the last. The contact is one for both
motions: its surface slip is (r_o w, v); it is *stuck* while |slip| <= r_o w_band and then
holds up to mu_s N (a torque r_o mu_s N), and *slides* outside the band with mu_d N along the
slip velocity (so a string that rotates drags little axially).

**The numerics.** Godunov's first-order finite-volume scheme for linear acoustics in a
heterogeneous medium (LeVeque, *Finite Volume Methods for Hyperbolic Problems*, 2002,
sec. 9.9): at every cell face the down-going invariant a = T + Z w of the cell above and the
up-going b = T - Z w of the cell below meet, w* = (a_L - b_R) / (Z_L + Z_R),
T* = a_L - Z_L w*; the cells update from the face values. Within a uniform section this is
exactly the first-order upwind scheme on the Riemann invariants of Aarsnes & Shor (J. Pet.
Sci. Eng. 163, 2018; their code, Open-Source-Drilling-Community/Aarsnes-and-Shor-Torsional-
Model, ``torsionalWaveStep.m``: ``Palpha - dt/dx c diff(Palpha_pad) - dt S`` and the same for
beta, the pipe-collar interface by the impedance ratio ``Zbar``). Below a Courant number
of 1 (default 0.9) it shares no numerical method with the package, but it diffuses a front
by c dx (1 - C) / 2: enough, on the deviated preset, to shorten the reach of the slip
pulses that free the bit, so that its break-away converges only slowly (18.4, 21.4, 19.6 s
at 1000, 2000, 4000 cells). At a Courant number of 1, on cells that take one step to cross
in every section (``cells`` a multiple of the sections' lengths' common divisor: 27 on the
deviated preset, 250 on the tangent), the upwind step is exact for the waves (a shift by
one cell, the method of characteristics, as the package steps its waves, written here
apart) and only the wall's friction is approximated, at first order in the cell
(docs/string.md, "Which slip pulse frees the bit").

The wall's friction sits at the faces, inside their Riemann problem (:func:`wall_faces`): each
face carries the wall between the centres of its two cells and moves only when the
invariants' push exceeds it (implicit Coulomb, never through zero); a stuck face has
w* = 0 and passes a torque jump up to its capacity. That is the balance law's steady state
kept exactly (the source at the interfaces: Bale, LeVeque, Mitran & Rossmanith, SIAM J. Sci.
Comput. 24, 2002): a stuck stretch of string keeps its torques. Aarsnes & Shor instead add
the friction to each cell's speed after the upwind step (their ``Pci`` / ``S_P``, in alpha and
beta alike), so the strain of a held cell still moves with its faces: the torques diffuse
through a stuck stretch at C c dx / 2 (1900 m^2/s at 2000 cells), and the bit creeps before
it breaks away. Written that way first, this solver broke away at 20.8 s on the deviated
case at 1000-2500 cells and at 17.9 s at 3000-4000 (Courant 0.9), against 17.85-17.94 s at
every resolution and Courant number (0.6, 0.9) with the friction at the faces (measured
2026-12-06). Inside the band their cell keeps the speed it had (the torque that keeps
``op`` unchanged, clamped to the static threshold); here, as in the package's documented law
(docs/string.md: "stuck ... the junction's speed is 0"), a held face is at rest. The band is
judged on each face's last speed.

**A length for the drop** (optional, ``Case.slip_weakening_m`` = L; default 0, the law
above exactly). The drop from mu_s to mu_d above has no length scale, and on the deviated
preset the break-away moves with the cell at every cell tried (docs/string.md, "Which slip
pulse frees the bit"). With L > 0 a face that leaves the band weakens linearly with its
surface slip s since it was last within the band, mu(s) = mu_s - (mu_s - mu_d) min(s, L) / L
(the linear slip-weakening law of fault mechanics: Ida 1972, Andrews 1976); inside the band
it still holds up to mu_s. The slip is the contact's total, sqrt((r_o w)^2 + v^2), per face
and line (:func:`sliding_capacity`, :func:`accumulate_slip`).

**The ends.** Top, torsion: the drive's speed w_s over the step, T* = b_1 + Z_1 w_s; the
drive as the package documents it in speed mode (docs/model.md, model/top_drive.py's module
doc): the setpoint ramps linearly to its target, a PI loop with conditional integration and
a torque limit, the motor torque lagged (first order) and rate limited, J dw_s/dt = motor -
T*. Top, axial: the hook held still. Bottom, torsion: the free bit's inertia I_b,
I_b dw_b/dt = a_N - Z_N w_b (implicit), never turning backwards (w_b >= 0, as the package's
off-bottom bit). Bottom, axial: a free end (F* = 0).

**The figures** (:func:`startup_figures`), written from docs/string.md's "Start-up off
bottom": the bit speed in rpm is judged low-passed at twice the third torsional mode of the
fixed-top string (:func:`torsional_modes_hz`) with a zero-phase 4th-order Butterworth
magnitude (:func:`lowpass`); break-away is the first sample above 1 rpm, first slip above
30 rpm; over the second half a stick is a run below 1 rpm, and the period is the mean time
between the slips (above 30 rpm) that follow sticks of at least 0.5 s.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import yaml

GRAVITY_M_S2 = 9.80665
RPM_PER_RAD_S = 60.0 / (2.0 * math.pi)
TURNING_RPM, SLIP_RPM, MIN_STICK_S = 1.0, 30.0, 0.5
SAMPLE_S = 0.01                      # 100 Hz, as ``drill_sim startup`` samples


# ---- the inputs ---------------------------------------------------------------------------
@dataclass(frozen=True)
class Section:
    """A hollow steel section: radii and length m, density kg/m^3, moduli Pa, losses 1/s."""

    outer_radius_m: float
    inner_radius_m: float
    length_m: float
    density_kg_m3: float
    shear_modulus_pa: float
    youngs_modulus_pa: float
    torsional_damping_per_s: float
    axial_damping_per_s: float

    @property
    def polar_moment_m4(self) -> float:
        return 0.5 * math.pi * (self.outer_radius_m**4 - self.inner_radius_m**4)

    @property
    def area_m2(self) -> float:
        return math.pi * (self.outer_radius_m**2 - self.inner_radius_m**2)


@dataclass(frozen=True)
class Case:
    """Everything the start-up needs, SI: sections top to bottom, the bit's inertia, the
    survey (md m, inclination deg), mud density, side friction (mu_s, mu_d, band rad/s) and
    the drive (J kg m^2, kp N m s, ki N m, torque limit N m, motor lag s, rate limit N m/s;
    inf: none); ``bend_term``: the normal force carries tension x build rate
    (:func:`normal_force_n_per_m`); ``slip_weakening_m``: the wall's slip-weakening distance
    L (0: the drop from mu_s to mu_d at once on leaving the band, the package's law;
    :func:`sliding_capacity`)."""

    sections: tuple[Section, ...]
    bit_inertia_kg_m2: float
    survey_md_m: tuple[float, ...]
    survey_inc_deg: tuple[float, ...]
    mud_density_kg_m3: float
    mu_static: float
    mu_dynamic: float
    stick_band_rad_s: float
    drive_inertia_kg_m2: float
    kp_nm_s: float
    ki_nm: float
    max_torque_nm: float
    motor_lag_s: float = 0.0
    max_torque_rate_nm_s: float = math.inf
    bend_term: bool = False
    slip_weakening_m: float = 0.0


def case_from_preset(source: str | Path | dict[str, Any], bend_term: bool = False) -> Case:
    """The :class:`Case` of a physical preset with a distributed string and a well (a YAML
    path or its mapping); the preset's own keys, read with their documented defaults. A
    survey in one vertical plane only (azimuth, where given, the same at every station)."""
    raw = yaml.safe_load(Path(source).read_text()) if not isinstance(source, dict) else source
    phys, string, well, drive = raw["physical"], raw["string"], raw["well"], raw["top_drive"]
    rho = float(phys.get("density_kg_m3", 7850.0))
    g, e = float(phys.get("shear_modulus_pa", 79.3e9)), float(phys.get("youngs_modulus_pa",
                                                                       206e9))
    gt, ga = (float(string.get(key, 0.0)) for key in ("torsional_damping_per_s",
                                                     "axial_damping_per_s"))
    sections = tuple(Section(float(s["outer_radius_m"]), float(s["inner_radius_m"]),
                             float(s["length_m"]), float(s.get("density_kg_m3", rho)),
                             float(s.get("shear_modulus_pa", g)),
                             float(s.get("youngs_modulus_pa", e)),
                             float(s.get("torsional_damping_per_s", gt)),
                             float(s.get("axial_damping_per_s", ga)))
                     for s in string["sections"])
    if len({float(p.get("azimuth_deg", 0.0)) for p in well["survey"]}) > 1:
        raise NotImplementedError("a survey that turns (azimuth changes): 2-D wells only")
    friction = well.get("side_friction", {})
    mu_s = float(friction.get("static", 0.0))

    def limit(key: str) -> float:
        value = float(drive.get(key, 0.0))
        return math.inf if value == 0.0 else value
    return Case(sections, float(string.get("bit_inertia_kg_m2", 0.0)),
                tuple(float(p["md_m"]) for p in well["survey"]),
                tuple(float(p["inclination_deg"]) for p in well["survey"]),
                float(well.get("mud_density_kg_m3", 0.0)), mu_s,
                float(friction.get("dynamic", mu_s)),
                float(friction.get("stick_speed_rad_s", 0.05)),
                float(drive["inertia_kg_m2"]), float(drive["kp_nm_s"]), float(drive["ki_nm"]),
                limit("max_torque_nm"), float(drive.get("motor_lag_s", 0.0)),
                limit("max_torque_rate_nm_s"), bend_term)


# ---- the well -----------------------------------------------------------------------------
def inclination_rad(case: Case, md_m: np.ndarray) -> np.ndarray:
    """Inclination at measured depths ``md_m`` (any shape): linear between survey points,
    constant past the last."""
    return np.radians(np.interp(md_m, case.survey_md_m, case.survey_inc_deg))


def build_rate_rad_m(case: Case, md_m: np.ndarray) -> np.ndarray:
    """d inc / d md at ``md_m``: the slope of the survey leg holding it (0 past the ends)."""
    md, inc = np.asarray(case.survey_md_m), np.radians(case.survey_inc_deg)
    slopes = np.concatenate(([0.0], np.diff(inc) / np.diff(md), [0.0]))
    return slopes[np.searchsorted(md, md_m, side="right")]


def buoyed_weight_n_per_m(case: Case, section: Section) -> float:
    """w_b = (rho - rho_mud) A g of ``section``."""
    return (section.density_kg_m3 - case.mud_density_kg_m3) * section.area_m2 * GRAVITY_M_S2


def hanging_tension_n(case: Case, md_m: np.ndarray, step_m: float = 0.25) -> np.ndarray:
    """The static tension of the string hanging off bottom, rotating (no axial drag, no
    force on the bit): the buoyed weight along the hole's axis of all that lies below
    ``md_m``, the integral of w_b cos(inc) from ``md_m`` to the bit (trapezoid on
    ``step_m``)."""
    edges = np.cumsum([0.0] + [s.length_m for s in case.sections])
    x = np.arange(0.0, edges[-1] + step_m, step_m).clip(max=edges[-1])
    w_b = np.array([buoyed_weight_n_per_m(case, s) for s in case.sections])
    per_m = w_b[np.clip(np.searchsorted(edges, x, side="right") - 1, 0, len(w_b) - 1)] \
        * np.cos(inclination_rad(case, x))
    from_top = np.concatenate(([0.0], np.cumsum(0.5 * (per_m[1:] + per_m[:-1]) * np.diff(x))))
    return np.interp(md_m, x, from_top[-1] - from_top)


def normal_force_n_per_m(case: Case, section: Section, md_m: np.ndarray) -> np.ndarray:
    """The wall's normal force per metre on ``section`` at ``md_m``: the buoyed weight's
    component across the hole, w_b sin(inc), and with ``case.bend_term`` the tension x
    curvature of a build or drop in the vertical plane, |T dinc/ds - w_b sin(inc)| (soft
    string, Johancsik, Friesen & Dawson, SPE 11380, 1984, eq. 1, with s down the hole: in a
    build the tension pulls the string to the high side, against its weight), T the static
    hanging tension (:func:`hanging_tension_n`), as docs/string.md says the package takes
    it since the survey work (main 97de425)."""
    weight = buoyed_weight_n_per_m(case, section) * np.sin(inclination_rad(case, md_m))
    if not case.bend_term:
        return weight
    return np.abs(hanging_tension_n(case, md_m) * build_rate_rad_m(case, md_m) - weight)


def half_cell_normal_forces_n(case: Case, section: Section, top_m: float, cells: int,
                              points: int = 8) -> tuple[np.ndarray, np.ndarray]:
    """The normal force on the upper and the lower half of each of ``cells`` equal cells of
    ``section`` (its top at ``top_m``): the integrals of N over them, Gauss-Legendre on
    ``points`` points each, shape (cells,) twice."""
    x, w = np.polynomial.legendre.leggauss(points)
    half = 0.5 * section.length_m / cells
    tops = top_m + 2.0 * half * np.arange(cells)

    def over(start: np.ndarray) -> np.ndarray:
        md = start[:, None] + 0.5 * half * (x[None, :] + 1.0)
        return 0.5 * half * (normal_force_n_per_m(case, section, md) @ w)
    return over(tops), over(tops + half)


def static_breakaway_torque_nm(case: Case, cells_per_section: int = 2000) -> float:
    """The wall's static torque on the whole string, the integral of r_o mu_s N."""
    total, top = 0.0, 0.0
    for s in case.sections:
        upper, lower = half_cell_normal_forces_n(case, s, top, cells_per_section)
        total += s.outer_radius_m * case.mu_static * (upper.sum() + lower.sum())
        top += s.length_m
    return total


# ---- one line of cells --------------------------------------------------------------------
@dataclass
class Line:
    """One kind of wave on its cells (top to bottom): per cell the inertia m (rho J dx or
    rho A dx), impedance Z, dt x stiffness / dx (G J dt / dx), the implicit loss factor
    1 / (1 + gamma dt), the depth of its centre; per face below a cell (the last: the bit's)
    the wall's static and dynamic capacity (N m or N) of the wall between the two cell
    centres, the slip per unit speed (r_o or 1) and the stick band in surface slip
    (r_o w_band); the state: cell speeds w and torques (forces) T, and the faces' last
    speeds; with a slip-weakening distance ``weakening_m`` > 0, each face's surface slip m
    since it was last stuck (``slip_m``)."""

    m: np.ndarray
    z: np.ndarray
    k: np.ndarray
    loss: np.ndarray
    depth_m: np.ndarray
    cap_s: np.ndarray
    cap_d: np.ndarray
    arm: np.ndarray
    band: np.ndarray
    w: np.ndarray
    t: np.ndarray
    w_face: np.ndarray
    weakening_m: float = 0.0
    slip_m: np.ndarray | None = None

    @property
    def inv_zsum(self) -> np.ndarray:
        return 1.0 / (self.z[:-1] + self.z[1:])


def build_line(case: Case, counts: list[int], dt: float, axial: bool) -> Line:
    """The cells of one line, ``counts[i]`` equal cells in section i. The wall between the
    top and the first cell's centre goes to the first inner face (the surface is vertical in
    every survey that starts at 0 deg; a rounding either way)."""
    keys = ("m", "z", "k", "loss", "depth_m", "cap_up", "cap_low", "arm", "band")
    cols: dict[str, list[np.ndarray]] = {key: [] for key in keys}
    top = 0.0
    for s, n in zip(case.sections, counts, strict=True):
        dx = s.length_m / n
        prop = s.area_m2 if axial else s.polar_moment_m4
        modulus = s.youngs_modulus_pa if axial else s.shear_modulus_pa
        gamma = s.axial_damping_per_s if axial else s.torsional_damping_per_s
        arm = 1.0 if axial else s.outer_radius_m
        upper, lower = half_cell_normal_forces_n(case, s, top, n)

        def full(value: float, n: int = n) -> np.ndarray:
            return np.full(n, value)
        cols["m"].append(full(s.density_kg_m3 * prop * dx))
        cols["z"].append(full(prop * math.sqrt(modulus * s.density_kg_m3)))
        cols["k"].append(full(modulus * prop * dt / dx))
        cols["loss"].append(full(1.0 / (1.0 + gamma * dt)))
        cols["depth_m"].append(top + dx * (np.arange(n) + 0.5))
        cols["cap_up"].append(arm * upper)
        cols["cap_low"].append(arm * lower)
        cols["arm"].append(full(arm))
        cols["band"].append(full(case.stick_band_rad_s * s.outer_radius_m))
        top += s.length_m
    c = {key: np.concatenate(v) for key, v in cols.items()}
    wall = c["cap_low"] + np.append(c["cap_up"][1:], 0.0)    # the face below each cell
    wall[0] += c["cap_up"][0]
    size = c["m"].size
    return Line(c["m"], c["z"], c["k"], c["loss"], c["depth_m"], case.mu_static * wall,
                case.mu_dynamic * wall, c["arm"], c["band"], np.zeros(size), np.zeros(size),
                np.zeros(size), case.slip_weakening_m, np.zeros(size))


def sliding_capacity(line: Line) -> np.ndarray:
    """Each face's capacity while it slides (outside the band). Without a slip-weakening
    distance (L = 0) the dynamic one, mu_d N: the static-to-dynamic drop happens at once on
    leaving the band and has no length. With L > 0, linear slip weakening (Ida, J. Geophys.
    Res. 77, 1972; Andrews, J. Geophys. Res. 81, 1976): mu(s) = mu_s - (mu_s - mu_d)
    min(s, L) / L, s the surface slip (``slip_m``) since the face was last within the band.
    That gives the drop a length, and a sliding patch a nucleation size
    h* = pi sqrt(G J L / ((mu_s - mu_d) N r_o^2)) (docs/string.md, "A length for the
    drop")."""
    if line.weakening_m <= 0.0:
        return line.cap_d
    return line.cap_s - (line.cap_s - line.cap_d) * np.minimum(line.slip_m / line.weakening_m,
                                                               1.0)


def accumulate_slip(line: Line, faces: slice, slip_speed: np.ndarray, dt: float) -> None:
    """The ``faces``' slip over the step at total surface ``slip_speed`` (m/s): back to 0
    on a face within the band (stuck), else grown by ``slip_speed`` dt."""
    line.slip_m[faces] = np.where(slip_speed > line.band[faces],
                                  line.slip_m[faces] + slip_speed * dt, 0.0)


def wall_faces(line: Line, inv_zsum: np.ndarray, dt: float, other_slip: np.ndarray | None
               ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The inner faces' Riemann problem with the wall's friction F held at the face (shape
    (cells - 1,) each: speed w*, the torque just above the face T*_up, just below it
    T*_down). The down-going a = T + Z w of the cell above and the up-going b = T - Z w of
    the cell below meet; the face moves when their difference exceeds the friction:
    (a - Z_up w*) - (b + Z_down w*) = F, |F| <= capacity, F opposing w*; held (w* = 0,
    F = a - b) otherwise. So a stuck stretch keeps its torques exactly (the wall holds the
    gradient: the balance law's steady state, LeVeque's f-wave idea of putting the source at
    the interfaces, Bale, LeVeque, Mitran & Rossmanith, SIAM J. Sci. Comput. 24, 2002).

    The capacity is static while the face's last slip sqrt((arm w*)^2 + other^2) is within
    the band, dynamic (or slip-weakening: :func:`sliding_capacity`) outside; it acts on
    this line in the share |own| / |slip| of the slip velocity (own: the face's speed
    without friction), all of it when ``other_slip`` is None (the other line at rest)."""
    a = line.t + line.z * line.w
    b = line.t - line.z * line.w
    push = a[:-1] - b[1:]
    last = line.w_face[:-1] * line.arm[:-1]
    if other_slip is None:
        cap = np.where(np.abs(last) > line.band[:-1], sliding_capacity(line)[:-1],
                       line.cap_s[:-1])
    else:
        sliding = last**2 + other_slip[:-1] ** 2 > line.band[:-1] ** 2
        own = np.abs(push * inv_zsum * line.arm[:-1])
        share = np.divide(own, np.hypot(own, other_slip[:-1]), out=np.ones_like(own),
                          where=own > 0.0)
        cap = np.where(sliding, sliding_capacity(line)[:-1], line.cap_s[:-1]) * share
    w_star = np.sign(push) * np.maximum(np.abs(push) - cap, 0.0) * inv_zsum
    line.w_face[:-1] = w_star
    if line.weakening_m > 0.0:
        slip = line.arm[:-1] * w_star
        accumulate_slip(line, slice(None, -1), np.abs(slip) if other_slip is None
                        else np.hypot(slip, other_slip[:-1]), dt)
    return w_star, a[:-1] - line.z[:-1] * w_star, b[1:] + line.z[1:] * w_star


def end_with_inertia(line: Line, inertia: float, w_end: float, dt: float,
                     clamp_forward: bool) -> tuple[float, float]:
    """The bottom face: a lumped ``inertia`` (0: a free end) moving at ``w_end``, driven by
    the a arriving from the last cell, with the last half-cell's wall (implicit Coulomb):
    I dw/dt = a - Z w - F. Returns (speed after the step, torque above the face); with
    ``clamp_forward`` never backwards (the package's off-bottom bit)."""
    a_end = line.t[-1] + line.z[-1] * line.w[-1]
    cap = sliding_capacity(line)[-1] if abs(line.w_face[-1]) > line.band[-1] / line.arm[-1] \
        else line.cap_s[-1]
    push = inertia * w_end + dt * a_end
    w = math.copysign(max(abs(push) - dt * cap, 0.0), push) / (inertia + dt * line.z[-1])
    if clamp_forward:
        w = max(w, 0.0)
    line.w_face[-1] = w
    if line.weakening_m > 0.0:
        accumulate_slip(line, slice(-1, None), np.abs(line.arm[-1:] * w), dt)
    return w, a_end - line.z[-1] * w


def advance_line(line: Line, w_top: float, t_top: float, faces: tuple[np.ndarray, ...],
                 w_bottom: float, t_bottom: float, dt: float) -> None:
    """The cells one step on from their faces: the top face (``w_top``, ``t_top``), the
    inner ``faces`` (:func:`wall_faces`) and the bottom one; the loss implicit."""
    w_star, t_up, t_down = faces
    t_above = np.concatenate(([t_top], t_down))          # torque on each cell from above
    t_below = np.append(t_up, t_bottom)                  # and what it gives below
    w_in = np.concatenate(([w_top], w_star))
    w_out = np.append(w_star, w_bottom)
    line.w = (line.w + dt * (t_above - t_below) / line.m) * line.loss
    line.t += line.k * (w_in - w_out)


# ---- the whole start-up -------------------------------------------------------------------
@dataclass(frozen=True)
class Series:
    """The samples at 100 Hz, each (samples,): time s, bit / drive / setpoint speed rpm,
    motor torque and string torque at the top N m, the drive's turns since the start, the
    string's twist (drive angle - bit angle) in turns."""

    t_s: np.ndarray
    bit_rpm: np.ndarray
    drive_rpm: np.ndarray
    setpoint_rpm: np.ndarray
    motor_torque_nm: np.ndarray
    surface_torque_nm: np.ndarray
    drive_turns: np.ndarray
    twist_turns: np.ndarray


def cell_counts(case: Case, cells: int) -> list[int]:
    """Cells per section, ``cells`` in all shared by length (at least one each)."""
    total = sum(s.length_m for s in case.sections)
    return [max(1, round(cells * s.length_m / total)) for s in case.sections]


def time_step_s(case: Case, counts: list[int], courant: float) -> float:
    """The torsional line's step at ``courant`` on its finest cell (at 1, every section
    whose cells take the same transit time is stepped exactly: one cell a step)."""
    fastest = min(s.length_m / n / math.sqrt(s.shear_modulus_pa / s.density_kg_m3)
                  for s, n in zip(case.sections, counts, strict=True))
    return courant * fastest


def axial_counts(case: Case, dt: float, courant: float) -> list[int]:
    """Axial cells per section at ``courant`` for the step ``dt`` (the faster axial wave
    takes longer cells, so both lines share the step)."""
    return [max(1, math.floor(courant * s.length_m
                              / (math.sqrt(s.youngs_modulus_pa / s.density_kg_m3) * dt)))
            for s in case.sections]


@dataclass
class Drive:
    """The top drive's state: speed rad/s, angle rad, setpoint rad/s, PI integral N m,
    motor torque N m."""

    w: float = 0.0
    angle: float = 0.0
    setpoint: float = 0.0
    integral: float = 0.0
    motor: float = 0.0


def drive_step(case: Case, d: Drive, target: float, rate: float, t_string: float,
               dt: float) -> None:
    """The drive one step on in speed mode (docs/model.md): the setpoint ramps toward
    ``target`` at ``rate``; the PI loop integrates unless its unlimited output saturates in
    the error's direction; the motor follows the command through a first-order lag and the
    rate limit, within the torque limit; J dw/dt = motor - ``t_string``."""
    lim = case.max_torque_nm
    d.setpoint = min(target, d.setpoint + rate * dt)
    err = d.setpoint - d.w
    integral = min(max(d.integral + case.ki_nm * err * dt, -lim), lim)
    unlimited = case.kp_nm_s * err + integral
    if not ((unlimited > lim and err > 0.0) or (unlimited < -lim and err < 0.0)):
        d.integral = integral
    command = min(max(unlimited, -lim), lim)
    share = 1.0 - math.exp(-dt / case.motor_lag_s) if case.motor_lag_s > 0.0 else 1.0
    lagged = d.motor + share * (command - d.motor)
    step = case.max_torque_rate_nm_s * dt
    motor = min(max(lagged, d.motor - step), d.motor + step)
    d.motor = min(max(motor, -lim), lim)
    d.angle += d.w * dt
    d.w += (d.motor - t_string) / case.drive_inertia_kg_m2 * dt


def run_startup(case: Case, rpm: float, ramp_s: float, seconds: float, cells: int,
                courant: float = 0.9,
                on_sample: Callable[[float, Line], None] | None = None) -> Series:
    """The start-up from rest, untwisted, off bottom: the drive's setpoint ramps from 0 to
    ``rpm`` in ``ramp_s`` (0: a step); ``cells`` torsional cells along the string (the axial
    line gets as many as its faster wave allows at the same step); sampled at 100 Hz from
    t = 0 to ``seconds``, each sample the state at the step nearest its time (the step is
    set by the cells, not by the samples); ``on_sample(t, torsional line)`` at each sample
    (to look inside)."""
    counts = cell_counts(case, cells)
    dt = time_step_s(case, counts, courant)
    tor = build_line(case, counts, dt, axial=False)
    axl = build_line(case, axial_counts(case, dt, courant), dt, axial=True)
    inv_t, inv_a = tor.inv_zsum, axl.inv_zsum
    target = rpm / RPM_PER_RAD_S
    rate = target / ramp_s if ramp_s > 0.0 else math.inf
    d, w_bit, bit_angle = Drive(), 0.0, 0.0
    samples = round(seconds / SAMPLE_S) + 1
    at_step = np.rint(np.arange(samples) * SAMPLE_S / dt).astype(int)   # the nearest steps
    out, k = np.zeros((8, samples)), 0
    for step in range(at_step[-1] + 1):
        t_top = tor.t[0] - tor.z[0] * tor.w[0] + tor.z[0] * d.w   # b_1 + Z_1 w_s
        while k < samples and at_step[k] == step:
            out[:, k] = (k * SAMPLE_S, w_bit, d.w, d.setpoint, d.motor, t_top, d.angle,
                         bit_angle)
            if on_sample is not None:
                on_sample(k * SAMPLE_S, tor)
            k += 1
        # The hook is held and the bit end free, so nothing forces the axial line: it stays
        # exactly at rest (every flux and friction term zero) until something moves it, and
        # is stepped, and felt by the torsional contact, only from then on.
        axial_moving = axl.w.any() or axl.t.any()
        v_at_t = np.interp(tor.depth_m, axl.depth_m, axl.w_face) if axial_moving else None
        inner = wall_faces(tor, inv_t, dt, v_at_t)
        w_bit, t_bottom = end_with_inertia(tor, case.bit_inertia_kg_m2, w_bit, dt, True)
        advance_line(tor, d.w, t_top, inner, w_bit, t_bottom, dt)
        if axial_moving:                                  # hook held, bit end free
            u_at_a = np.interp(axl.depth_m, tor.depth_m, tor.w_face * tor.arm)
            f_top = axl.t[0] - axl.z[0] * axl.w[0]
            inner_a = wall_faces(axl, inv_a, dt, u_at_a)
            v_end, f_end = end_with_inertia(axl, 0.0, 0.0, dt, False)
            advance_line(axl, 0.0, f_top, inner_a, v_end, f_end, dt)
        drive_step(case, d, target, rate, t_top, dt)
        bit_angle += w_bit * dt
    t, w_b, w_s, ref, motor, top, angle, bit = out
    return Series(t, w_b * RPM_PER_RAD_S, w_s * RPM_PER_RAD_S, ref * RPM_PER_RAD_S, motor,
                  top, angle / (2 * math.pi), (angle - bit) / (2 * math.pi))


# ---- the figures --------------------------------------------------------------------------
def torsional_modes_hz(case: Case, count: int = 3, f_max_hz: float = 50.0) -> list[float]:
    """The first ``count`` natural frequencies of the string clamped at the top and free at
    the bit with its inertia I_b. From the bit up, the (angle, torque) amplitude of a mode
    at ``omega`` starts at (1, -I_b omega^2) and crosses a section of wavenumber k = omega / c
    and S = G J as theta(x) = theta cos kx + T sin(kx) / (S k), T(x) = -theta S k sin kx +
    T cos kx; a natural frequency is a zero of the angle left at the clamped top (sign
    changes on a 0.005 Hz grid, then bisection)."""
    def top_angle(omega: float) -> float:
        angle, torque = 1.0, -case.bit_inertia_kg_m2 * omega**2   # the bit inertia
        for s in reversed(case.sections):
            c = math.sqrt(s.shear_modulus_pa / s.density_kg_m3)
            stiff = s.shear_modulus_pa * s.polar_moment_m4 * omega / c
            kl = omega / c * s.length_m
            angle, torque = (angle * math.cos(kl) + torque / stiff * math.sin(kl),
                             -angle * stiff * math.sin(kl) + torque * math.cos(kl))
        return angle
    grid = 2 * math.pi * np.arange(0.001, f_max_hz, 0.005)
    values = np.array([top_angle(w) for w in grid])
    found = []
    for i in np.flatnonzero(np.sign(values[:-1]) != np.sign(values[1:]))[:count]:
        lo, hi = grid[i], grid[i + 1]
        for _ in range(60):
            mid = 0.5 * (lo + hi)
            lo, hi = (lo, mid) if np.sign(top_angle(mid)) != np.sign(top_angle(lo)) else (mid,
                                                                                         hi)
        found.append(0.5 * (lo + hi) / (2 * math.pi))
    return found


def lowpass(x: np.ndarray, sample_s: float, cutoff_hz: float) -> np.ndarray:
    """Zero-phase low-pass: the gain of a 4th-order Butterworth run forward and backward,
    1 / (1 + (f / fc)^8), applied to the FFT of the record with its mean removed, padded by
    its mirror images at both ends."""
    mean = x.mean()
    pad = x.size - 1
    padded = np.pad(x - mean, pad, mode="reflect")
    f = np.fft.rfftfreq(padded.size, sample_s)
    y = np.fft.irfft(np.fft.rfft(padded) / (1.0 + (f / cutoff_hz) ** 8), n=padded.size)
    return y[pad:pad + x.size] + mean


def slip_times(t: np.ndarray, rpm: np.ndarray) -> list[float]:
    """After each stick (a run below ``TURNING_RPM``) of at least ``MIN_STICK_S`` that
    ends within the record, the first sample above ``SLIP_RPM`` before the next such
    stick."""
    stuck = np.abs(rpm) < TURNING_RPM
    edges = np.flatnonzero(np.diff(np.concatenate(([0], stuck.astype(int), [0]))))
    runs = [(s, e) for s, e in zip(edges[::2], edges[1::2], strict=True)
            if e < t.size and t[e] - t[s] >= MIN_STICK_S - 1e-9]
    times = []
    for i, (_, end) in enumerate(runs):
        stop = runs[i + 1][0] if i + 1 < len(runs) else t.size
        above = np.flatnonzero(rpm[end:stop] > SLIP_RPM)
        if above.size:
            times.append(float(t[end + above[0]]))
    return times


def startup_figures(run: Series, cutoff_hz: float) -> dict[str, Any]:
    """The start-up's figures (module doc), None where an event never happens."""
    t = run.t_s
    rpm = lowpass(run.bit_rpm, SAMPLE_S, cutoff_hz)

    def first(mask: np.ndarray, values: np.ndarray) -> float | None:
        return float(values[np.argmax(mask)]) if mask.any() else None
    turning, slipping = rpm > TURNING_RPM, rpm > SLIP_RPM
    half = t >= 0.5 * (t[0] + t[-1])
    slips = slip_times(t[half], rpm[half])
    return {"breakaway_s": first(turning, t),
            "breakaway_turns": first(turning, run.drive_turns),
            "breakaway_torque_nm": first(turning, run.surface_torque_nm),
            "first_slip_s": first(slipping, t),
            "peak_motor_torque_nm": float(np.abs(run.motor_torque_nm).max()),
            "stick_slip": bool(slips),
            "period_s": float(np.mean(np.diff(slips))) if len(slips) >= 2 else None,
            "stick_fraction": float(np.mean(np.abs(rpm[half]) < TURNING_RPM)),
            "cutoff_hz": cutoff_hz}
