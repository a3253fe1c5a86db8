"""A well path as a drilling engineer gives it: survey stations of measured depth,
inclination and azimuth, joined by minimum curvature.

Between two stations the path is the circular arc that meets both tangents (the minimum
curvature method, Mason & Taylor 1971; Sawaryn & Thorogood, SPE 84246, 2003): its dog-leg
is the angle between the two tangents, its curvature the dog-leg over the course length,
constant along the leg. The arc mathematics is welleng's (``welleng.utils.MinCurve``,
Apache-2.0): positions, dog-legs and the attitude (inclination, azimuth) anywhere on a leg.
It is used only here and only when a well is built (the kernel never sees a survey: the
string's builder reads normal forces from it once), so it costs the kernel nothing.

A survey without azimuths (the old ``{md_m, inclination_deg}`` form) has azimuth 0: a 2-D
well in one vertical plane, on which minimum curvature makes the inclination linear in
measured depth between stations, the rule the old form always had.

Past the last station the path goes on straight along the last tangent. SI (m, rad)
except where a name says deg. ROS-free.
"""

from __future__ import annotations

import csv
import functools
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from drill_sim_ros.model.checks import as_number, shown
from drill_sim_ros.model.errors import ParameterError

COLUMNS = ("md_m", "inclination_deg", "azimuth_deg")
MAX_MD_M = 1e5
RANGES = {"md_m": (0.0, MAX_MD_M), "inclination_deg": (0.0, 180.0),
          "azimuth_deg": (0.0, 360.0)}
DLS_COURSE_M = 30.0                     # dog-leg severity per 30 m, the metric convention


@dataclass(frozen=True)
class Survey:
    """Stations ``(md_m, inclination_deg, azimuth_deg)``, measured depth increasing from
    0 (checked by :func:`survey_from_rows`)."""

    stations: tuple[tuple[float, float, float], ...] = ((0.0, 0.0, 0.0),)

    @property
    def md_m(self) -> np.ndarray:
        return np.array([s[0] for s in self.stations])

    @property
    def last_md_m(self) -> float:
        return self.stations[-1][0]

    def _curve(self) -> Any:
        return _min_curve(self.stations)

    def attitude_rad(self, md_m: Any) -> tuple[np.ndarray, np.ndarray]:
        """Inclination and azimuth (rad) at measured depths ``md_m`` (array), on the legs'
        arcs; held past the last station (a straight tangent)."""
        md = np.clip(np.atleast_1d(np.asarray(md_m, dtype=float)), 0.0, self.last_md_m)
        inc, azi = self._curve().inc_azi_at(md)
        return np.asarray(inc), np.asarray(azi)

    def tangent(self, md_m: Any) -> np.ndarray:
        """Unit tangents (n, 3), components (east, north, down), pointing deeper."""
        inc, azi = self.attitude_rad(md_m)
        return np.stack([np.sin(inc) * np.sin(azi), np.sin(inc) * np.cos(azi),
                         np.cos(inc)], axis=-1)

    def curvature_vector(self, md_m: Any) -> np.ndarray:
        """dt/ds (n, 3), 1/m: the path's curvature times the unit normal towards the
        centre of its arc, (east, north, down); zero on straight legs and past the last
        station. On a leg of dog-leg D over course length L the tangent turns in the
        leg's plane at D / L: dt/ds = (D / L) (-sin(phi) v1 + cos(phi) u), phi the angle
        turned so far (welleng's leg frame ``v1, u``)."""
        md = np.atleast_1d(np.asarray(md_m, dtype=float))
        out = np.zeros((md.size, 3))
        if len(self.stations) < 2:
            return out
        curve = self._curve()
        v1, u, curved = curve.leg_frames()
        mds = np.asarray(curve.md, dtype=float)
        leg = np.clip(np.searchsorted(mds, md, side="right") - 1, 0, len(mds) - 2)
        inside = (md >= 0.0) & (md <= mds[-1]) & curved[leg]
        rate = curve.dogleg[leg + 1] / curve.delta_md[leg + 1]
        phi = (md - mds[leg]) * rate
        turn = (-np.sin(phi)[:, None] * v1[leg] + np.cos(phi)[:, None] * u[leg])
        out[inside] = (rate[:, None] * turn)[inside]
        return out

    def dogleg_severity_deg_per_30m(self) -> np.ndarray:
        """Dog-leg severity of each leg (one per station after the first), deg/30 m."""
        if len(self.stations) < 2:
            return np.zeros(0)
        curve = self._curve()
        return np.degrees(curve.dogleg[1:]) * DLS_COURSE_M / curve.delta_md[1:]

    def positions_m(self, md_m: Any) -> np.ndarray:
        """Positions (n, 3) east, north, true vertical depth from the top station, m; past
        the last station straight along its tangent."""
        md = np.atleast_1d(np.asarray(md_m, dtype=float))
        if len(self.stations) < 2:
            return md[:, None] * self.tangent(md)
        curve = self._curve()
        inside = np.minimum(md, self.last_md_m)
        pos = np.asarray(curve.interpolate(inside), dtype=float).reshape(-1, 3)
        return pos + (md - inside)[:, None] * self.tangent(md)

    @property
    def two_dimensional(self) -> bool:
        """True when every azimuth is 0 (the old form, or a well in the north plane)."""
        return all(s[2] == 0.0 for s in self.stations)


