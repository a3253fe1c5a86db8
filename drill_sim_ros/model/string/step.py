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
# int64 (W_INT_ROWS, parts): steps, buffer offset, slot, the other line's part whose
# junction lies nearest in depth to this part's (the two motions of one wall contact), and
# the first part past this part's run of parts of its impedance in its line (the parts'
# slots follow each other: .readings.line_energy sums a run at once)
W_LEN, W_OFF, W_POS, W_PAIR, W_RUN = 0, 1, 2, 3, 4
W_INT_ROWS = 5
# float64 (W_ROWS, segments), per part, of the junction below it: impedance, point damper,
# the wall's static and dynamic friction limits (0: no wall contact), the stick band, the
# surface slip (m / t*) per unit of the line's speed (r_o; L*); four rows worked out from
# those once (.lines.junction_rows) instead of at every junction every step: the
# junction's impedance Z_j + Z_j+1 + D, the stick band's slip squared (W_VS W_SLIP)^2, the
# dynamic limit times the slip, F_d s, and the part's 2 Z; and rows of state: the
# junction's surface slip last step, |w| r_o (the stick band's memory, kept as the slip:
# each junction's is read twice a step, by itself and by the other line's junction beside
# it); in the line's first part only, the power the walls' friction and the point dampers'
# D w^2 took, summed over the line's junctions and the steps (x dtau: the work they took),
# and the power that entered the line at its top; in its last part only, the power that
# left it at its bottom (the bit), summed so: the energy balance the guard checks
# (.balance); and per junction, the wall's and the damper's power summed over the steps in
# which it was below zero (the energy it gave the string; 0 for any physical element: the
# guard names it)
W_Z, W_D, W_FS, W_FD, W_VS, W_SLIP = 0, 1, 2, 3, 4, 5
W_ZJ, W_BAND2, W_KD, W_2Z = 6, 7, 8, 9
W_LAST, W_WORK, W_DAMP, W_TOP, W_BIT, W_WALL_GAVE, W_DAMP_GAVE = 10, 11, 12, 13, 14, 15, 16
W_ROWS = 17


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


@njit(cache=True, inline="always")
def junction_speed(wave_f: np.ndarray, j: int, a_in: float, b_in: float, u: float,
                   o: float) -> tuple[float, float, float]:
    """The speed of the junction below part ``j``, from the waves arriving at it (``a_in``
    from above, ``b_in`` from below): continuous across it, with the torques balanced on
    its elements, the point damper D (torque D w) and the wall's friction F:
    (a_in - Z_j w) - (b_in + Z_j+1 w) = D w + F. Without wall contact (W_FS 0) that is
    w = (a_in - b_in) / (Z_j + Z_j+1 + D), the lossless scattering and its damper. The
    junction takes w (a_in - b_in - (Z_j + Z_j+1) w) = D w^2 + F w of the waves' energy
    each step. ``u``, ``o``: the wall contact's slips, this line's last step and the other
    line's (:func:`slips_last_step`). Returns (w, the wall's power F w, the damper's D w^2)."""
    if wave_f[W_FS, j] == 0.0:
        w = (a_in - b_in) / wave_f[W_ZJ, j]
        return w, 0.0, wave_f[W_D, j] * w * w
    return wall_junction(wave_f, j, a_in - b_in, u, o)


