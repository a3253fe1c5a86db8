"""A rig's surface log: read from a CSV, a LAS file or a sim_node recording, checked, cut
into start-ups.

What a log holds (SI once read), each of shape (samples,): time s, the drive's surface
speed rad/s and a surface torque N m, either the torque sub's string torque at the quill
(``string``) or the drive's motor torque (``motor``); optionally the hook load N, the WOB N,
a downhole bit speed rad/s and the drive's speed setpoint rad/s (``drill_sim fit --follow
setpoint``).

CSV and LAS columns are named by what they hold and end in their unit (case ignored):

* time: ``time_s``, ``t_s`` (s);
* surface speed: ``surface_rpm``, ``drive_rpm``, ``rpm``, ``surface_speed_rad_s``,
  ``drive_speed_rad_s`` (rev/min or rad/s);
* torque: ``string_torque_nm`` / ``_knm`` or ``torque_sub_nm`` / ``_knm`` (the torque sub),
  ``motor_torque_nm`` / ``_knm``, ``surface_torque_nm`` / ``_knm``, ``torque_nm`` / ``_knm``
  (the drive's reading: motor torque); the string torque is taken when both are given;
* optional: ``hook_load_n`` / ``_kn``, ``wob_n`` / ``_kn``, ``bit_rpm`` /
  ``bit_speed_rad_s``, ``setpoint_rpm`` / ``setpoint_rad_s``.

A LAS file's curves are read by mnemonic and unit (``RPM`` in ``rpm``, ``TORQUE`` in
``kN.m``, ...: the mnemonic, an underscore and the unit with dots and slashes dropped);
its index must be time in s. A recording (``.mcap``) is read on
``drill/surface/measured``: the top drive's speed and motor torque, the quill's string
torque and the hook load, at their header stamps.

A log is refused, in one line naming what is wrong, when a needed column is missing, its
times do not increase (unsorted or repeated), the sampling has gaps, or a needed signal has
a run of NaN.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from drill_sim_ros.fit.errors import LogError
from drill_sim_ros.model.params import RPM_PER_RAD_S

RAD_S_PER_RPM = 1.0 / RPM_PER_RAD_S
MAX_GAP_RATIO = 1.5          # a step longer than this times the median: a gap
REST_RPM = 2.0               # the drive at rest below this (its smoothed speed)
TURNING_RPM = 5.0            # the drive turning above this
MIN_REST_S = 0.5             # the shortest rest that a start-up starts from
LEAD_S = 1.0                 # rest kept before a start-up's rise
SMOOTH_S = 0.2               # the speed's running mean when start-ups are looked for

TIME_NAMES = ("time_s", "t_s")
SPEED_NAMES = {"surface_rpm": 1.0 * RAD_S_PER_RPM, "drive_rpm": RAD_S_PER_RPM,
               "rpm": RAD_S_PER_RPM, "surface_speed_rpm": RAD_S_PER_RPM,
               "drive_speed_rpm": RAD_S_PER_RPM, "surface_speed_rad_s": 1.0,
               "drive_speed_rad_s": 1.0}
STRING_TORQUE_NAMES = {"string_torque_nm": 1.0, "string_torque_knm": 1e3,
                       "torque_sub_nm": 1.0, "torque_sub_knm": 1e3}
MOTOR_TORQUE_NAMES = {"motor_torque_nm": 1.0, "motor_torque_knm": 1e3,
                      "surface_torque_nm": 1.0, "surface_torque_knm": 1e3,
                      "torque_nm": 1.0, "torque_knm": 1e3}
OPTIONAL_NAMES = {"hook_load_n": {"hook_load_n": 1.0, "hook_load_kn": 1e3},
                  "wob_n": {"wob_n": 1.0, "wob_kn": 1e3},
                  "bit_speed_rad_s": {"bit_rpm": RAD_S_PER_RPM, "bit_speed_rad_s": 1.0},
                  "setpoint_rad_s": {"setpoint_rpm": RAD_S_PER_RPM, "setpoint_rad_s": 1.0}}
TORQUE_KINDS = ("string", "motor")


@dataclass(frozen=True)
class SurfaceLog:
    """A log in SI (module doc); ``torque_kind`` is 'string' or 'motor'; ``source`` names
    the file; optional signals are None when not logged."""

    source: str
    t_s: np.ndarray
    speed_rad_s: np.ndarray
    torque_nm: np.ndarray
    torque_kind: str
    hook_load_n: np.ndarray | None = None
    wob_n: np.ndarray | None = None
    bit_speed_rad_s: np.ndarray | None = None
    setpoint_rad_s: np.ndarray | None = None    # the drive's commanded speed (--follow)

    @property
    def sample_s(self) -> float:
        """The median sampling period, s."""
        return float(np.median(np.diff(self.t_s)))

    def part(self, start: int, stop: int) -> SurfaceLog:
        """The samples [start, stop) (times as logged)."""
        cut = slice(start, stop)
        return replace(self, t_s=self.t_s[cut], speed_rad_s=self.speed_rad_s[cut],
                       torque_nm=self.torque_nm[cut],
                       **{name: None if getattr(self, name) is None else getattr(self, name)[cut]
                          for name in OPTIONAL_NAMES})

    def window(self, t0_s: float, t1_s: float) -> SurfaceLog:
        """The samples with t0_s <= t <= t1_s; LogError when fewer than two."""
        inside = np.flatnonzero((self.t_s >= t0_s) & (self.t_s <= t1_s))
        if inside.size < 2:
            raise LogError(f"{self.source}: --window {t0_s:g}:{t1_s:g} holds fewer than two "
                           f"samples (the log spans {self.t_s[0]:g} to {self.t_s[-1]:g} s)")
        return self.part(int(inside[0]), int(inside[-1]) + 1)


# ---- reading --------------------------------------------------------------------------
def read_log(path: str | Path, torque_kind: str | None = None) -> SurfaceLog:
    """The log at ``path`` (by its suffix: .mcap, .las, else CSV), checked (module doc);
    ``torque_kind`` ('string' / 'motor') picks the torque when the log has both."""
    path = Path(path)
    if not path.is_file():
        raise LogError(f"--log {path}: no such file")
    suffix = path.suffix.lower()
    if suffix == ".mcap":
        from drill_sim_ros.fit.mcap_log import read_mcap_columns
        columns = read_mcap_columns(path)
    elif suffix == ".las":
        columns = _las_columns(path)
    else:
        columns = _csv_columns(path)
    return check_log(log_from_columns(str(path), columns, torque_kind))


def _csv_columns(path: Path) -> dict[str, np.ndarray]:
    """The CSV's columns by lower-case header name (numbers; an empty cell is NaN)."""
    try:
        with path.open() as f:
            header = f.readline()
            table = np.genfromtxt(f, delimiter=",", dtype=float, ndmin=2)
    except (OSError, UnicodeDecodeError, ValueError) as exc:
        raise LogError(f"--log {path}: not a readable CSV ({exc})") from None
    names = [name.strip().strip('"').lower() for name in header.split(",")]
    if table.size == 0 or table.shape[1] != len(names):
        raise LogError(f"--log {path}: the CSV needs a header line and rows of "
                       f"{len(names)} numbers each")
    return {name: table[:, i] for i, name in enumerate(names)}


