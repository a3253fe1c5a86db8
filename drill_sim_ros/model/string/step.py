"""The string's compiled step (the kernel's seam), in kernel units: what the string
presents at its ends, one step of each delay line between the end speeds, and the
junctions' law (point damper, the wall's Coulomb friction). A new element at the
junctions is a row of ``wave_f`` (built in :mod:`.lines`) and a term of
:func:`junction_speed`."""

from __future__ import annotations

import math

import numpy as np
from numba import njit

# rows of the integer and float layout arrays of the delay lines
# int64 (W_INT_ROWS, parts): steps, buffer offset, slot, and the other line's part whose
# junction lies nearest in depth to this part's (the two motions of one wall contact)
W_LEN, W_OFF, W_POS, W_PAIR = 0, 1, 2, 3
W_INT_ROWS = 4
# float64 (W_ROWS, segments), per part, of the junction below it: impedance, point damper,
# the wall's static and dynamic friction limits (0: no wall contact), the stick band, the
# surface slip (m / t*) per unit of the line's speed (r_o; L*); three rows worked out from
# those once (.lines.junction_rows) instead of at every junction every step: the
# junction's impedance Z_j + Z_j+1 + D, the stick band's slip squared (W_VS W_SLIP)^2 and
# the dynamic limit times the slip, F_d s; and rows of state: the junction's surface slip
# last step, |w| r_o (the stick band's memory, kept as the slip: each junction's is read
# twice a step, by itself and by the other line's junction beside it); in the line's
# first part only, the power the walls' friction and the point dampers' D w^2 took, summed
# over the line's junctions and the steps (x dtau: the work they took), and the power
# that entered the line at its top; in its last part only, the power that left it at its
# bottom (the bit), summed so: the energy balance the guard checks (.balance); and per
# junction, the wall's and the damper's power summed over the steps in which it was below
# zero (the energy it gave the string; 0 for any physical element: the guard names it)
W_Z, W_D, W_FS, W_FD, W_VS, W_SLIP = 0, 1, 2, 3, 4, 5
W_ZJ, W_BAND2, W_KD = 6, 7, 8
W_LAST, W_WORK, W_DAMP, W_TOP, W_BIT, W_WALL_GAVE, W_DAMP_GAVE = 9, 10, 11, 12, 13, 14, 15
# and per junction the scratch rows of one line's step (:func:`scatter`'s three passes): the
# waves arriving at it (a from above, b from below), the other line's slip beside it, and
# its new speed and the wall's power
W_AIN, W_BIN, W_OTHER, W_SPEED, W_POWER = 16, 17, 18, 19, 20
W_ROWS = 21


@njit(cache=True, inline="always")
def wall_slips(wave_f: np.ndarray, j: int, pair: int, own_speed: float,
               other_speed: float) -> tuple[float, float, bool]:
    """The surface slips (m per t*) of junction ``j``'s own motion and of the other line's
    at the same junction ``pair``, and whether the contact slides (:func:`slides`)."""
    u = abs(own_speed) * wave_f[W_SLIP, j]
    o = abs(other_speed) * wave_f[W_SLIP, pair]
    return u, o, slides(wave_f, j, u, o)


@njit(cache=True, inline="always")
def slides(wave_f: np.ndarray, j: int, u: float, o: float) -> bool:
    """Whether the wall contact of junction ``j`` slides, with the surface slips ``u`` of
    its own motion and ``o`` of the other line's: the two motions share one contact, which
    is stuck while its total slip sqrt(u^2 + o^2) is within the stick band r_o omega_s
    (Karnopp) and slides outside it."""
    return u * u + o * o > wave_f[W_BAND2, j]


# ---- compiled: the string's step (the kernel's seam) ------------------------------------
# The kernel sees the string through three calls per step: ``ends`` (what the string
# presents at the bit, in the bit law's affine form, and at the top), ``advance`` (one step
# on between the new end speeds) and ``bha_speed`` (for the sample). ``lay`` is the
# distributed string's layout for a run, from :func:`layout`. A lumped string (``wave``
# None) is RGD07's spring, compiled apart. An element at the junctions (a point damper;
# wall friction, a shock sub) is a row of ``wave_f``, a term of :func:`junction_speed` and
# its share of the steady twist in :func:`fill_steady`.
@njit(cache=True, inline="always")
def layout(wave_i: np.ndarray | None, parts_t: int, bit_inertia: float, echo: float,
           bha_part: int) -> tuple[int, int, float, float, int]:
    """The distributed string's layout for a run: the torsional parts (the axial ones
    follow), all parts, the bit's lumped inertia, the torsional bottom's echo (1: the bit;
    0: anechoic) and the part at whose top the BHA speed is read."""
    return (parts_t, 0 if wave_i is None else wave_i.shape[1], bit_inertia, echo, bha_part)


