"""Static soft-string torque and drag (Johancsik, Friesen & Dawson, SPE 11380, 1984), and
the normal force on each element of the string that the dynamic model's wall friction
reads.

The string lies along the hole's path (a soft string: no bending stiffness) and presses
on the wall with, per metre, the vector sum of its buoyed weight's part across the hole
and the tension x curvature of a bend. The balance of an element of length ds across the
hole, t the unit tangent pointing deeper, e_z straight down, T the effective tension
(buoyancy in it), w = (rho_steel - rho_mud) A g:

    n(s) = | T dt/ds + w (e_z - (e_z . t) t) |                                      (1)
         = sqrt( (T sin(inc) dazi/ds)^2 + (T dinc/ds - w sin(inc))^2 ),

with s measured down the hole. Written with s measured UP the hole, from the bit, as
Johancsik et al. step their elements, dinc/ds changes sign and (1) reads as their
F_n = [(F_t dazi sin inc)^2 + (F_t dinc + W sin inc)^2]^(1/2) (per element: W = w ds);
the Oliasoft soft-string specification (docs.oliasoft.com, Torque & Drag, eq. 1) writes
the same "+" form and notes that the side force depends on the sign of the build. So
in a build (inclination growing with depth) tension pulls the string towards the high
side, against its weight; in a drop it adds to it. Note: welleng 0.30's
``torque_drag.force_normal`` adds T x (inc_deeper - inc_shallower) to W sin(inc), the
opposite sign in a build or drop with the string in tension (tests/model/
test_torque_drag.py measures the difference; in a pure turn and where T = 0 they agree).

Along the string, from the bit up (dT/ds taken upwards; F_bit = the WOB, compressive):

    T(bit) = -F_bit,   dT = w cos(inc) ds + {+mu n ds: pick-up, -mu n ds: slack-off,
                                             0: rotating},
    torque: M(bit) = the torque on bit,   dM = mu n r_o ds  (rotating),

mu the sliding (dynamic) friction, r_o the section's outer radius (tool joints are not
modelled). Hook load = T at the top. The rotating case's tension needs no n, so its n is
a closed form of the path; pick-up and slack-off are integrated on cells of at most
``MAX_CELL_M``, midpoint (Heun) in each.

The dynamic model's wall friction takes each element's n from the ROTATING static
tension with the bit off bottom (F_bit = 0) or on it (F_bit = the WOB): a tension
computed once when the string is built, not the live axial force
(:func:`element_normal_force_n`).

SI throughout; ROS-free.
"""

from __future__ import annotations

import functools
import itertools
from dataclasses import dataclass
from typing import Any, Protocol

import numpy as np

from drill_sim_ros.model.survey import Survey

GRAVITY_M_S2 = 9.80665
MAX_CELL_M = 0.5
E_DOWN = np.array([0.0, 0.0, 1.0])


class StringSection(Protocol):
    """What the soft string reads of a section (model.string.Section has it)."""

    @property
    def length_m(self) -> float: ...
    @property
    def outer_radius_m(self) -> float: ...
    @property
    def area_m2(self) -> float: ...
    @property
    def density_kg_m3(self) -> float: ...


@dataclass(frozen=True)
class Cells:
    """The string cut into cells (top to bit), arrays over the cells: edges (n + 1) in
    measured depth, m; per cell its length, buoyed weight per metre (N/m), outer radius
    (m), and at its middle cos(inc), the curvature vector dt/ds (n, 3; 1/m) and the
    weight's part across the hole w (e_z - (e_z.t) t) (n, 3; N/m)."""

    edges_m: np.ndarray
    length_m: np.ndarray
    weight_n_m: np.ndarray
    radius_m: np.ndarray
    cos_inc: np.ndarray
    curvature_per_m: np.ndarray
    cross_weight_n_m: np.ndarray


def string_cells(survey: Survey, sections: tuple[StringSection, ...],
                 mud_density_kg_m3: float, max_cell_m: float = MAX_CELL_M) -> Cells:
    """:class:`Cells` of ``sections`` hung from md 0 in ``survey``'s path: edges at every
    section end and survey station, and no cell longer than ``max_cell_m``."""
    tops = np.cumsum([0.0, *(s.length_m for s in sections)])
    knots = np.union1d(tops, survey.md_m[survey.md_m < tops[-1]])
    pieces = [np.linspace(a, b, max(1, int(np.ceil((b - a) / max_cell_m))) + 1)[:-1]
              for a, b in itertools.pairwise(knots)]
    edges = np.concatenate([*pieces, knots[-1:]])
    mid = 0.5 * (edges[:-1] + edges[1:])
    which = np.clip(np.searchsorted(tops, mid, side="right") - 1, 0, len(sections) - 1)
    weight = np.array([(s.density_kg_m3 - mud_density_kg_m3) * s.area_m2 * GRAVITY_M_S2
                       for s in sections])[which]
    radius = np.array([s.outer_radius_m for s in sections])[which]
    t = survey.tangent(mid)
    cross = weight[:, None] * (E_DOWN[None, :] - t[:, 2:3] * t)
    return Cells(edges, np.diff(edges), weight, radius, t[:, 2],
                 survey.curvature_vector(mid), cross)


