"""The distributed string on the dashboard: a depth x time picture of its angular speed and
the current speed and torque along depth, from drill/typed/string/torsion
(drill_sim_msgs/StringProfile) or drill/string/torsion (JointState).

The picture (:data:`~drill_sim_ros.viz.entities.STRING_PICTURE`) is an RGB image, one row
per depth (top drive at the top, bit at the bottom), one column per profile (newest at the
right), the last :data:`IMAGE_PROFILES` profiles (:data:`NO_DATA` grey before the first).
Its colours are a diverging map centred on the mean speed of the profiles it shows: white at
the mean, blue slower, red faster, the ends at the mean -+ the deviation that 99% of the
pixels stay within (:class:`ColourScale`). Torsional waves show as slanted stripes,
stick-slip as blue bands spreading up from the bottom. Beside it: a depth axis (m), a time
axis (s before the newest profile) and a colour bar labelled in rpm. It is logged at most
once per :data:`IMAGE_PERIOD_S` of sim time (the viewer shows the latest), in a fixed frame
(:data:`FRAME_BOUNDS`, the view's visual bounds) whatever the number of depths. The profiles
are two bar charts over depth (abscissa: depth below the top, m).
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
from drill_sim_ros.viz.frames import nice_step
from drill_sim_ros.viz.static_views import GREY, log_labels

IMAGE_PROFILES = 300        # 30 s at the default 10 Hz; a multiple of 4
IMAGE_PERIOD_S = 1.0
MIN_HALF_SPAN_RPM = 1.0     # the colour scale's least half span, rpm
MIN_HALF_SPAN_OF_MEAN = 0.05  # ... and share of the mean (a steady string stays pale)
SPAN_PERCENTILE = 99.0      # the ends: the deviation from the mean this share stays within
# ColorBrewer's RdBu (11 classes), from slow to fast: dark blue .. white (the middle) .. dark
# red; an odd number of stops puts white exactly at the scale's centre.
_STOPS = np.array([(5, 48, 97), (33, 102, 172), (67, 147, 195), (146, 197, 222),
                   (209, 229, 240), (247, 247, 247), (253, 219, 199), (244, 165, 130),
                   (214, 96, 77), (178, 24, 43), (103, 0, 31)], dtype=np.float64)
MIDDLE_COLOUR = tuple(int(c) for c in _STOPS[len(_STOPS) // 2])
NO_DATA = (90, 90, 90)      # columns before the first profile: no colour of the map
SPEED_COLOR, TORQUE_COLOR = (31, 119, 180), (44, 160, 44)
# The frame, in picture columns: the picture is IMAGE_PROFILES wide and PICTURE_HEIGHT high
# (its rows scaled to it), the colour bar BAR_WIDTH wide at BAR_GAP to its right.
PICTURE_HEIGHT = 80.0
BAR_GAP, BAR_WIDTH, BAR_ROWS = 8.0, 10.0, 65       # odd rows: one at the centre
LABEL_ROW_BELOW, LABEL_ROW_ABOVE = PICTURE_HEIGHT + 4.0, -18.0
# rerun draws a point's label just below the point: about this many frame units at the
# dashboard's sizes, so a label meant beside a tick is anchored this much above it
LABEL_DROP = 5.0
FRAME_BOUNDS = ((-44.0, IMAGE_PROFILES + BAR_GAP + BAR_WIDTH + 40.0),
                (-22.0, PICTURE_HEIGHT + 18.0))


def palette(fraction: np.ndarray) -> np.ndarray:
    """RGB uint8, shape (*fraction.shape, 3), of positions on the colour map: 0 the slow end,
    0.5 the middle (white), 1 the fast end; clipped to [0, 1]."""
    x = np.clip(fraction, 0.0, 1.0) * (len(_STOPS) - 1)
    low = np.minimum(x.astype(np.int64), len(_STOPS) - 2)
    frac = (x - low)[..., None]
    return np.round(_STOPS[low] * (1.0 - frac) + _STOPS[low + 1] * frac).astype(np.uint8)


@dataclass(frozen=True)
class ColourScale:
    """The picture's colour scale: ``centre_rpm`` white, ``centre_rpm -+ half_span_rpm`` the
    two ends."""

    centre_rpm: float
    half_span_rpm: float

    @classmethod
    def of(cls, speed_rpm: np.ndarray) -> ColourScale:
        """Centred on the mean of ``speed_rpm`` (the profiles shown); the half span is the
        deviation from it that SPAN_PERCENTILE % of the values stay within, at least
        MIN_HALF_SPAN_OF_MEAN of the mean and MIN_HALF_SPAN_RPM."""
        centre = float(np.mean(speed_rpm))
        spread = float(np.percentile(np.abs(speed_rpm - centre), SPAN_PERCENTILE))
        return cls(centre, max(spread, MIN_HALF_SPAN_OF_MEAN * abs(centre),
                               MIN_HALF_SPAN_RPM))

    def colours(self, speed_rpm: np.ndarray) -> np.ndarray:
        """RGB uint8, shape (*speed_rpm.shape, 3); beyond the ends: the end colours."""
        return palette(0.5 + 0.5 * (speed_rpm - self.centre_rpm) / self.half_span_rpm)

    def ticks_rpm(self) -> np.ndarray:
        """The colour bar's labelled speeds, top (fast) to bottom (slow)."""
        return self.centre_rpm + self.half_span_rpm * np.array([1.0, 0.5, 0.0, -0.5, -1.0])


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