def _las_columns(path: Path) -> dict[str, np.ndarray]:
    """A LAS file's curves named mnemonic_unit (module doc); the index is time in s."""
    import lasio
    try:
        las = lasio.read(str(path))
    except Exception as exc:     # lasio raises many kinds on a bad file
        raise LogError(f"--log {path}: not a readable LAS file ({exc})") from None
    columns: dict[str, np.ndarray] = {}
    for i, curve in enumerate(las.curves):
        unit = curve.unit.lower().replace(".", "").replace("/", "_").replace(" ", "")
        name = curve.mnemonic.lower()
        if i == 0:
            if unit not in ("s", "sec"):
                raise LogError(f"--log {path}: the LAS index {curve.mnemonic} is in "
                               f"{curve.unit!r}; it must be time in s")
            name, unit = "time", "s"
        columns[f"{name}_{unit}" if unit else name] = np.asarray(curve.data, dtype=float)
    return columns


def _pick(columns: dict[str, np.ndarray], names: dict[str, float]
          ) -> tuple[str, np.ndarray] | None:
    """The first of ``names`` present, converted to SI by its factor."""
    for name, factor in names.items():
        if name in columns:
            return name, columns[name] * factor
    return None


def log_from_columns(source: str, columns: dict[str, np.ndarray],
                     torque_kind: str | None = None) -> SurfaceLog:
    """A :class:`SurfaceLog` from named columns (module doc); LogError naming a missing one."""
    time = next((columns[name] for name in TIME_NAMES if name in columns), None)
    if time is None:
        raise LogError(f"{source}: no time column (one of {', '.join(TIME_NAMES)}); "
                       f"columns: {', '.join(columns)}")
    speed = _pick(columns, SPEED_NAMES)
    if speed is None:
        raise LogError(f"{source}: no surface speed column (one of "
                       f"{', '.join(SPEED_NAMES)}); columns: {', '.join(columns)}")
    torques = {"string": _pick(columns, STRING_TORQUE_NAMES),
               "motor": _pick(columns, MOTOR_TORQUE_NAMES)}
    if torque_kind is not None and torque_kind not in TORQUE_KINDS:
        raise LogError(f"--torque {torque_kind!r} must be one of {TORQUE_KINDS}")
    kind = torque_kind or ("string" if torques["string"] is not None else "motor")
    if torques[kind] is None:
        wanted = STRING_TORQUE_NAMES if kind == "string" else MOTOR_TORQUE_NAMES
        raise LogError(f"{source}: no {kind} torque column (one of {', '.join(wanted)}); "
                       f"columns: {', '.join(columns)}")
    optional = {key: _pick(columns, names) for key, names in OPTIONAL_NAMES.items()}
    return SurfaceLog(source=source, t_s=np.asarray(time, dtype=float),
                      speed_rad_s=speed[1], torque_nm=torques[kind][1], torque_kind=kind,
                      **{key: None if v is None else v[1] for key, v in optional.items()})