@njit(cache=True, inline="always")
def ends(wave: np.ndarray | None, wave_i: np.ndarray | None, wave_f: np.ndarray | None,
         lay: tuple, psi: float, dt: float, phi_s: float, phi: float, v: float, omega: float,
         w_app: float, omega_s: float, v_hook: float) -> tuple[float, ...]:
    """What the string presents over this step: at the bit, the affine forms of the bit law
    (bit_rock) ``v0, kick_v, f_ext, omega0, kick_w, t_ext``; at the top, the torque at the
    quill and the force at the hook above the hanging weight."""
    if wave is None:
        return _lumped_ends(psi, dt, phi_s, phi, v, omega, w_app)
    return _distributed_ends(wave, wave_i, wave_f, lay, dt, omega_s, v, omega, v_hook)


@njit(cache=True, inline="always")
def advance(wave: np.ndarray | None, wave_i: np.ndarray | None, wave_f: np.ndarray | None,
            lay: tuple, omega_top: float, v_top: float, omega_bit: float,
            v_bit: float) -> None:
    """The string one step on between the speeds over the step at its ends (the drive's
    and the hook's at the top, the bit's at the bottom); the lumped spring keeps no waves.
    (No early return: in an inlined function it cost the distributed step 7 %, measured.)"""
    if wave is not None:
        drive_line(wave, wave_i, wave_f, 0, lay[0], omega_top, omega_bit, lay[3])
        drive_line(wave, wave_i, wave_f, lay[0], lay[1], v_top, v_bit, 1.0)


@njit(cache=True, inline="always")
def bha_speed(wave: np.ndarray | None, wave_i: np.ndarray | None, wave_f: np.ndarray | None,
              lay: tuple, omega: float) -> float:
    """The BHA's angular speed now: the bit's ``omega`` in the lumped string, else the speed
    at the top of the BHA's part."""
    return omega if wave is None else speed_at_top_of(wave, wave_i, wave_f, lay[4])


@njit(cache=True, inline="always")
def _lumped_ends(psi: float, dt: float, phi_s: float, phi: float, v: float, omega: float,
                 w_app: float) -> tuple[float, ...]:
    """:func:`ends` of RGD07's lumped string (eq. 25): the spring torque PHI_S - PHI and
    psi dtau on the applied weight at the bit; at the top the same torque and the applied
    weight."""
    t_pipe = phi_s - phi                      # pipe torque C (PHI_S - PHI), scaled
    return v, psi * dt, w_app, omega, dt, t_pipe, t_pipe, w_app


@njit(cache=True, inline="always")
def _distributed_ends(wave: np.ndarray, wave_i: np.ndarray, wave_f: np.ndarray, lay: tuple,
                      dt: float, omega_s: float, v: float, omega: float,
                      v_hook: float) -> tuple[float, ...]:
    """:func:`ends` of the wave guide: the arriving waves and the end impedances, with the
    bit's lumped inertia; at the top b + Z w with the drive's and the hook's speeds."""
    parts_t, parts, bit_inertia, _, _ = lay
    b_top_t, a_bot_t = arriving(wave, wave_i, 0, parts_t)
    b_top_a, a_bot_a = arriving(wave, wave_i, parts_t, parts)
    v0, kick_v, f_ext = bottom_end(a_bot_a, wave_f[W_Z, parts - 1], 0.0, v, dt)
    omega0, kick_w, t_ext = bottom_end(a_bot_t, wave_f[W_Z, parts_t - 1], bit_inertia,
                                       omega, dt)
    return (v0, kick_v, f_ext, omega0, kick_w, t_ext, b_top_t + wave_f[W_Z, 0] * omega_s,
            b_top_a + wave_f[W_Z, parts_t] * v_hook)


# ---- compiled: one step of a line -------------------------------------------------------
@njit(cache=True, inline="always")
def drive_line(wave: np.ndarray, wave_i: np.ndarray, wave_f: np.ndarray, lo: int, hi: int,
               w_top: float, w_bottom: float, echo: float) -> None:
    """A line (parts ``lo`` .. ``hi``) one step on, driven at its ends by the speeds over the
    step: a = b + 2 Z w_top enters at the top, b = (a - 2 Z w_bottom) x ``echo`` at the
    bottom (``echo`` 1; 0: an anechoic bottom that sends nothing back). Sums the power
    that enters at the top, (a^2 - b^2) / 4 Z = w_top (b + Z w_top), in W_TOP of part
    ``lo``, and the power that leaves at the bottom, (a^2 - b^2) / 4 Z (the bit's
    w_bottom (a - Z w_bottom) when it echoes), in W_BIT of part ``hi - 1``."""
    b_top, a_bottom = arriving(wave, wave_i, lo, hi)
    z_top, z_bottom = wave_f[W_Z, lo], wave_f[W_Z, hi - 1]
    a_top = b_top + 2.0 * z_top * w_top
    b_bottom = (a_bottom - 2.0 * z_bottom * w_bottom) * echo
    wave_f[W_TOP, lo] += w_top * (b_top + z_top * w_top)
    wave_f[W_BIT, hi - 1] += (a_bottom * a_bottom - b_bottom * b_bottom) / (4.0 * z_bottom)
    scatter(wave, wave_i, wave_f, lo, hi, a_top, b_bottom)