def normal_per_m(cells: Cells, tension_n: np.ndarray) -> np.ndarray:
    """Eq. (1) at each cell's middle for the tension there, N/m."""
    return np.linalg.norm(tension_n[:, None] * cells.curvature_per_m
                          + cells.cross_weight_n_m, axis=1)


def rotating_tension_n(cells: Cells, bit_force_n: float = 0.0) -> np.ndarray:
    """The rotating string's tension at the cells' edges (top to bit), N: the bit's
    -F_bit plus the buoyed weight along the axis of everything below (no axial drag)."""
    below = np.cumsum((cells.weight_n_m * cells.cos_inc * cells.length_m)[::-1])[::-1]
    return np.append(below, 0.0) - bit_force_n


@dataclass(frozen=True)
class TorqueDrag:
    """The static soft-string loads along the string, arrays at the cells' edges (top to
    bit, ``depth_m``): tension for pick-up, slack-off and rotating (N; the top value is
    the hook load less the block's weight), the rotating torque (N m, the top value the
    surface torque), and the rotating normal force per metre at the cells (N/m)."""

    depth_m: np.ndarray
    pickup_n: np.ndarray
    slackoff_n: np.ndarray
    rotating_n: np.ndarray
    torque_nm: np.ndarray
    normal_n_m: np.ndarray

    @property
    def surface_torque_nm(self) -> float:
        return float(self.torque_nm[0])


def torque_drag(cells: Cells, mu: float, bit_force_n: float = 0.0,
                bit_torque_nm: float = 0.0) -> TorqueDrag:
    """Pick-up, slack-off and rotating loads of ``cells`` with sliding friction ``mu``,
    ``bit_force_n`` on the bit (compressive; 0 off bottom) and ``bit_torque_nm``."""
    rotating = rotating_tension_n(cells, bit_force_n)
    normal = normal_per_m(cells, 0.5 * (rotating[:-1] + rotating[1:]))
    torque = bit_torque_nm + np.append(
        np.cumsum((mu * normal * cells.radius_m * cells.length_m)[::-1])[::-1], 0.0)
    return TorqueDrag(cells.edges_m, _dragged(cells, mu, bit_force_n),
                      _dragged(cells, -mu, bit_force_n), rotating, torque, normal)


def _dragged(cells: Cells, signed_mu: float, bit_force_n: float) -> np.ndarray:
    """Tension at the edges moving up (``signed_mu`` > 0) or down (< 0), from the bit,
    each cell by Heun's rule on dT/ds = w cos(inc) + signed_mu n(T)."""
    out = np.empty(cells.edges_m.size)
    out[-1] = tension = -bit_force_n
    along = cells.weight_n_m * cells.cos_inc
    bend, cross = cells.curvature_per_m, cells.cross_weight_n_m
    for i in range(cells.length_m.size - 1, -1, -1):
        ds = cells.length_m[i]
        slope0 = along[i] + signed_mu * float(np.linalg.norm(tension * bend[i] + cross[i]))
        guess = tension + ds * slope0
        slope1 = along[i] + signed_mu * float(np.linalg.norm(guess * bend[i] + cross[i]))
        tension += 0.5 * ds * (slope0 + slope1)
        out[i] = tension
    return out


@functools.lru_cache(maxsize=32)
def _cells(survey: Survey, sections: tuple[StringSection, ...],
           mud_density_kg_m3: float) -> Cells:
    """:func:`string_cells` once per string and well (the builder and the hook ask)."""
    return string_cells(survey, sections, mud_density_kg_m3)


def hanging_weight_n(survey: Survey, sections: tuple[StringSection, ...],
                     mud_density_kg_m3: float) -> float:
    """The string's buoyed weight along the hole's axis, N: the rotating tension at the
    top off bottom, what the hook carries when nothing drags."""
    return float(rotating_tension_n(_cells(survey, tuple(sections), mud_density_kg_m3))[0])


@functools.lru_cache(maxsize=32)
def _cumulative_normal(survey: Survey, sections: tuple[StringSection, ...],
                       mud_density_kg_m3: float,
                       bit_force_n: float) -> tuple[np.ndarray, np.ndarray]:
    """Edges and the rotating normal force integrated from the top to each edge, N."""
    cells = _cells(survey, sections, mud_density_kg_m3)
    tension = rotating_tension_n(cells, bit_force_n)
    normal = normal_per_m(cells, 0.5 * (tension[:-1] + tension[1:]))
    return cells.edges_m, np.append(0.0, np.cumsum(normal * cells.length_m))


def element_normal_force_n(survey: Survey, sections: tuple[StringSection, ...],
                           mud_density_kg_m3: float, top_m: Any, bottom_m: Any,
                           bit_force_n: float = 0.0) -> Any:
    """The wall's normal force on the string between measured depths ``top_m`` and
    ``bottom_m`` (floats, or arrays of elements: then an array), N: eq. (1) with the
    rotating static tension (the bit carrying ``bit_force_n``, compressive; 0 off
    bottom), integrated over cells of at most ``MAX_CELL_M`` (the profile is computed once
    per string and well, then read by interpolating its running integral)."""
    edges, running = _cumulative_normal(survey, tuple(sections), mud_density_kg_m3,
                                        float(bit_force_n))
    force = np.interp(bottom_m, edges, running) - np.interp(top_m, edges, running)
    return float(force) if np.ndim(force) == 0 else force
