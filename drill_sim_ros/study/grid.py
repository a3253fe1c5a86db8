"""What a map computes: the base case, the varied axes and the numerics of every point.

A :class:`MapSpec` is a grid over one or more axes. An axis varies a dimensionless group
(``n, psi, beta, lam, w0, omega0``), the ratio ``w0_ratio`` = W0/lambda (RGD07 eq. 46; W0 is
set to ratio * lambda, lambda held), or, for a physical preset, the surface speed
``surface_rpm`` [rpm] or the weight ``wob_n`` [N] (converted with the preset's t* and
force unit, eqs. 19-20). Points are numbered in C order over the axes.
"""

from __future__ import annotations

import itertools
import json
import math
from dataclasses import asdict, dataclass, field

import numpy as np

from drill_sim_ros.model.checks import check_blade_counts
from drill_sim_ros.model.errors import ParameterError
from drill_sim_ros.model.params import DimensionlessParams, Scales

GROUPS = ("n", "psi", "beta", "lam", "w0", "omega0")
DIMENSIONLESS_AXES = (*GROUPS, "w0_ratio")
PHYSICAL_AXES = ("surface_rpm", "wob_n")
AXIS_UNITS = {"n": "1", "psi": "1", "beta": "1", "lam": "1", "w0": "1", "omega0": "1",
              "w0_ratio": "1", "surface_rpm": "rpm", "wob_n": "N"}
AXIS_LABELS = {"n": "n (blades)", "psi": "ψ", "beta": "β", "lam": "λ", "w0": "W₀",
               "omega0": "ω₀", "w0_ratio": "W₀′ = W₀/λ", "surface_rpm": "surface speed [rpm]",
               "wob_n": "applied weight [N]"}
# Axes that set W0 or omega0; at most one of each pair in a map.
_W_AXES = ("w0", "w0_ratio", "wob_n")
_OMEGA_AXES = ("omega0", "surface_rpm")
MAX_POINTS = 1_000_000      # the Dataset holds every point in memory (~100 MB)


@dataclass(frozen=True)
class Axis:
    """One varied quantity and its values."""

    name: str
    values: tuple[float, ...]

    @property
    def units(self) -> str:
        return AXIS_UNITS[self.name]


@dataclass(frozen=True)
class Numerics:
    """How every point is integrated (the options of ``drill_sim run``)."""

    tau_end: float = 600.0
    average_from: float = 300.0
    dtau: float = 1e-4
    n_nodes: int = 2048
    method: str = "profile"
    perturb_v: float = 0.01
    perturb_omega: float = 0.0

    def __post_init__(self) -> None:
        if not (math.isfinite(self.tau_end) and self.tau_end > 0.0):
            raise ParameterError(f"--tau-end = {self.tau_end!r} must be a positive number")
        if not 0.0 <= self.average_from <= self.tau_end:
            raise ParameterError(f"--average-from = {self.average_from!r} must lie in "
                                 f"[0, tau-end = {self.tau_end!r}]")


@dataclass(frozen=True)
class Control:
    """A controller in the loop of every point (``drill_sim map --controller``): the
    closed-loop bench of :mod:`drill_sim_ros.control.bench`, switched on at ``enable_at_s``."""

    controller: str
    mode: str = "speed"
    enable_at_s: float = 0.0

    def __post_init__(self) -> None:
        if self.mode not in ("speed", "torque"):
            raise ParameterError(f"--mode {self.mode!r} must be speed or torque")
        if not (math.isfinite(self.enable_at_s) and self.enable_at_s >= 0.0):
            raise ParameterError(f"--enable-at = {self.enable_at_s!r} must be a number >= 0 s")


@dataclass(frozen=True)
class MapSpec:
    """A grid of runs: ``base`` with the ``axes`` varied, each point run with ``numerics``."""

    base: DimensionlessParams
    axes: tuple[Axis, ...]
    numerics: Numerics = field(default_factory=Numerics)
    scales: Scales | None = None       # set for physical presets (SI axes allowed)
    preset: str = ""
    control: Control | None = None     # None: the open-loop model (constant surface speed)

    def __post_init__(self) -> None:
        validate_axes(self.axes, physical=self.scales is not None)
        if self.control is not None:
            validate_control(self)
        if self.size > MAX_POINTS:
            shape = " x ".join(f"{n:,}" for n in self.shape)
            raise ParameterError(f"--vary: the map has {self.size:,} points ({shape}); at "
                                 f"most {MAX_POINTS:,} (every point is held in memory)")
        validate_corners(self)

    @property
    def shape(self) -> tuple[int, ...]:
        return tuple(len(a.values) for a in self.axes)

    @property
    def size(self) -> int:
        return math.prod(self.shape)

    def point(self, flat_index: int) -> DimensionlessParams:
        """The groups of point ``flat_index`` (C order over the axes)."""
        where = np.unravel_index(flat_index, self.shape)
        values = {a.name: a.values[int(i)] for a, i in zip(self.axes, where, strict=True)}
        return point_params(self.base, values, self.scales)

    def to_json(self) -> str:
        """Canonical text of the spec (stored in the NetCDF attributes; compared on resume)."""
        return json.dumps({"base": asdict(self.base),
                           "axes": [[a.name, list(a.values)] for a in self.axes],
                           "numerics": asdict(self.numerics),
                           "scales": None if self.scales is None else asdict(self.scales),
                           "preset": self.preset,
                           **({} if self.control is None else
                              {"control": asdict(self.control)})}, sort_keys=True)