@njit(cache=True, inline="always")
def arriving(wave: np.ndarray, wave_i: np.ndarray, lo: int, hi: int) -> tuple[float, float]:
    """The waves arriving now at the two ends of a line: (b at the top, a at the bottom)."""
    b_top = wave[wave_i[W_OFF, lo] + wave_i[W_LEN, lo] + wave_i[W_POS, lo]]
    a_bottom = wave[wave_i[W_OFF, hi - 1] + wave_i[W_POS, hi - 1]]
    return b_top, a_bottom


@njit(cache=True, inline="always")
def scatter(wave: np.ndarray, wave_i: np.ndarray, wave_f: np.ndarray, lo: int, hi: int,
            a_top: float, b_bottom: float) -> None:
    """One step of a line: ``a_top`` enters at the top, ``b_bottom`` at the bottom, every
    inner junction scatters what arrives (:func:`junction_law`), and the delay lines move on
    by one step. Within a line's step no junction reads another's result: each reads the
    waves that arrived (written at least one step ago: every slot is read before it is
    written, and a part's slots are its own), its own slip last step and the other line's
    slip (the other line's columns, final for this step), so the step runs in three passes:
    (1) gather the waves arriving at each junction and the other line's slip beside it into
    scratch rows, (2) the junctions' law over all of them at once, in vector lanes
    (:func:`junction_law`), (3) scatter the waves each junction sends into the slots and
    move the delay lines on (:func:`next_slot`), summing the walls' and the dampers' power in
    junction order (the energy balance the guard checks). Indexes the layout arrays in
    place: row views would cost reference counting every step (about a tenth of the
    distributed string's step, measured); slots and junctions as unsigned integers,
    np.uint64, so numba leaves out its test for a negative index (Python's wrap-around: a
    sixth of the walled string's step, measured, and a gather instead of a vector load).
    A junction's own GAVE rows are written only in the step its wall or damper gives energy
    (power below zero: never for physical values), so the guard can name it."""
    for j in range(lo, hi - 1):                       # (1) gather, before any slot is written
        ju, below = np.uint64(j), j + 1
        wave_f[W_AIN, ju] = wave[np.uint64(wave_i[W_OFF, j] + wave_i[W_POS, j])]
        wave_f[W_BIN, ju] = wave[np.uint64(wave_i[W_OFF, below] + wave_i[W_LEN, below]
                                           + wave_i[W_POS, below])]
        wave_f[W_OTHER, ju] = wave_f[W_LAST, np.uint64(wave_i[W_PAIR, j])]
    junction_law(wave_f, lo, hi - 1)                  # (2) the law, all junctions
    off, n, pos = wave_i[W_OFF, lo], wave_i[W_LEN, lo], wave_i[W_POS, lo]    # (3) scatter
    wave_i[W_POS, lo] = next_slot(pos, n)    # (a branch here costs NRT calls in the loop)
    b_slot = np.uint64(off + n + pos)
    wave[np.uint64(off + pos)] = a_top
    wall = damper = 0.0                      # the power the line's elements take
    for j in range(lo, hi - 1):
        ju, out_slot = np.uint64(j), b_slot  # the b entering part j at its bottom
        off, n, pos = wave_i[W_OFF, j + 1], wave_i[W_LEN, j + 1], wave_i[W_POS, j + 1]
        if n > 1:
            wave_i[W_POS, j + 1] = next_slot(pos, n)
        a_slot, b_slot = np.uint64(off + pos), np.uint64(off + n + pos)
        w, wall_power = wave_f[W_SPEED, ju], wave_f[W_POWER, ju]
        damper_power = wave_f[W_D, ju] * w * w
        wall += wall_power
        damper += damper_power
        if min(wall_power, damper_power) < 0.0:      # an element gave energy: a bug
            wave_f[W_WALL_GAVE, ju] += min(wall_power, 0.0)
            wave_f[W_DAMP_GAVE, ju] += min(damper_power, 0.0)
        wave[out_slot] = wave_f[W_AIN, ju] - 2.0 * wave_f[W_Z, ju] * w
        wave[a_slot] = wave_f[W_BIN, ju] + 2.0 * wave_f[W_Z, ju + np.uint64(1)] * w
    wave[b_slot] = b_bottom
    wave_f[W_WORK, lo] += wall
    wave_f[W_DAMP, lo] += damper