def profile_fields(msg: Any) -> tuple[tuple[Any, ...], Any, Any]:
    """(its depths, speeds rad/s, torques N m) of a profile message of either kind: a
    drill_sim_msgs/StringProfile (depths in m) or a JointState of drill/string/torsion (its
    joint names, one per depth)."""
    if hasattr(msg, "depth_m"):
        return tuple(msg.depth_m), msg.speed_rad_s, msg.torque_nm
    return tuple(msg.name), msg.velocity, msg.effort


def string_batch(messages: list[Any]) -> StringBatch | None:
    """A batch of string profiles, StringProfile or JointState messages, of one kind (None:
    none, or malformed: arrays not as long as the depths, or the depths changed within the
    list)."""
    fields = [profile_fields(m) for m in messages]
    first = fields[0][0] if fields else ()
    good = [(m, speed, torque) for m, (depths, speed, torque) in zip(messages, fields,
                                                                     strict=True)
            if depths and depths == first and len(speed) == len(torque) == len(depths)]
    if not good:
        return None
    times = np.array([m.header.stamp.sec + m.header.stamp.nanosec / NS_PER_S
                      for m, _, _ in good])
    depths_m = [depth_of_joint(d) if isinstance(d, str) else float(d) for d in first]
    return StringBatch(times, np.array(depths_m, dtype=np.float64),
                       np.array([speed for _, speed, _ in good], dtype=np.float64),
                       np.array([torque for _, _, torque in good], dtype=np.float64))


def depth_axis_y(depths_m: np.ndarray) -> tuple[float, float]:
    """The depths m at the top and bottom edges of the picture: its rows are cells centred
    on ``depths_m`` (top to bottom, equally spaced: the middles of equal intervals)."""
    if len(depths_m) < 2:
        return 0.0, 2.0 * float(depths_m[0])
    half_cell = 0.5 * (float(depths_m[-1]) - float(depths_m[0])) / (len(depths_m) - 1)
    return float(depths_m[0]) - half_cell, float(depths_m[-1]) + half_cell


