"""The well around the string: its path, the mud, and the string's friction on the wall.

A soft-string model (Johancsik, Friesen & Dawson, SPE 11380, 1984, without the bends' term;
the side-friction model of Aarsnes & Shor, J. Pet. Sci. Eng. 163, 2018): the string lies on
the low side of the hole, pressed on it by its buoyed weight per metre,

    N(s) = w_b sin(inc(s)),    w_b = (rho_steel - rho_mud) A g,

with ``inc`` linear in measured depth s between the survey's points. The tension x curvature
term of a bend needs an azimuth (a dog-leg); the survey here has inclination only, so it is
left out, and a build section presses only by its weight. The wall holds a Coulomb friction
on the string's surface: a torque r_o mu N and an axial force mu N per metre, static up to
``mu_s`` while the element is within the stick band |speed| <= omega_s (a slip speed of
r_o omega_s on the surface), sliding at ``mu_d`` outside it. The kernel lumps it at the
wave guide's junctions the way it lumps the dampers (:func:`drill_sim_ros.model.string
.wave_line`), and splits the sliding force between rotation and axial motion along the
surface slip velocity (the torque-and-drag rule: a string that rotates drags little axially).

No well (``None``) is a vertical hole without wall contact: the model as before it.
SI throughout; ROS-free.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, field
from typing import Any

from drill_sim_ros.model.checks import check_known_keys, number_in
from drill_sim_ros.model.errors import ParameterError

GRAVITY_M_S2 = 9.80665
WELL_KEYS = ("survey", "mud_density_kg_m3", "side_friction")
SURVEY_KEYS = ("md_m", "inclination_deg")
FRICTION_KEYS = ("static", "dynamic", "stick_speed_rad_s")


@dataclass(frozen=True)
class SideFriction:
    """The wall's Coulomb friction: static and dynamic coefficients, the stick band in rad/s
    of string rotation (r_o omega_s of surface slip, rotating or moving axially)."""

    static: float = 0.0
    dynamic: float = 0.0
    stick_speed_rad_s: float = 0.05


@dataclass(frozen=True)
class Well:
    """A well path (measured depth m, inclination deg; linear between points, constant past
    the last), the mud density (kg/m^3; 0: in air) and the side friction."""

    survey: tuple[tuple[float, float], ...] = ((0.0, 0.0),)
    mud_density_kg_m3: float = 0.0
    side_friction: SideFriction = field(default_factory=SideFriction)

    def inclination_rad(self, md_m: float) -> float:
        """The inclination at measured depth ``md_m``, linear between survey points."""
        pts = self.survey
        if md_m <= pts[0][0]:
            return math.radians(pts[0][1])
        for (md0, inc0), (md1, inc1) in itertools.pairwise(pts):
            if md_m <= md1:
                return math.radians(inc0 + (inc1 - inc0) * (md_m - md0) / (md1 - md0))
        return math.radians(pts[-1][1])

    def normal_force_n(self, top_m: float, bottom_m: float, area_m2: float,
                       density_kg_m3: float, pieces: int = 64) -> float:
        """The wall's normal force on the string between measured depths ``top_m`` and
        ``bottom_m``: the integral of (rho - rho_mud) A g sin(inc) ds (midpoint rule on
        ``pieces`` pieces, exact where the inclination is constant)."""
        return self._buoyed_integral(math.sin, top_m, bottom_m, area_m2, density_kg_m3,
                                     pieces)

    def axial_weight_n(self, top_m: float, bottom_m: float, area_m2: float,
                       density_kg_m3: float, pieces: int = 64) -> float:
        """The buoyed weight along the hole's axis between ``top_m`` and ``bottom_m``: the
        integral of (rho - rho_mud) A g cos(inc) ds, what the string hangs from the hook
        with it when nothing drags (the hook load at rest off bottom)."""
        return self._buoyed_integral(math.cos, top_m, bottom_m, area_m2, density_kg_m3,
                                     pieces)

    def _buoyed_integral(self, along: Any, top_m: float, bottom_m: float, area_m2: float,
                         density_kg_m3: float, pieces: int) -> float:
        w_b = (density_kg_m3 - self.mud_density_kg_m3) * area_m2 * GRAVITY_M_S2
        ds = (bottom_m - top_m) / pieces
        return w_b * ds * sum(along(self.inclination_rad(top_m + (i + 0.5) * ds))
                              for i in range(pieces))

    @property
    def has_friction(self) -> bool:
        return self.side_friction.static > 0.0 or self.side_friction.dynamic > 0.0


def _number(where: str, value: Any, low: float, high: float) -> float:
    return number_in(f"'{where}'", value, low, high)


def _survey(raw: Any) -> tuple[tuple[float, float], ...]:
    """The survey list, checked: md increasing from 0, inclination in [0, 180] deg."""
    if not isinstance(raw, list) or not raw:
        raise ParameterError("'well.survey' must be a list of {md_m, inclination_deg}, "
                             "starting at md_m 0")
    points = []
    for i, point in enumerate(raw):
        where = f"well.survey[{i}]"
        if not isinstance(point, dict):
            raise ParameterError(f"'{where}' must be a mapping of md_m, inclination_deg")
        check_known_keys(point, SURVEY_KEYS, where)
        missing = [key for key in SURVEY_KEYS if key not in point]
        if missing:
            raise ParameterError(f"'{where}' needs {', '.join(missing)}")
        points.append((_number(f"{where}.md_m", point["md_m"], 0.0, 1e5),
                       _number(f"{where}.inclination_deg", point["inclination_deg"], 0.0,
                               180.0)))
    if points[0][0] != 0.0:
        raise ParameterError(f"'well.survey[0].md_m' = {points[0][0]:g} must be 0 (the "
                             "survey starts at the surface)")
    for i in range(1, len(points)):
        if points[i][0] <= points[i - 1][0]:
            raise ParameterError(f"'well.survey[{i}].md_m' = {points[i][0]:g} must be "
                                 f"greater than the point before ({points[i - 1][0]:g})")
    return tuple(points)


def _friction(raw: Any) -> SideFriction:
    """The ``side_friction`` mapping, checked: 0 <= dynamic <= static <= 2, stick band
    (0, 10] rad/s."""
    if not isinstance(raw, dict):
        raise ParameterError("'well.side_friction' must be a mapping of "
                             f"{', '.join(FRICTION_KEYS)}")
    check_known_keys(raw, FRICTION_KEYS, "well.side_friction")
    static = _number("well.side_friction.static", raw.get("static", 0.0), 0.0, 2.0)
    dynamic = _number("well.side_friction.dynamic", raw.get("dynamic", static), 0.0, 2.0)
    if dynamic > static:
        raise ParameterError(f"'well.side_friction.dynamic' = {dynamic:g} must not exceed "
                             f"static = {static:g}")
    band = _number("well.side_friction.stick_speed_rad_s",
                   raw.get("stick_speed_rad_s", SideFriction.stick_speed_rad_s), 1e-6, 10.0)
    return SideFriction(static, dynamic, band)


def well_from_dict(raw: Any) -> Well:
    """A preset's ``well`` mapping (module doc), each error one line naming the key."""
    if not isinstance(raw, dict):
        raise ParameterError(f"'well' must be a mapping of {', '.join(WELL_KEYS)}")
    check_known_keys(raw, WELL_KEYS, "well")
    if "survey" not in raw:
        raise ParameterError("'well' needs a survey: [{md_m: 0, inclination_deg: 0}, ...]")
    return Well(_survey(raw["survey"]),
                _number("well.mud_density_kg_m3", raw.get("mud_density_kg_m3", 0.0), 0.0,
                        5000.0),
                _friction(raw.get("side_friction", {})))


def well_to_dict(well: Well) -> dict[str, Any]:
    """The preset mapping of ``well`` (what :func:`well_from_dict` reads)."""
    f = well.side_friction
    return {"survey": [{"md_m": md, "inclination_deg": inc} for md, inc in well.survey],
            "mud_density_kg_m3": well.mud_density_kg_m3,
            "side_friction": {"static": f.static, "dynamic": f.dynamic,
                              "stick_speed_rad_s": f.stick_speed_rad_s}}
