"""Building the delay lines in kernel units: how a string is cut into parts (lossless
sections, point dampers, or a walled string's cells of one wave step), each part's
impedance, damper and wall friction at the junction below it, the layout arrays the
compiled step (:mod:`.step`) reads, and the steady state they start from."""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

import numpy as np

from drill_sim_ros.model.string.spec import (
    STRING_DISTRIBUTED,
    STRING_LUMPED,
    Section,
    StringSpec,
    axial_compliance_m_per_n,
    line_properties,
)
from drill_sim_ros.model.string.step import (
    W_2Z,
    W_BAND2,
    W_D,
    W_FD,
    W_FS,
    W_INT_ROWS,
    W_KD,
    W_LAST,
    W_LEN,
    W_OFF,
    W_PAIR,
    W_ROWS,
    W_RUN,
    W_SLIP,
    W_VS,
    W_Z,
    W_ZJ,
    wall_slips,
)


# ---- the delay lines in kernel units --------------------------------------------------------
@dataclass(frozen=True)
class WaveLine:
    """One kind of wave (torsional or axial) along the string, in kernel units: per part
    (top to bottom) its travel time in tau, impedance, the point damper below it, its length
    in m, and the wall friction at the junction below it: the static and dynamic limits of
    its torque (force), the stick band and the surface slip per unit speed (the rows of
    ``wave_f``; empty: no wall contact). ``cells``: every part is one cell of the wave
    guide's step (a walled string, :func:`wall_cells`), one step of the delay lines at any
    step the simulator runs (:func:`line_steps`)."""

    travel_tau: tuple[float, ...]
    impedance: tuple[float, ...]
    damper_below: tuple[float, ...]
    length_m: tuple[float, ...] = ()
    static_below: tuple[float, ...] = ()
    dynamic_below: tuple[float, ...] = ()
    stick_speed: tuple[float, ...] = ()
    slip_per_speed: tuple[float, ...] = ()
    cells: bool = False


def section_parts(lossy: bool, damping_points: int) -> tuple[tuple[float, ...], int]:
    """How a section of a string without wall friction is cut into delay-line parts:
    lossless, one part; damped, ``damping_points`` point dampers, each at the middle of an
    equal share of the section carrying that share's damping, and the lines run from
    element to element, so the parts are a half share, ``damping_points - 1`` whole ones and
    a half (a junction with no element between two equal lines would only pass the waves
    on, and cost a step's work). Returns the parts' lengths in shares, and the shares in
    the section. (A walled string is cut into cells instead, :func:`wall_cells`.)"""
    if not lossy:
        return (1.0,), 1
    return (0.5, *([1.0] * (damping_points - 1)), 0.5), damping_points


def walled(spec: StringSpec) -> bool:
    """Whether ``spec`` lies in a well whose wall holds a friction: its lines are then cut
    into cells of one wave step (:func:`wall_cells`)."""
    return spec.well is not None and spec.well.has_friction


def wall_cells(spec: StringSpec, axial: bool, wave_step_s: float) -> list[int]:
    """The cells of each section of a walled string for one kind of wave: the sections'
    ends rounded to whole wave steps on the cumulative travel time (each within half a
    step, as every section end), and each section cut into as many equal cells as it then
    spans steps, so every cell is one step of the delay lines (line_steps gives 1 each:
    the cells' ends lie within half a step of the grid). At least one cell a section."""
    travel = np.cumsum([s.length_m / line_properties(s, axial).speed_m_s
                        for s in spec.sections])
    edges = np.rint(travel / wave_step_s).astype(np.int64)
    return [max(1, int(n)) for n in np.diff(np.concatenate(([0], edges)))]


def _cell_normals(spec: StringSpec, s: Section, top_m: float, cells: int) -> list[float]:
    """The wall's normal force on each of the ``cells`` equal cells of ``s`` (its top at
    measured depth ``top_m``), N: the one place the string asks the well for it
    (:meth:`Well.string_normal_force_n`: the buoyed weight and tension x curvature, the
    tension static, the string rotating off bottom), one call for all the cells."""
    share = s.length_m / cells
    tops_m = top_m + share * np.arange(cells)
    return [float(n) for n in spec.well.string_normal_force_n(spec.sections, tops_m,
                                                              tops_m + share)]