class StringViews:
    """Logs string profiles: keeps the last :data:`IMAGE_PROFILES` (speeds, rpm) for the
    picture."""

    def __init__(self, rec: Any) -> None:
        self.rec = rec
        self._columns: deque[np.ndarray] = deque(maxlen=IMAGE_PROFILES)
        self._last_image_s = -np.inf
        self._last_profile_s: float | None = None
        self._period_s: float | None = None       # between profiles, once two came
        self._depths_m: np.ndarray | None = None
        self.profiles = 0

    def log(self, batch: StringBatch) -> None:
        """The bar charts of every profile and the picture when one is due."""
        if not len(batch):
            return
        if self._depths_m is None or not np.array_equal(self._depths_m, batch.depths_m):
            self._columns.clear()                 # other depths: a new picture
            self._depths_m = batch.depths_m
            self._log_frame(float(batch.sim_time_s[0]))
        rpm = batch.speed_rad_s * RPM_PER_RAD_S
        for t_s, column, torque in zip(batch.sim_time_s.tolist(), rpm, batch.torque_nm,
                                       strict=True):
            if t_s < self._last_image_s:
                self._columns.clear()             # sim time went back: a reset
                self._last_image_s = -np.inf
            elif self._last_profile_s is not None and t_s > self._last_profile_s:
                self._period_s = t_s - self._last_profile_s
            self._last_profile_s = t_s
            self._log_bars(t_s, column, torque)
            self._columns.append(column)
            if t_s - self._last_image_s >= IMAGE_PERIOD_S:
                self._log_image(t_s)
        self.profiles += len(batch)

    def _log_image(self, t_s: float) -> None:
        """The picture, its colour scale's labels and the time axis at ``t_s``. Always
        IMAGE_PROFILES wide, NO_DATA until there are as many profiles: a fixed picture, and
        rows of a multiple of 4 bytes (the web viewer draws no others)."""
        speed_rpm = np.stack(self._columns, axis=1)              # (depths, profiles)
        scale = ColourScale.of(speed_rpm)
        image = np.empty((speed_rpm.shape[0], IMAGE_PROFILES, 3), dtype=np.uint8)
        image[:] = NO_DATA
        image[:, IMAGE_PROFILES - speed_rpm.shape[1]:] = scale.colours(speed_rpm)
        self.rec.set_time(ent.TIMELINE, duration=t_s)
        self.rec.log(ent.STRING_PICTURE, rr.Image(image, color_model="RGB"))
        self._log_scale(scale)
        self._log_time_axis()
        self._last_image_s = t_s

    def _log_frame(self, t_s: float) -> None:
        """What changes only with the depths: the picture's row scale, its outline, the
        depth axis; and the colour bar (one image of the palette, fast at the top)."""
        depths = self._depths_m
        top_m, bottom_m = depth_axis_y(depths)
        self.rec.set_time(ent.TIMELINE, duration=t_s)
        self.rec.log(ent.STRING_PICTURE, rr.Transform3D(
            scale=[1.0, PICTURE_HEIGHT / len(depths), 1.0]))
        w, h = float(IMAGE_PROFILES), PICTURE_HEIGHT
        self.rec.log(ent.STRING_OUTLINE, rr.LineStrips2D(
            [[(0.0, 0.0), (w, 0.0), (w, h), (0.0, h), (0.0, 0.0)]], colors=GREY,
            radii=rr.Radius.ui_points(0.75)))
        step = nice_step(bottom_m - top_m, 6)
        # (the depths come from joint names, to 0.1 m: an edge may miss a tick by that)
        ticks_m = np.arange(np.ceil(top_m / step - 0.01) * step, bottom_m + 0.01 * step,
                            step) + 0.0                                  # (no "-0")
        ys = (ticks_m - top_m) / (bottom_m - top_m) * h
        self.rec.log(f"{ent.STRING_DEPTH_AXIS}/ticks", rr.LineStrips2D(
            [[(-4.0, y), (0.0, y)] for y in ys], colors=GREY, radii=rr.Radius.ui_points(0.75)))
        log_labels(self.rec, ent.STRING_DEPTH_AXIS,
                   [(-22.0, y - LABEL_DROP) for y in ys] + [(-22.0, LABEL_ROW_BELOW)],
                   [f"{d:g}" for d in ticks_m] + ["depth [m]"], static=False)
        fraction = 1.0 - (np.arange(BAR_ROWS) + 0.5) / BAR_ROWS          # top row: fast
        bar = np.repeat(palette(fraction)[:, None, :], 4, axis=1)          # 12-byte rows
        self.rec.log(ent.STRING_COLOUR_BAR, rr.Image(bar, color_model="RGB"),
                     rr.Transform3D(translation=[w + BAR_GAP, 0.0, 0.0],
                                    scale=[BAR_WIDTH / 4, h / BAR_ROWS, 1.0]))

    def _log_scale(self, scale: ColourScale) -> None:
        """The colour bar's labels (rpm, fast at the top) for ``scale``."""
        ticks = scale.ticks_rpm()
        ys = np.linspace(0.0, PICTURE_HEIGHT, len(ticks))
        x = IMAGE_PROFILES + BAR_GAP + BAR_WIDTH + 18.0
        digits = 0 if scale.half_span_rpm >= 10.0 else 1
        log_labels(self.rec, ent.STRING_SCALE_LABELS,
                   [(x, y - LABEL_DROP) for y in ys] + [(x, LABEL_ROW_ABOVE)],
                   [f"{v:.{digits}f}" for v in ticks] + ["rpm"], static=False)

    def _log_time_axis(self) -> None:
        """Seconds before the newest profile under the picture's columns (only "now" until
        the profile period is known)."""
        now_x = IMAGE_PROFILES - 0.5
        if self._period_s is None:
            log_labels(self.rec, ent.STRING_TIME_AXIS, [(now_x, LABEL_ROW_BELOW)], ["now"],
                       static=False)
            return
        span_s = self._period_s * IMAGE_PROFILES
        step = nice_step(span_s, 4)
        ago_s = np.arange(0.0, span_s - 0.5 * self._period_s, step)
        xs = now_x - ago_s / self._period_s
        log_labels(self.rec, ent.STRING_TIME_AXIS, [(x, LABEL_ROW_BELOW) for x in xs],
                   ["now"] + [f"-{a:g} s" for a in ago_s[1:]], static=False)

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
