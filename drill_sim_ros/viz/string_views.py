"""The distributed string on the dashboard: a depth x time picture of its angular speed and
the current speed and torque along depth, from drill/string/torsion.

The picture is an RGB image, one row per depth (top drive at the top, bit at the bottom),
one column per profile (newest at the right), the last :data:`IMAGE_PROFILES` profiles
(white before the first),
coloured by speed from 0 (dark blue) to :attr:`StringViews.full_scale_rpm` (dark red):
torsional waves show as slanted stripes, stick-slip as dark blue bands at the bottom. It is
logged at most once per :data:`IMAGE_PERIOD_S` of sim time (the viewer shows the latest).
The profiles are two bar charts over depth (abscissa: depth below the top, m).
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass
from typing import Any

import numpy as np
import rerun as rr

from drill_sim_ros.model.params import RPM_PER_RAD_S
from drill_sim_ros.model.telemetry import NS_PER_S
from drill_sim_ros.viz import entities as ent

IMAGE_PROFILES = 300        # 30 s at the default 10 Hz; a multiple of 4
IMAGE_PERIOD_S = 1.0
FULL_SCALE_OF_NOMINAL = 2.0  # the colour scale's top, times the nominal speed (green: nominal)
# colour stops from 0 to full scale: dark blue, blue, cyan, green, yellow, red, dark red
_STOPS = np.array([(0, 0, 110), (30, 80, 220), (0, 200, 230), (60, 190, 60), (245, 225, 40),
                   (230, 50, 30), (120, 0, 0)], dtype=np.float64)
SPEED_COLOR, TORQUE_COLOR = (31, 119, 180), (44, 160, 44)


@dataclass(frozen=True)
class StringBatch:
    """``n`` string profiles: ``sim_time_s`` (n,), ``depths_m`` (d,), ``speed_rad_s`` and
    ``torque_nm`` (n, d)."""

    sim_time_s: np.ndarray
    depths_m: np.ndarray
    speed_rad_s: np.ndarray
    torque_nm: np.ndarray

    def __len__(self) -> int:
        return len(self.sim_time_s)


def depth_of_joint(name: str) -> float:
    """The depth m in a drill/string/torsion joint name (``string_0021.1m`` -> 21.1)."""
    return float(name.removeprefix("string_").removesuffix("m"))


def string_batch(messages: list[Any]) -> StringBatch | None:
    """A batch of JointState messages of drill/string/torsion (None: none, or malformed:
    arrays not as long as the names, or the depths changed within the list)."""
    good = [m for m in messages if m.name and len(m.velocity) == len(m.effort) == len(m.name)
            and list(m.name) == list(messages[0].name)]
    if not good:
        return None
    times = np.array([m.header.stamp.sec + m.header.stamp.nanosec / NS_PER_S for m in good])
    return StringBatch(times, np.array([depth_of_joint(n) for n in good[0].name]),
                       np.array([m.velocity for m in good], dtype=np.float64),
                       np.array([m.effort for m in good], dtype=np.float64))


def speed_colors(speed_rpm: np.ndarray, full_scale_rpm: float) -> np.ndarray:
    """RGB uint8, shape (*speed_rpm.shape, 3), of speeds on the 0 .. full-scale colour map
    (below 0: the bottom colour; above full scale: the top one)."""
    x = np.clip(speed_rpm / full_scale_rpm, 0.0, 1.0) * (len(_STOPS) - 1)
    low = np.minimum(x.astype(np.int64), len(_STOPS) - 2)
    frac = (x - low)[..., None]
    return np.round(_STOPS[low] * (1.0 - frac) + _STOPS[low + 1] * frac).astype(np.uint8)


class StringViews:
    """Logs string profiles: keeps the last :data:`IMAGE_PROFILES` for the picture."""

    def __init__(self, rec: Any, nominal_rpm: float) -> None:
        self.rec = rec
        self.full_scale_rpm = FULL_SCALE_OF_NOMINAL * max(abs(nominal_rpm), 1.0)
        self._columns: deque[np.ndarray] = deque(maxlen=IMAGE_PROFILES)
        self._last_image_s = -np.inf
        self._depths_m: np.ndarray | None = None
        self.profiles = 0

    def log(self, batch: StringBatch) -> None:
        """The bar charts of every profile and the picture when one is due."""
        if not len(batch):
            return
        if self._depths_m is None or not np.array_equal(self._depths_m, batch.depths_m):
            self._columns.clear()                 # other depths: a new picture
            self._depths_m = batch.depths_m
        rpm = batch.speed_rad_s * RPM_PER_RAD_S
        for t_s, column, torque in zip(batch.sim_time_s.tolist(), rpm, batch.torque_nm,
                                       strict=True):
            if t_s < self._last_image_s:
                self._columns.clear()             # sim time went back: a reset
                self._last_image_s = -np.inf
            self._log_bars(t_s, column, torque)
            self._columns.append(speed_colors(column, self.full_scale_rpm))
            if t_s - self._last_image_s >= IMAGE_PERIOD_S:
                self._log_image(t_s)
        self.profiles += len(batch)

    def _log_image(self, t_s: float) -> None:
        # always IMAGE_PROFILES wide, white until there are as many profiles: a fixed
        # picture, and rows of a multiple of 4 bytes (the web viewer draws no others)
        columns = np.stack(self._columns, axis=1)                # (depths, profiles, 3)
        image = np.full((columns.shape[0], IMAGE_PROFILES, 3), 255, dtype=np.uint8)
        image[:, IMAGE_PROFILES - columns.shape[1]:] = columns
        self.rec.set_time(ent.TIMELINE, duration=t_s)
        self.rec.log(ent.STRING_DEPTH_TIME, rr.Image(image, color_model="RGB"))
        self._last_image_s = t_s

    def _log_bars(self, t_s: float, rpm: np.ndarray, torque_nm: np.ndarray) -> None:
        """The bar charts of one profile: speed rpm and torque kN m over depth m. Logged
        row by row (the stream's batcher merges them into chunks: one chunk per row, as
        ``send_columns`` makes them, loads slowly in the web viewer)."""
        depths = self._depths_m
        width = 0.9 * (float(np.diff(depths).min()) if len(depths) > 1 else 1.0)
        self.rec.set_time(ent.TIMELINE, duration=t_s)
        self.rec.log(ent.STRING_SPEED, rr.BarChart(rpm, abscissa=depths, widths=[width],
                                                   color=SPEED_COLOR))
        self.rec.log(ent.STRING_TORQUE, rr.BarChart(torque_nm * 1e-3, abscissa=depths,
                                                    widths=[width], color=TORQUE_COLOR))