def to_junctions(per_cell: list[float]) -> list[float]:
    """Per-cell quantities (a cell's damping, its friction limit) moved onto the junctions
    between the cells: each junction takes half of the cell above and half of the cell
    below it, the first and last junctions also the outer half of the end cells, so the sum
    is kept; the last entry (the line's bottom, no junction) is 0."""
    if len(per_cell) < 2:
        return [0.0] * len(per_cell)
    out = [0.5 * (a + b) for a, b in itertools.pairwise(per_cell)]
    out[0] += 0.5 * per_cell[0]
    out[-1] += 0.5 * per_cell[-1]
    return [*out, 0.0]


def _walled_line(spec: StringSpec, axial: bool, time_s: float, z_unit: float,
                 force_unit: float, speed_unit: float, wave_step_s: float) -> WaveLine:
    """:func:`wave_line` of a walled string: every cell of one wave step
    (:func:`wall_cells`) carries its viscous damping and the wall's Coulomb friction (static
    and dynamic limits of the torque r_o mu N, axially of the force mu N, N the cell's
    normal force), moved onto the junctions between the cells (:func:`to_junctions`); the
    stick band (rad/s; axially r_o omega_s m/s) and the surface slip per unit speed (r_o;
    1) of the cell above each junction."""
    mu = spec.well.side_friction
    travel, z, length, damp, fs, fd, band, slip = [], [], [], [], [], [], [], []
    top_m = 0.0
    for s, cells in zip(spec.sections, wall_cells(spec, axial, wave_step_s), strict=True):
        props = line_properties(s, axial)
        share, arm = s.length_m / cells, 1.0 if axial else s.outer_radius_m
        normal = _cell_normals(spec, s, top_m, cells)
        travel += [share / props.speed_m_s / time_s] * cells
        z += [props.impedance / z_unit] * cells
        length += [share] * cells
        damp += [props.damping_per_s * props.inertia_per_m * share / z_unit] * cells
        fs += [arm * mu.static * n / force_unit for n in normal]
        fd += [arm * mu.dynamic * n / force_unit for n in normal]
        band += [mu.stick_speed_rad_s * (s.outer_radius_m if axial else 1.0) / speed_unit
                 ] * cells
        slip += [(1.0 if axial else s.outer_radius_m) * speed_unit * time_s] * cells
        top_m += s.length_m
    return WaveLine(tuple(travel), tuple(z), tuple(to_junctions(damp)), tuple(length),
                    tuple(to_junctions(fs)), tuple(to_junctions(fd)), tuple(band),
                    tuple(slip), cells=True)


def wave_line(spec: StringSpec, axial: bool, time_s: float, z_unit: float,
              force_unit: float, length_unit: float, wave_step_s: float = 0.0) -> WaveLine:
    """Parts of ``spec`` for one kind of wave. ``z_unit`` converts an SI impedance (and a
    damper, N m s/rad or N s/m) to kernel units, ``force_unit`` a torque (force),
    ``length_unit`` a length (the axial speed's unit L* / t*). A walled string
    (:func:`walled`) is cut into cells of ``wave_step_s`` (the wave guide's step, s;
    :func:`_walled_line`); any other into lossless sections and, where damped,
    ``damping_points`` point dampers per section (:func:`section_parts`)."""
    speed_unit = (length_unit if axial else 1.0) / time_s
    if walled(spec):
        return _walled_line(spec, axial, time_s, z_unit, force_unit, speed_unit,
                            wave_step_s)
    travel, z, damper, length = [], [], [], []
    for s in spec.sections:
        props = line_properties(s, axial)
        t_tau = s.length_m / props.speed_m_s / time_s
        shares, points = section_parts(props.damping_per_s > 0.0, spec.damping_points)
        d_share = props.damping_per_s * props.inertia_per_m * s.length_m / points / z_unit
        travel += [share * t_tau / points for share in shares]
        z += [props.impedance / z_unit] * len(shares)
        damper += [d_share] * (len(shares) - 1) + [0.0]
        length += [share * s.length_m / points for share in shares]
    return WaveLine(tuple(travel), tuple(z), tuple(damper), tuple(length))


