"""The bit-rock law of RGD07 and its delay: one seam at the bottom end of the string.

Richard, Germay & Detournay (2007), J. Sound Vib. 305, 432-456. Dimensionless throughout
(time unit t*, length unit L*, weight unit zeta eps a L*, torque unit C; eqs. 19-22).

The string meets the bit in one form, whatever the string is: over one step the bit's new
velocities are affine in the bit's forces,

    v_new = v0 + kick_v (f_ext - W),        omega_new = omega0 + kick_w (t_ext - T),

where the string gives ``(v0, kick_v, f_ext)`` and ``(omega0, kick_w, t_ext)``:

* the lumped string of RGD07 (eq. 25): ``v0 = V``, ``kick_v = psi dtau``, ``f_ext = W_APP``;
  ``omega0 = OMEGA``, ``kick_w = dtau``, ``t_ext`` = the spring torque ``PHI_S - PHI``;
* a distributed string (:mod:`drill_sim_ros.model.string`): the arriving wave and the
  string's impedance, with an optional lumped mass or inertia at the bit.

``f_ext`` and ``t_ext`` are what the string would apply to an immobile bit, so the stick and
the set-valued contact laws need nothing else. The delay (eqs. 6-8, 26-28) is read from the
bottom-hole profile (production) or from the exact time history (reference, Appendix C).
Functions never raise; the kernel returns status codes.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

# ---- interaction modes ------------------------------------------------------------------
MODE_CUTTING = 0    # cutting with full wearflat contact
MODE_LOST_CONTACT = 1  # cutting, wearflat contact partly or fully lost (V <= 0)
MODE_STUCK = 2      # OMEGA = 0 (eq. 32)
MODE_OFF_BOTTOM = 3  # delta < 0: bit above the rock, T = W = 0
MODE_NAMES = ("cutting", "lost_contact", "stuck", "off_bottom")


@njit(cache=True, inline="always")
def wearflat_contact(v0: float, f_ext: float, doc: float, lam: float,
                     kick: float) -> tuple[float, float]:
    """Axial update with the contact law of eq. (31), implicit in the new velocity.

    Returns ``(v_new, w_f)`` with ``w_f = lam`` if ``v_new > 0``, ``0`` if ``v_new < 0`` and
    ``v_new = 0, 0 <= w_f <= lam`` from the balance of linear momentum otherwise (eq. 31,
    last line; eq. 25 left with W = delta + W_f, eq. 29).
    """
    v_free = v0 + kick * (f_ext - doc)        # no wearflat force
    if v_free < 0.0:
        return v_free, 0.0                   # moving up: contact lost
    v_full = v_free - kick * lam             # full wearflat force
    if v_full > 0.0:
        return v_full, lam                   # moving down: full contact
    return 0.0, v_free / kick                # V = 0: set-valued contact force


@njit(cache=True, inline="always")
def stuck_wearflat(f_ext: float, doc: float, lam: float) -> float:
    """Wearflat force while the bit sticks (eq. 31 last line, eq. 25 left with V = 0).

    The bit is immobile, so the axial balance W = f_ext holds with W = delta_k + W_f
    (eq. 29): the wearflat carries what the cutting face does not, within ``[0, lam]``.
    """
    return min(max(f_ext - doc, 0.0), lam)


@njit(cache=True, inline="always")
def bit_response(v0: float, kick_v: float, f_ext: float, omega0: float, kick_w: float,
                 t_ext: float, doc: float, stuck: bool, beta: float,
                 lam: float) -> tuple[float, float, float, float, float, int, bool]:
    """Bit-rock forces and the bit's new velocities (eqs. 25, 29-33).

    Returns ``(v_new, omega_new, w_f, wob, tob, mode, stuck_new)``.
    """
    if stuck and doc >= 0.0 and t_ext <= doc + beta * lam:
        # Stick (eq. 32): the bit is immobile and the rock reacts the string torque and
        # force, until the string torque exceeds the cutting + friction torque
        # delta_k + beta lam (eqs. 14, 33 in the form valid for any top-drive speed).
        # The wearflat is in full contact as the paper assumes and carries f_ext - delta_k
        # (eq. 31, last line), so W = delta_k + W_f (eq. 29) and <U''> = 0 give eq. 44.
        w_f = stuck_wearflat(f_ext, doc, lam)
        return 0.0, 0.0, w_f, doc + w_f, t_ext, MODE_STUCK, True
    if doc >= 0.0:
        v_new, w_f = wearflat_contact(v0, f_ext, doc, lam, kick_v)
        wob = doc + w_f                       # eq. (29): W = delta + W_f
        tob = doc + beta * w_f                # eq. (30): T = delta + beta W_f
        mode = MODE_CUTTING if w_f >= lam else MODE_LOST_CONTACT
    else:
        v_new = v0 + kick_v * f_ext           # off bottom: T = W = 0, the bit falls
        w_f, wob, tob, mode = 0.0, 0.0, 0.0, MODE_OFF_BOTTOM
    omega_new = omega0 + (t_ext - tob) * kick_w   # eq. (25) right, in absolute angles
    if omega_new > 0.0:
        return v_new, omega_new, w_f, wob, tob, mode, False
    if doc >= 0.0:                            # eq. (32): the bit sticks on the rock
        return 0.0, 0.0, w_f, wob, tob, mode, True
    return v_new, 0.0, w_f, wob, tob, mode, False   # never backward rotation


# ---- the delay, read from the bottom-hole profile (production path) ----------------------
@njit(cache=True, inline="always")
def profile_surface(profile: np.ndarray, node: int, frac: float, h_old: float) -> float:
    """Rock height under the bit, left by the previous blade (eq. 6: U(t - t_n) where eq. 7
    holds), by linear interpolation in angle between the node just passed (its height before
    this blade re-cut it, ``h_old``) and the next node."""
    nxt = node + 1 if node + 1 < profile.shape[0] else 0
    return h_old + frac * (profile[nxt] - h_old)


@njit(cache=True, inline="always")
def profile_recut(profile: np.ndarray, node: int, frac: float, h_old: float, u: float,
                  u_new: float, dfrac: float) -> tuple[int, float, float, bool]:
    """Nodes passed during a step of ``dfrac`` node spacings are re-cut to the bit depth
    where the bit is deeper (max rule), so rock is re-cut correctly after a bounce.

    Returns ``(node, frac, h_old, ok)``; ``ok`` is False (and nothing is cut) when the step
    would pass a whole sector or more, or is not finite: a runaway the caller reports.
    """
    if not dfrac < profile.shape[0]:          # also catches nan and inf
        return node, frac, h_old, False
    n_nodes = profile.shape[0]
    f_start = frac
    frac += dfrac
    while frac >= 1.0:
        frac -= 1.0
        node = node + 1 if node + 1 < n_nodes else 0
        u_cross = u + (u_new - u) * (1.0 - f_start) / dfrac
        f_start -= 1.0
        h_old = profile[node]
        if u_cross > h_old:
            profile[node] = u_cross
    return node, frac, h_old, True


# ---- the delay, from the exact time history (reference path, RGD07 Appendix C) -----------
@njit(cache=True, error_model="numpy")    # as kernel._steps
def delayed_depth(hist_phi: np.ndarray, hist_u: np.ndarray, head: int, count: int,
                  cursor: int, phi_target: float) -> tuple[float, int]:
    """U at the latest time the bit angle was ``phi_target`` (eq. 7), by interpolation.

    History is a ring buffer (capacity = len(hist_phi)) of ``count`` samples ending at
    ``head - 1``, with PHI increasing. ``cursor`` (an age-ordered index) only moves
    forward because ``phi_target`` does. Returns ``(U, cursor)``.
    """
    cap = hist_phi.shape[0]
    start = head - count
    while cursor + 1 < count and hist_phi[(start + cursor + 1) % cap] <= phi_target:
        cursor += 1
    i0 = (start + cursor) % cap
    if cursor + 1 >= count:
        return hist_u[i0], cursor
    i1 = (start + cursor + 1) % cap
    w = (phi_target - hist_phi[i0]) / (hist_phi[i1] - hist_phi[i0])
    return hist_u[i0] + w * (hist_u[i1] - hist_u[i0]), cursor


@njit(cache=True, inline="always")
def history_store(hist: np.ndarray, head: int, count: int, cursor: int, phi: float,
                  phi_new: float, u_new: float) -> tuple[int, int, int, bool]:
    """Store (PHI, U) when the bit turned, forget what is older than one sector.

    Returns ``(head, count, cursor, ok)``; ``ok`` is False when the history is full.
    """
    cap = hist.shape[1]
    if phi_new > phi:
        if count == cap:
            if cursor == 0:
                return head, count, cursor, False
            count -= 1
            cursor -= 1
        hist[0, head] = phi_new
        hist[1, head] = u_new
        head = head + 1 if head + 1 < cap else 0
        count += 1
    while cursor > 1:
        count -= 1
        cursor -= 1
    return head, count, cursor, True


def sector(n_blades: float) -> float:
    """The angle between blades, 2 pi / n (eq. 7)."""
    return 2.0 * math.pi / n_blades
