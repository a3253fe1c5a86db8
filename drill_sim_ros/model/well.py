"""The well around the string: its path, the mud, and the string's friction on the wall.

A soft-string model (Johancsik, Friesen & Dawson, SPE 11380, 1984; the side-friction model
of Aarsnes & Shor, J. Pet. Sci. Eng. 163, 2018): the string lies along the hole's path
(:mod:`drill_sim_ros.model.survey`: stations of measured depth, inclination and azimuth,
minimum curvature between them), pressed on the wall by its buoyed weight's part across
the hole and, in a bend, by tension x curvature (:mod:`drill_sim_ros.model.torque_drag`,
eq. 1):

    n(s) = | T dt/ds + w_b (e_z - (e_z . t) t) |,    w_b = (rho_steel - rho_mud) A g,

the tension T the static one of the string rotating off bottom (or on the WOB). The wall
holds a Coulomb friction on the string's surface: a torque r_o mu n and an axial force
mu n per metre, static up to ``mu_s`` while the element is within the stick band
|speed| <= omega_s (a slip speed of r_o omega_s on the surface), sliding at ``mu_d``
outside it. The kernel lumps it at the wave guide's junctions the way it lumps the dampers
(:func:`drill_sim_ros.model.string.wave_line`), and splits the sliding force between
rotation and axial motion along the surface slip velocity (the torque-and-drag rule: a
string that rotates drags little axially).

No well (``None``) is a vertical hole without wall contact: the model as before it.
SI throughout; ROS-free.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from drill_sim_ros.model import torque_drag
from drill_sim_ros.model.checks import check_known_keys, number_in
from drill_sim_ros.model.errors import ParameterError
from drill_sim_ros.model.survey import COLUMNS, Survey, read_survey_csv, survey_from_rows

GRAVITY_M_S2 = torque_drag.GRAVITY_M_S2
WELL_KEYS = ("survey", "mud_density_kg_m3", "side_friction")
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
    """A well path (:class:`Survey`: minimum curvature between stations, straight past the
    last), the mud density (kg/m^3; 0: in air) and the side friction."""

    survey: Survey = field(default_factory=Survey)
    mud_density_kg_m3: float = 0.0
    side_friction: SideFriction = field(default_factory=SideFriction)

    def inclination_rad(self, md_m: float) -> float:
        """The inclination at measured depth ``md_m`` on the minimum-curvature path (in a
        2-D well: linear between stations)."""
        return float(self.survey.attitude_rad(md_m)[0][0])

    def string_normal_force_n(self, sections: tuple[Any, ...], top_m: Any, bottom_m: Any,
                              bit_force_n: float = 0.0) -> Any:
        """The wall's normal force between ``top_m`` and ``bottom_m`` (floats, or arrays of
        elements: an array) on the string of ``sections`` (hung from md 0), N: weight
        across the hole and tension x curvature,
        the tension the static one rotating with ``bit_force_n`` on the bit (0 off bottom;
        :func:`torque_drag.element_normal_force_n`). What the string's builder reads."""
        return torque_drag.element_normal_force_n(self.survey, tuple(sections),
                                                  self.mud_density_kg_m3, top_m, bottom_m,
                                                  bit_force_n)

    def normal_force_n(self, top_m: float, bottom_m: float, area_m2: float,
                       density_kg_m3: float, pieces: int = 64) -> float:
        """The buoyed weight's part across the hole between measured depths ``top_m`` and
        ``bottom_m``: the integral of (rho - rho_mud) A g sin(inc) ds (midpoint rule on
        ``pieces`` pieces), WITHOUT the bend term (:meth:`string_normal_force_n` has it)."""
        w_b = (density_kg_m3 - self.mud_density_kg_m3) * area_m2 * GRAVITY_M_S2
        ds = (bottom_m - top_m) / pieces
        inc = self.survey.attitude_rad(top_m + (np.arange(pieces) + 0.5) * ds)[0]
        return float(w_b * ds * np.sum(np.sin(inc)))

    def hanging_weight_n(self, sections: tuple[Any, ...]) -> float:
        """The buoyed weight of the string of ``sections`` along the hole's axis, N: what
        it hangs from the hook with when nothing drags (the hook load at rest off bottom;
        :func:`torque_drag.hanging_weight_n`, the static rotating hook load)."""
        return torque_drag.hanging_weight_n(self.survey, tuple(sections),
                                            self.mud_density_kg_m3)

    @property
    def has_friction(self) -> bool:
        return self.side_friction.static > 0.0 or self.side_friction.dynamic > 0.0


def _number(where: str, value: Any, low: float, high: float) -> float:
    return number_in(f"'{where}'", value, low, high)


def _survey(raw: Any, base_dir: Path | None) -> Survey:
    """The survey: a list of stations {md_m, inclination_deg, azimuth_deg (optional,
    0)}, or the name of a CSV file with those columns (relative to ``base_dir``, the
    preset's directory); md from 0 and increasing, inclination in [0, 180] deg, azimuth
    in [0, 360] deg."""
    if isinstance(raw, str) and raw:
        path = Path(raw).expanduser()
        if not path.is_absolute() and base_dir is not None:
            path = base_dir / path
        return read_survey_csv(path)
    if not isinstance(raw, list) or not raw:
        raise ParameterError("'well.survey' must be a list of {md_m, inclination_deg, "
                             "azimuth_deg} starting at md_m 0, or a CSV file's name")
    for i, point in enumerate(raw):
        if not isinstance(point, dict):
            raise ParameterError(f"'well.survey[{i}]' must be a mapping of "
                                 f"{', '.join(COLUMNS)}")
        check_known_keys(point, COLUMNS, f"well.survey[{i}]")

    def where(i: int | None, column: str | None) -> str:
        return "'well.survey'" if i is None else f"'well.survey[{i}].{column}'"
    return survey_from_rows(raw, where)


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


def well_from_dict(raw: Any, base_dir: Path | None = None) -> Well:
    """A preset's ``well`` mapping (module doc), each error one line naming the key; a
    survey file's name is read relative to ``base_dir`` (the preset's directory)."""
    if not isinstance(raw, dict):
        raise ParameterError(f"'well' must be a mapping of {', '.join(WELL_KEYS)}")
    check_known_keys(raw, WELL_KEYS, "well")
    if "survey" not in raw:
        raise ParameterError("'well' needs a survey: [{md_m: 0, inclination_deg: 0, "
                             "azimuth_deg: 0}, ...] or a CSV file's name")
    return Well(_survey(raw["survey"], base_dir),
                _number("well.mud_density_kg_m3", raw.get("mud_density_kg_m3", 0.0), 0.0,
                        5000.0),
                _friction(raw.get("side_friction", {})))


def well_to_dict(well: Well) -> dict[str, Any]:
    """The preset mapping of ``well`` (what :func:`well_from_dict` reads)."""
    f = well.side_friction
    return {"survey": [dict(zip(COLUMNS, station, strict=True))
                       for station in well.survey.stations],
            "mud_density_kg_m3": well.mud_density_kg_m3,
            "side_friction": {"static": f.static, "dynamic": f.dynamic,
                              "stick_speed_rad_s": f.stick_speed_rad_s}}