def section_part_counts(spec: StringSpec, axial: bool, wave_step_s: float) -> list[int]:
    """The delay-line parts of each section for one kind of wave (:func:`wave_line`)."""
    if walled(spec):
        return wall_cells(spec, axial, wave_step_s)
    return [len(section_parts(line_properties(s, axial).damping_per_s > 0.0,
                              spec.damping_points)[0]) for s in spec.sections]


def line_steps(line: WaveLine, dtau: float) -> np.ndarray:
    """Whole steps per part: boundaries rounded on the cumulative travel time, so each one
    lies within half a step of its true place. ParameterError-free: the caller checks >= 1.
    A line of cells (``line.cells``) keeps at least one step a cell: cut for the preset's
    wave step, a session's slightly shorter step (whole steps a control period) could round
    a cell that falls a little short of a step to none; its edge then moves one step down
    (and the next ones as far as needed), which leaves every other line as rounded."""
    edges = np.rint(np.cumsum(line.travel_tau) / dtau).astype(np.int64)
    if line.cells:
        edges = np.maximum(edges, np.arange(1, edges.size + 1))
        edges = np.maximum.accumulate(edges - np.arange(edges.size)) + np.arange(edges.size)
    return np.diff(np.concatenate(([0], edges)))


def _rows(line: WaveLine, name: str) -> np.ndarray:
    """A per-part tuple of ``line`` as an array (zeros where the line has none)."""
    values = getattr(line, name)
    return np.asarray(values, dtype=float) if values else np.zeros(len(line.travel_tau))


def junction_pairs(lines: tuple[WaveLine, ...]) -> np.ndarray:
    """For every part of the two ``lines`` (torsional, axial), the column of the other
    line's part whose junction (its bottom) lies nearest in depth to this part's: the
    torsional and the axial motion of one wall contact, which slides on their joint slip
    (:func:`wall_slips`). Lines cut alike pair part j with part j of the other line."""
    bottoms = [np.cumsum(line.length_m) for line in lines]
    offsets = (len(lines[0].travel_tau), 0)
    pairs = []
    for own, other, offset in ((bottoms[0], bottoms[1], offsets[0]),
                               (bottoms[1], bottoms[0], offsets[1])):
        inner = other[:-1] if other.size > 1 else other
        right = np.clip(np.searchsorted(inner, own), 0, inner.size - 1)
        left = np.clip(right - 1, 0, inner.size - 1)
        nearest = np.where(np.abs(inner[left] - own) <= np.abs(inner[right] - own), left,
                           right)
        pairs.append(nearest + offset)
    return np.concatenate(pairs)


def build_lines(lines: tuple[WaveLine, ...], dtau: float
                ) -> tuple[np.ndarray, np.ndarray, np.ndarray, tuple[int, ...]]:
    """The layout of the delay lines of ``lines`` (torsional first): ``(wave_i, wave_f,
    wave, counts)`` with ``wave_i`` int64 (W_INT_ROWS, parts) rows W_LEN, W_OFF, W_POS,
    W_PAIR (:func:`junction_pairs`), W_RUN (:func:`impedance_runs`), ``wave_f`` float64
    (W_ROWS, parts) rows W_Z .. W_BIT (:func:`junction_rows`; the state rows zero), an empty
    buffer, and the parts per line."""
    lens = np.concatenate([line_steps(line, dtau) for line in lines])
    wave_i = np.zeros((W_INT_ROWS, lens.size), dtype=np.int64)
    wave_i[W_LEN] = lens
    wave_i[W_OFF] = np.concatenate(([0], np.cumsum(2 * lens)[:-1]))
    wave_i[W_PAIR] = junction_pairs(lines)
    wave_f = np.zeros((W_ROWS, lens.size))
    for row, name in ((W_Z, "impedance"), (W_D, "damper_below"), (W_FS, "static_below"),
                      (W_FD, "dynamic_below"), (W_VS, "stick_speed"),
                      (W_SLIP, "slip_per_speed")):
        wave_f[row] = np.concatenate([_rows(line, name) for line in lines])
    counts = tuple(len(x.travel_tau) for x in lines)
    wave_i[W_RUN] = impedance_runs(wave_f[W_Z], counts)
    junction_rows(wave_f, counts)
    return wave_i, wave_f, np.zeros(int(2 * lens.sum())), counts