def validate_axes(axes: tuple[Axis, ...], physical: bool) -> None:
    """Known names, no repeats, at most one W0 and one omega0 axis, finite values, whole
    numbers of blades."""
    allowed = DIMENSIONLESS_AXES + (PHYSICAL_AXES if physical else ())
    names = [a.name for a in axes]
    if not axes:
        raise ParameterError("a map needs at least one --vary NAME=START:STOP:COUNT")
    for a in axes:
        if a.name not in allowed:
            extra = "" if physical else f" ({', '.join(PHYSICAL_AXES)} need a physical preset)"
            raise ParameterError(f"--vary {a.name!r}: unknown; allowed: "
                                 f"{', '.join(allowed)}{extra}")
        if not a.values or not all(math.isfinite(v) for v in a.values):
            raise ParameterError(f"--vary {a.name}: values must be finite, at least one")
        if a.name == "n":
            check_blade_counts(a.values, "--vary n")
    for group in (_W_AXES, _OMEGA_AXES, names):
        chosen = [n for n in names if n in group]
        if len(chosen) > 1 and group is not names:
            raise ParameterError(f"--vary {' and '.join(chosen)} set the same quantity; "
                                 "vary only one of them")
    if len(set(names)) != len(names):
        raise ParameterError(f"--vary names a quantity twice: {names}")


def validate_corners(spec: MapSpec) -> None:
    """Every corner of the grid (each axis at its smallest and largest value) is a valid
    point of the model, so every point is: the groups' ranges are intervals and each group
    is monotonic in the axes that set it. Checked here, on the client, before any work."""
    ends = [sorted({int(np.argmin(a.values)), int(np.argmax(a.values))}) for a in spec.axes]
    for corner in itertools.product(*ends):
        try:
            spec.point(int(np.ravel_multi_index(corner, spec.shape)))
        except ParameterError as exc:
            where = ", ".join(f"{a.name}={a.values[i]:g}" for a, i in zip(spec.axes, corner,
                                                                         strict=True))
            raise ParameterError(f"--vary: the point {where} is outside the model's range: "
                                 f"{exc}") from None


def validate_control(spec: MapSpec) -> None:
    """A controlled map runs the bench on a physical preset as it is, at each point's surface
    rpm and WOB: only those two axes, within the run."""
    if spec.scales is None or not spec.preset:
        raise ParameterError("--controller needs a physical preset (--params, e.g. "
                             "field_8p5in_shale): the controllers are tuned in SI")
    other = [a.name for a in spec.axes if a.name not in PHYSICAL_AXES]
    if other:
        raise ParameterError(f"--controller: --vary {', '.join(other)} is not a surface input; "
                             f"a controlled map varies only {' and '.join(PHYSICAL_AXES)}")
    from drill_sim_ros.model.presets import load_preset
    preset = load_preset(spec.preset).params
    changed = [g for g in GROUPS if g not in ("w0", "omega0")
               and getattr(spec.base, g) != getattr(preset, g)]
    if changed:
        raise ParameterError(f"--controller runs the preset {spec.preset} as it is: "
                             f"{', '.join(changed)} cannot be changed (only rpm and WOB)")
    end_s = spec.numerics.tau_end * spec.scales.time_s
    if spec.control.enable_at_s > end_s:
        raise ParameterError(f"--enable-at = {spec.control.enable_at_s:g} s must lie in "
                             f"[0, the run's {end_s:g} s]")


def point_params(base: DimensionlessParams, values: dict[str, float],
                 scales: Scales | None) -> DimensionlessParams:
    """``base`` with the axis ``values`` applied (lambda before W0 = ratio * lambda)."""
    changes: dict[str, float | int] = {g: values[g] for g in GROUPS if g in values}
    if "n" in changes:
        changes["n"] = int(changes["n"])          # a whole number (validate_axes)
    lam = float(changes.get("lam", base.lam))
    if "w0_ratio" in values:
        changes["w0"] = values["w0_ratio"] * lam
    if scales is not None and "surface_rpm" in values:
        changes["omega0"] = scales.omega_from_rpm(values["surface_rpm"])
    if scales is not None and "wob_n" in values:
        changes["w0"] = scales.w_from_newton(values["wob_n"])
    return base.with_(**changes)


def parse_vary(text: str) -> Axis:
    """``NAME=START:STOP:COUNT`` (evenly spaced, both ends included) or ``NAME=v1,v2,...``."""
    name, sep, rest = text.partition("=")
    name = name.strip()
    if not sep or not rest:
        raise ParameterError(f"--vary {text!r}: expected NAME=START:STOP:COUNT or "
                             "NAME=V1,V2,...")
    try:
        if ":" in rest:
            start, stop, count = rest.split(":")
            n = int(count)
            if not 1 <= n <= 100_000:
                raise ParameterError(f"--vary {text!r}: COUNT = {n} must be in [1, 100000]")
            values = tuple(float(v) for v in np.linspace(float(start), float(stop), n))
        else:
            values = tuple(float(v) for v in rest.split(",") if v.strip())
    except ValueError as exc:
        raise ParameterError(f"--vary {text!r}: not numbers ({exc})") from exc
    return Axis(name, values)