# ---- checks ---------------------------------------------------------------------------
def check_log(log: SurfaceLog) -> SurfaceLog:
    """``log`` if usable, else LogError in one line: fewer than 3 samples, times that do
    not increase (the first bad row named), a gap, a NaN run in a needed signal. An
    optional signal with a NaN is dropped (not refused)."""
    t = log.t_s
    if t.size < 3:
        raise LogError(f"{log.source}: {t.size} samples; a log needs at least 3")
    _check_finite(log.source, "time", t)
    dt = np.diff(t)
    if np.any(dt <= 0.0):
        row = int(np.argmax(dt <= 0.0)) + 1
        what = "repeated" if dt[row - 1] == 0.0 else "not increasing (unsorted)"
        raise LogError(f"{log.source}: the times are {what} at sample {row} "
                       f"(t = {t[row]:g} s after {t[row - 1]:g} s)")
    median = float(np.median(dt))
    if np.max(dt) > MAX_GAP_RATIO * median:
        row = int(np.argmax(dt))
        raise LogError(f"{log.source}: a gap of {dt[row]:g} s after t = {t[row]:g} s (the "
                       f"sampling period is {median:g} s); cut it out with --window")
    _check_finite(log.source, "surface speed", log.speed_rad_s)
    _check_finite(log.source, f"{log.torque_kind} torque", log.torque_nm)
    dropped = {name: None for name in OPTIONAL_NAMES
               if getattr(log, name) is not None and not np.all(np.isfinite(getattr(log, name)))}
    return replace(log, **dropped)


def _check_finite(source: str, what: str, values: np.ndarray) -> None:
    bad = ~np.isfinite(values)
    if bad.any():
        first = int(np.argmax(bad))
        last = first + int(np.argmax(~bad[first:])) if (~bad[first:]).any() else values.size
        raise LogError(f"{source}: the {what} is NaN or infinite in samples {first} to "
                       f"{last - 1} ({int(bad.sum())} samples in all)")


# ---- start-ups ------------------------------------------------------------------------
def find_startups(log: SurfaceLog) -> list[tuple[int, int]]:
    """The start-ups in ``log`` as sample spans [start, stop): the drive at rest (its
    ``SMOOTH_S`` running mean below ``REST_RPM``) for at least ``MIN_REST_S``, then turning
    (above ``TURNING_RPM`` before it rests again); a span starts ``LEAD_S`` (at most the
    rest's length) before the rest ends and stops where the next such rest begins, or at the
    end. LogError when there is none."""
    dt = log.sample_s
    rpm = _running_mean(log.speed_rad_s / RAD_S_PER_RPM, max(1, round(SMOOTH_S / dt)))
    rests = [(a, b) for a, b in _runs(np.abs(rpm) < REST_RPM)
             if b - a >= max(1, round(MIN_REST_S / dt))]
    spans = []
    for i, (a, b) in enumerate(rests):
        stop = rests[i + 1][0] if i + 1 < len(rests) else rpm.size
        moving = _runs(np.abs(rpm[b:stop]) >= REST_RPM)
        if moving and np.any(rpm[b:b + moving[0][1]] > TURNING_RPM):
            spans.append((max(a, b - max(1, round(LEAD_S / dt))), stop))
    if not spans:
        raise LogError(f"{log.source}: no start-up in the window (the drive at rest, below "
                       f"{REST_RPM:g} rpm for {MIN_REST_S:g} s, then above {TURNING_RPM:g} rpm)")
    return spans


def _runs(mask: np.ndarray) -> list[tuple[int, int]]:
    """The runs of True in ``mask`` as spans [start, stop)."""
    edges = np.flatnonzero(np.diff(np.concatenate(([0], mask.astype(np.int8), [0]))))
    return [(int(a), int(b)) for a, b in zip(edges[::2], edges[1::2], strict=True)]


def _running_mean(values: np.ndarray, width: int) -> np.ndarray:
    """A centred running mean of ``width`` samples (shorter at the ends)."""
    kernel = np.ones(width)
    return (np.convolve(values, kernel, mode="same")
            / np.convolve(np.ones_like(values), kernel, mode="same"))