def impedance_runs(impedance: np.ndarray, counts: tuple[int, ...]) -> np.ndarray:
    """For every part of the lines of ``counts`` parts, the first part past its run of
    parts of equal ``impedance`` in its line (the line's end after its last run)."""
    out = np.empty(impedance.size, dtype=np.int64)
    lo = 0
    for n in counts:
        hi = lo + n
        starts = lo + 1 + np.flatnonzero(impedance[lo + 1:hi] != impedance[lo:hi - 1])
        ends = np.append(starts, hi)
        out[lo:hi] = ends[np.searchsorted(starts, np.arange(lo, hi), side="right")]
        lo = hi
    return out


def junction_rows(wave_f: np.ndarray, counts: tuple[int, ...]) -> None:
    """The rows of ``wave_f`` the step reads instead of working them out at every junction
    every step, from the others, in place: W_ZJ = Z_j + Z_j+1 + D_j (within each line of
    ``counts`` parts; a line's bottom part has no junction below, 0), W_BAND2 =
    (W_VS W_SLIP)^2, W_KD = W_FD W_SLIP and W_2Z = 2 W_Z, with the step's operations in its
    order, so the same numbers to the bit."""
    wave_f[W_ZJ] = 0.0
    lo = 0
    for n in counts:
        hi = lo + n
        wave_f[W_ZJ, lo:hi - 1] = (wave_f[W_Z, lo:hi - 1] + wave_f[W_Z, lo + 1:hi]
                                   + wave_f[W_D, lo:hi - 1])
        lo = hi
    band = wave_f[W_VS] * wave_f[W_SLIP]
    wave_f[W_BAND2] = band * band
    wave_f[W_KD] = wave_f[W_FD] * wave_f[W_SLIP]
    wave_f[W_2Z] = 2.0 * wave_f[W_Z]


def steady_friction(wave_f: np.ndarray, j: int, pair: int, speed: float,
                    other_speed: float) -> float:
    """The wall's friction at junction ``j`` moving steadily at ``speed`` (the other line
    at ``other_speed``): none at rest; within the stick band the static limit; sliding, the
    dynamic force's share along this line, u / sqrt(u^2 + o^2) (:func:`wall_slips`)."""
    if speed == 0.0 or wave_f[W_FS, j] == 0.0:
        return 0.0
    u, o, sliding = wall_slips(wave_f, j, pair, speed, other_speed)
    if not sliding:
        return math.copysign(wave_f[W_FS, j], speed)
    return math.copysign(wave_f[W_FD, j] * u / math.sqrt(u * u + o * o), speed)