@njit(cache=True, inline="always")
def junction_law(wave_f: np.ndarray, lo: int, hi: int) -> None:
    """The junctions ``lo`` .. ``hi - 1`` of a line: each one's new speed w (W_SPEED) and
    its wall's power F w (W_POWER) from the waves arriving at it (W_AIN from above, W_BIN
    from below), continuous across it, with the torques balanced on its elements, the point
    damper D (torque D w) and the wall's friction F: (a_in - Z_j w) - (b_in + Z_j+1 w) =
    D w + F; with Z = Z_j + Z_j+1 + D (W_ZJ) and the push a_in - b_in:

    * no wall contact (W_FS 0): w = push / Z, the lossless scattering and its damper;
    * the contact (model.well) stuck (within the stick band: the slips last step of this
      junction and of the other line's beside it, W_LAST and W_OTHER, :func:`slides`), or
      sliding with the other line still: set-valued, as the bit's stick (eq. 32): held
      still while the push is within the limit (static in the band, dynamic outside it:
      Karnopp), else w Z = push - limit sign(push), power limit |w|;
    * sliding with both lines moving: the dynamic force lies along the slip velocity, so
      this line feels F = F_d u / sqrt(u^2 + o^2) = c w, c = F_d s / sqrt(u^2 + o^2) (s the
      slip per unit speed), taken with the last slip in the root: with k = F_d s (W_KD)
      and r = sqrt(u^2 + o^2), w = push r / (Z r + k), power c w^2 = k w push / (Z r + k).
      A string that rotates drags axially as a viscous c = F_d / (r_o omega), and the
      other way round.

    Keeps each walled junction's slip |w| s (W_LAST) for the band. Written without
    branches (every case worked out, one chosen: selects), from contiguous rows, so LLVM
    runs it in vector lanes: the square root and the division, the step's dearest
    operations, four at a time; IEEE square root and division are exact in every lane, and
    every case's operations are those of the scalar law, so the same numbers to the bit."""
    for j in range(lo, hi):
        ju = np.uint64(j)
        push = wave_f[W_AIN, ju] - wave_f[W_BIN, ju]
        u, o = wave_f[W_LAST, ju], wave_f[W_OTHER, ju]
        fs, z, k = wave_f[W_FS, ju], wave_f[W_ZJ, ju], wave_f[W_KD, ju]
        wall = fs != 0.0
        sliding = u * u + o * o > wave_f[W_BAND2, ju]
        both = wall & sliding & (o > 0.0)             # sliding with both lines moving
        limit = wave_f[W_FD, ju] if sliding else fs
        held = wall & (not both)                          # set-valued: stuck, or one line moves
        r = math.sqrt(u * u + o * o)
        per_z = (push - math.copysign(limit, push) if held else push) / (
            z * r + k if both else z)
        w = per_z * r if both else per_z
        w = 0.0 if held & (abs(push) <= limit) else w
        power = k * w * per_z if both else limit * abs(w)
        wave_f[W_SPEED, ju] = w
        wave_f[W_POWER, ju] = power if wall else 0.0
        wave_f[W_LAST, ju] = abs(w) * wave_f[W_SLIP, ju] if wall else u


@njit(cache=True, inline="always")
def next_slot(pos: int, steps: int) -> int:
    """The slot of a part of ``steps`` steps after ``pos``: its delay lines move on by one.
    (A part of one step, a walled string's cell, keeps slot 0, and the junctions' loop does
    not write it: storing it at every junction cost the walled step 5 %, measured.)"""
    return pos + 1 if pos + 1 < steps else 0


@njit(cache=True, inline="always")
def speed_at_top_of(wave: np.ndarray, wave_i: np.ndarray, wave_f: np.ndarray,
                    j: int) -> float:
    """Speed at the top of part ``j`` now: (a entering last step - b arriving) / 2 Z."""
    off, n, pos = wave_i[W_OFF, j], wave_i[W_LEN, j], wave_i[W_POS, j]
    last = pos - 1 if pos > 0 else n - 1
    return (wave[off + last] - wave[off + n + pos]) / (2.0 * wave_f[W_Z, j])


@njit(cache=True, inline="always")
def bottom_end(a_in: float, z: float, mass: float, v: float,
               dt: float) -> tuple[float, float, float]:
    """The bit end of a line in the bit law's affine form (see :mod:`bit_rock`):
    ``(v0, kick, f_ext)`` with a lumped ``mass`` (inertia) at the bit moving at ``v``;
    implicit in the string's impedance, exact for ``mass = 0`` (the end moves at
    (a - F) / Z)."""
    denom = mass + dt * z
    return mass * v / denom, dt / denom, a_in