@njit(cache=True, inline="always")
def wall_junction(wave_f: np.ndarray, j: int, push: float, u: float,
                  o: float) -> tuple[float, float, float]:
    """:func:`junction_speed` with the wall's Coulomb friction (model.well), implicit in the
    new speed w, with Z = Z_j + Z_j+1 + D. The contact (:func:`slides`, from the slip
    ``u`` of this junction last step and ``o`` of the other line's beside it):

    * within the stick band, or sliding with the other line still: set-valued, as the bit's
      stick (eq. 32): held still while the unbalanced torque ``push`` = a_in - b_in is
      within the limit (static in the band, dynamic outside it: Karnopp), else
      w Z = push - limit sign(push);
    * sliding with both lines moving: the dynamic force lies along the slip velocity, so
      this line feels F = F_d u / sqrt(u^2 + o^2) = c w, c = F_d s / sqrt(u^2 + o^2) (s the
      slip per unit speed), taken with the last slip in the root: w = push / (Z + c). A
      string that rotates drags axially as a viscous c = F_d / (r_o omega), and the other
      way round. Written with one division, the step's dearest operation: with
      k = F_d s and r = sqrt(u^2 + o^2), w = push r / (Z r + k), and the power
      c w^2 = k w push / (Z r + k).

    Keeps the slip for the band; returns (w, the friction power, the damper's D w^2)."""
    sliding = slides(wave_f, j, u, o)
    z = wave_f[W_ZJ, j]
    if sliding and o > 0.0:
        k = wave_f[W_KD, j]
        r = math.sqrt(u * u + o * o)
        per_z = push / (z * r + k)
        w = per_z * r
        power = k * w * per_z
    else:
        limit = wave_f[W_FD, j] if sliding else wave_f[W_FS, j]
        w = 0.0
        if abs(push) > limit:
            w = (push - math.copysign(limit, push)) / z
        power = limit * abs(w)
    wave_f[W_LAST, j] = abs(w) * wave_f[W_SLIP, j]
    return w, power, wave_f[W_D, j] * w * w


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
    inner junction scatters what arrives (continuous speed, torques balanced with its point
    damper), and the delay lines move on by one step. Reads each slot before writing it.
    Indexes the layout arrays in place: row views would cost reference counting every step
    (about a tenth of the distributed string's step, measured). The junctions' law is
    :func:`junction_speed`; the other line's junction beside junction j is W_PAIR (the one
    nearest in depth, :func:`.lines.junction_pairs`). Each part's slots are read once, at
    the junction above it, and its slot moved on there (:func:`next_slot`): the b arriving
    at its top is read where the b entering at its bottom is written one junction later,
    and the a entering at its top is written where the a arriving at its bottom is read.
    The power the walls and the dampers take is summed over the line's junctions in two
    numbers and added to the line's W_WORK and W_DAMP once a step (the energy balance the
    guard checks); a junction's own row is written only in the step its wall or damper gives
    energy (power below zero: never for physical values), so the guard can name it.
    (The slots are worked out in the loop itself: an inlined helper that writes ``wave_i``
    made the walled string's step five times slower, measured. The slots and the pair index
    as unsigned integers, np.uint64, so numba leaves out its test for a negative index,
    Python's wrap-around: a sixth of the walled string's step, measured. Summing each
    junction's power in its own row, a load and a store of two rows at every junction, cost
    the walled string's step a few percent; testing the two powers apart (``or``), more.
    Each junction's slips, its own of the step before and the other line's (an index, then
    the slip: two loads in a row), are read in the loop's turn before, for the next
    junction: they open the law's longest chain of latencies (the slips, the root, the
    division, the power's test), which bounds the sliding string's step, as many junctions
    being in flight as the processor's window holds; read a turn ahead, the chain is
    shorter by those loads: 8.5 to 7.6 us a wave step, the deviated preset turning steadily,
    measured; the same numbers to the bit.)"""
    off, n, pos = wave_i[W_OFF, lo], wave_i[W_LEN, lo], wave_i[W_POS, lo]
    wave_i[W_POS, lo] = next_slot(pos, n)    # (a branch here costs NRT calls in the loop)
    a_slot, b_slot = np.uint64(off + pos), np.uint64(off + n + pos)
    a_in = wave[a_slot]                      # arriving at the bottom of part lo
    wave[a_slot] = a_top
    wall = damper = 0.0                      # the power the line's elements take
    u_next, o_next = slips_last_step(wave_i, wave_f, lo)
    for j in range(lo, hi - 1):
        u, o = u_next, o_next                # junction j's slips last step
        out_slot = b_slot                    # the b entering part j at its bottom
        off, n, pos = wave_i[W_OFF, j + 1], wave_i[W_LEN, j + 1], wave_i[W_POS, j + 1]
        if n > 1:
            wave_i[W_POS, j + 1] = next_slot(pos, n)
        a_slot, b_slot = np.uint64(off + pos), np.uint64(off + n + pos)
        b_in = wave[b_slot]                  # arriving at the top of part j + 1
        u_next, o_next = slips_last_step(wave_i, wave_f, j + 1)
        w, wall_power, damper_power = junction_speed(wave_f, j, a_in, b_in, u, o)
        wall += wall_power
        damper += damper_power
        if min(wall_power, damper_power) < 0.0:      # an element gave energy: a bug
            wave_f[W_WALL_GAVE, j] += min(wall_power, 0.0)
            wave_f[W_DAMP_GAVE, j] += min(damper_power, 0.0)
        wave[out_slot] = a_in - wave_f[W_2Z, j] * w
        a_next = wave[a_slot]
        wave[a_slot] = b_in + wave_f[W_2Z, j + 1] * w
        a_in = a_next
    wave[b_slot] = b_bottom
    wave_f[W_WORK, lo] += wall
    wave_f[W_DAMP, lo] += damper


@njit(cache=True, inline="always")
def slips_last_step(wave_i: np.ndarray, wave_f: np.ndarray, j: int) -> tuple[float, float]:
    """The surface slip of junction ``j`` last step and that of the other line's junction
    beside it (W_PAIR) as it stands (the torsional line steps first, so the axial one reads
    its new slips; a line's step never writes the other line's), :func:`wall_slips`. Read
    for every part: the bottom part's (no junction below) are read and not used."""
    return wave_f[W_LAST, j], wave_f[W_LAST, np.uint64(wave_i[W_PAIR, j])]


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