def fill_steady(wave: np.ndarray, wave_i: np.ndarray, wave_f: np.ndarray, lo: int, hi: int,
                end_force: float, speed: float, other_speed: float = 0.0) -> float:
    """Parts ``lo..hi-1`` turning (moving) steadily at ``speed``, the other line at
    ``other_speed`` (its junction W_PAIR beside each junction): each part carries
    the force at the bottom end, ``end_force``, plus the drag D x speed of every point
    damper and the wall's friction (:func:`steady_friction`) of every junction below its
    top (the elements below part j sit at its bottom), so no element sheds a wave. Every
    junction's memory is its slip at ``speed``. Returns the force at the top, what the drive (the
    hook) must hold."""
    wall = np.array([steady_friction(wave_f, j, int(wave_i[W_PAIR, j]), speed, other_speed)
                     for j in range(lo, hi)])
    drag_below = (np.cumsum(wave_f[W_D, lo:hi][::-1])[::-1] * speed
                  + np.cumsum(wall[::-1])[::-1])
    for j in range(lo, hi):
        n, off, z = wave_i[W_LEN, j], wave_i[W_OFF, j], wave_f[W_Z, j]
        force = end_force + float(drag_below[j - lo])
        wave[off:off + n] = force + z * speed
        wave[off + n:off + 2 * n] = force - z * speed
    wave_f[W_LAST, lo:hi] = abs(speed) * wave_f[W_SLIP, lo:hi]     # (the step's wall_slips)
    return end_force + speed * float(wave_f[W_D, lo:hi].sum()) + float(wall.sum())


@dataclass(frozen=True)
class KernelString:
    """A string in kernel units, what the simulator builds its arrays from.

    ``model``: STRING_LUMPED or STRING_DISTRIBUTED; ``lines``: (torsional, axial);
    ``bit_inertia``: J_bit / I; ``hook_kp``, ``hook_ki``: the WOB loop's gains (hook speed
    per unit force error, and per unit force error and tau); ``bha_part``: the torsional
    part at whose top the BHA speed is read; ``spec``: the SI description; ``pickup``,
    ``clearance``: the hook's pick-up speed off bottom and the bit's clearance then;
    ``tag_speed``: its lowering speed's cap when it tags bottom again; ``substeps``: the
    bit law's steps per wave-guide step (StringSpec.bit_substeps)."""

    model: int
    lines: tuple[WaveLine, ...] = ()
    bit_inertia: float = 0.0
    hook_kp: float = 0.0
    hook_ki: float = 0.0
    bha_part: int = 0
    spec: StringSpec | None = None
    pickup: float = 0.0
    clearance: float = 0.0
    tag_speed: float = 0.0
    substeps: int = 1


LUMPED = KernelString(STRING_LUMPED)


def kernel_string(spec: StringSpec, time_s: float, torque_nm: float, length_m: float,
                  force_n: float, wave_dtau: float = 0.0) -> KernelString:
    """``spec`` in kernel units: time t*, torque C, length L*, force zeta eps a L*
    (RGD07 eqs. 19-20). The hook loop is critically damped with time constant
    ``hook_wob_time_s`` on the string's static axial stiffness. ``wave_dtau``: the wave
    guide's step in tau (numerics.dtau x bit_substeps), which a walled string's cells span
    (:func:`wall_cells`; a string without wall friction ignores it)."""
    if not spec.distributed:
        return KernelString(STRING_LUMPED, spec=spec)
    if walled(spec) and wave_dtau <= 0.0:
        raise ValueError("a walled string is cut into cells of the wave step: give wave_dtau")
    z_torsion = torque_nm * time_s                     # N m s/rad per kernel unit
    z_axial = force_n * time_s / length_m               # N s/m per kernel unit
    step_s = wave_dtau * time_s
    torsion = wave_line(spec, False, time_s, z_torsion, torque_nm, length_m, step_s)
    axial = wave_line(spec, True, time_s, z_axial, force_n, length_m, step_s)
    stiffness = length_m / force_n / axial_compliance_m_per_n(spec)
    t_w = spec.hook_wob_time_s / time_s
    bha_part = len(torsion.travel_tau) - section_part_counts(spec, False, step_s)[-1]
    return KernelString(STRING_DISTRIBUTED, (torsion, axial),
                        spec.bit_inertia_kg_m2 / (torque_nm * time_s**2),
                        2.0 / (t_w * stiffness), 1.0 / (t_w**2 * stiffness), bha_part, spec,
                        spec.hook_pickup_m_s * time_s / length_m,
                        spec.off_bottom_clearance_m / length_m,
                        spec.hook_tag_m_s * time_s / length_m, spec.bit_substeps)