@functools.lru_cache(maxsize=64)
def _min_curve(stations: tuple[tuple[float, float, float], ...]) -> Any:
    """welleng's minimum-curvature legs of ``stations`` (imported here, not at module
    load: welleng brings scipy, and a preset without a well never needs it)."""
    from welleng.utils import MinCurve
    rows = stations if len(stations) > 1 else (*stations, (1.0, *stations[0][1:]))
    md, inc, azi = (np.array(col, dtype=float) for col in zip(*rows, strict=True))
    return MinCurve(md, np.radians(inc), np.radians(azi))


def survey_from_rows(rows: list[dict[str, Any]], where: Any) -> Survey:
    """Stations from mappings of md_m, inclination_deg and (optional) azimuth_deg, checked:
    each a number in range, md from 0 and increasing. ``where(i, column)`` names row ``i``
    (and ``column``) in an error, as the input names it (a preset's list, a CSV line)."""
    if not rows:
        raise ParameterError(f"{where(None, None)} has no stations; give md_m, "
                             "inclination_deg, azimuth_deg from md_m 0")
    stations = []
    for i, row in enumerate(rows):
        stations.append(tuple(_value(row, column, where(i, column)) for column in COLUMNS))
    if stations[0][0] != 0.0:
        raise ParameterError(f"{where(0, 'md_m')} = {stations[0][0]:g} must be 0 (the "
                             "survey starts at the surface)")
    for i in range(1, len(stations)):
        if stations[i][0] <= stations[i - 1][0]:
            raise ParameterError(f"{where(i, 'md_m')} = {stations[i][0]:g} must be greater "
                                 f"than the station before ({stations[i - 1][0]:g})")
    return Survey(tuple(stations))


def _value(row: dict[str, Any], column: str, label: str) -> float:
    """``row[column]`` as a number in its range, or one line; azimuth 0 when the row has no
    such key (a CSV's short row has it, empty: that is an error)."""
    if column == "azimuth_deg" and column not in row:
        return 0.0                              # the old 2-D form: no azimuth key at all
    if row.get(column) in (None, ""):
        raise ParameterError(f"{label} is missing")
    low, high = RANGES[column]
    number = as_number(row[column])
    x = math.nan if number is None else float(number)
    if not (math.isfinite(x) and low <= x <= high):
        what = "not a number" if number is None or math.isnan(x) else "out of range"
        raise ParameterError(f"{label} = {shown(row[column])} is {what}; allowed [{low:g}, "
                             f"{high:g}]")
    return x


def read_survey_csv(path: Path) -> Survey:
    """A survey CSV as rigs export it: a header row naming md_m, inclination_deg and
    azimuth_deg (any order, other columns ignored), then one station a line. Each error is
    one line naming the file, the line and the column."""
    try:
        text = path.read_text()
    except OSError as exc:
        raise ParameterError(f"survey file {path}: cannot read it "
                             f"({exc.strerror or exc})") from None
    reader = csv.DictReader(text.splitlines())
    header = [name.strip() for name in reader.fieldnames or []]
    missing = [c for c in COLUMNS if c not in header]
    if missing:
        raise ParameterError(f"survey file {path} line 1: missing column(s) "
                             f"{', '.join(missing)}; the header needs {', '.join(COLUMNS)}")
    rows, lines = [], []
    for row in reader:
        rows.append({(k or "").strip(): v.strip() if isinstance(v, str) else v
                     for k, v in row.items()})
        lines.append(reader.line_num)

    def where(i: int | None, column: str | None) -> str:
        if i is None:
            return f"survey file {path}"
        return f"survey file {path} line {lines[i]} column {column}"
    return survey_from_rows(rows, where)
