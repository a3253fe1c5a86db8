"""Compiled stepping of the RGD07 delay model (eqs. 25-33), in absolute variables.

Richard, Germay & Detournay (2007), J. Sound Vib. 305, 432-456. Everything here is
dimensionless (time unit t*, length unit L*, weight unit zeta*eps*a*L*, torque unit C).

Absolute variables (so the surface inputs may change at any step):

* ``U``  bit depth (down positive), ``V = dU/dtau`` (rate of penetration);
* ``PHI`` bit angle, ``OMEGA = dPHI/dtau`` (never negative);
* ``PHI_S`` top-drive angle, turning at ``OMEGA_S``; pipe torque = ``PHI_S - PHI``
  (eq. 25 right: ``phi'' + phi = T0 - T`` with ``phi = PHI - PHI_0`` is
  ``PHI'' = (PHI_S - PHI) - T``). The top drive (:mod:`drill_sim_ros.model.top_drive`)
  either imposes ``OMEGA_S`` (kinematic, the paper's boundary condition) or is an inertia
  ``j OMEGA_S' = m - (PHI_S - PHI)`` turned by a motor torque ``m`` (speed loop or torque
  command), integrated with the bit by the same symplectic Euler step;
* ``W_APP`` the applied weight (eq. 25 left: ``U'' = psi (W_APP - W)``).

The depth of cut (eqs. 6-8, 26-28) is read from the bottom-hole profile: the height
each angle of one blade sector (2 pi / n) was last cut to, stored on ``n_nodes`` nodes.
A passing blade lowers the surface to the bit depth when the bit is deeper (max rule), so
the rock is re-cut correctly after the bit has bounced off bottom. :func:`advance` with
``exact=True`` is the reference path: it keeps the exact time history of (PHI, U) and
solves eq. (7) for the delay by interpolation, as in RGD07 Appendix C.

Integration is symplectic Euler (RGD07 eq. C.1 with the position update using the new
velocity). The wearflat contact (eq. 31) is solved implicitly in the new axial velocity,
which yields the set-valued force ``0 <= W_f <= lam`` at ``V = 0`` (eq. 31, last line)
with no chattering. Stick (eq. 32) freezes the bit; the wearflat then carries what the
cutting face does not, ``W_f = W_APP - delta_k`` bounded to ``[0, lam]`` (eq. 31 last line,
eq. 25 left), so ``W = delta + W_f`` holds in every mode. Slip happens when the pipe torque
reaches the cutting + friction torque (eqs. 14, 33), checked at every step so the
top-drive speed may vary.

Kernels never raise: they return a status code (``STATUS_*``).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from drill_sim_ros.model.top_drive import (
    TD_KINEMATIC,
    TD_SPEED,
    drive_acceleration,
    kinematic_torque,
    ramp,
    speed_loop,
    torque_command,
)

# ---- parameter vector (float64) -------------------------------------------------------
P_N = 0             # number of blades n
P_BETA = 1          # beta = mu gamma zeta (eq. 10)
P_LAM = 2           # bluntness lambda (eq. 24)
P_PSI = 3           # system number psi (eq. 24)
P_DT = 4            # time step dtau
P_OMEGA_RATE = 5    # max |d OMEGA_S / dtau| (inf = instantaneous)
P_W_RATE = 6        # max |d W_APP / dtau| (inf = instantaneous)
P_TAU_AVG = 7       # statistics accumulate for tau >= P_TAU_AVG
P_TD_MODE = 8       # top-drive mode: top_drive.TD_KINEMATIC | TD_SPEED | TD_TORQUE
P_TD_INERTIA = 9    # drive inertia ratio j = J / I
P_TD_KP = 10        # speed loop proportional gain, scaled kp_SI / (C t*)
P_TD_KI = 11        # speed loop integral gain, scaled ki_SI / C
P_TD_MAX_TORQUE = 12  # motor torque limit, scaled by C (inf: none)
N_PARAMS = 13

# ---- surface targets (float64) ----------------------------------------------------------
I_OMEGA_S = 0       # commanded top-drive speed (kinematic and speed modes)
I_W_APP = 1         # commanded applied weight
I_MOTOR_TORQUE = 2  # commanded motor torque (torque mode)
N_INPUTS = 3

# ---- state vector (float64) -------------------------------------------------------------
S_TAU = 0
S_U = 1
S_V = 2
S_PHI = 3
S_OMEGA = 4
S_PHI_S = 5
S_OMEGA_S = 6
S_W_APP = 7
S_STUCK = 8         # 1.0 while the bit sticks (eq. 32)
S_NODE = 9          # index of the profile node most recently passed
S_FRAC = 10         # bit position past that node, in node spacings [0, 1)
S_H_OLD = 11        # that node's height before the current blade re-cut it
S_STEP = 12         # step counter
S_OMEGA_REF = 13    # speed setpoint in force (the ramped I_OMEGA_S)
S_TD_INTEGRAL = 14  # speed loop integral, torque units
S_MOTOR_TORQUE = 15  # motor torque of the last step
N_STATE = 16

# ---- sample columns ---------------------------------------------------------------------
C_TAU = 0
C_U = 1             # bit depth
C_V = 2             # rate of penetration
C_PHI = 3           # bit angle
C_OMEGA = 4         # bit angular speed
C_PHI_S = 5         # top-drive angle
C_OMEGA_S = 6       # top-drive speed
C_W_APP = 7         # applied weight
C_WOB = 8           # weight on bit W
C_TOB = 9           # torque on bit T
C_DOC = 10          # depth of cut delta (negative: clearance above the rock)
C_WF = 11           # wearflat contact weight W_f
C_T_PIPE = 12       # pipe (surface) torque PHI_S - PHI
C_MODE = 13
C_MOTOR_TORQUE = 14  # top-drive motor torque over the step
C_OMEGA_REF = 15    # top-drive speed setpoint in force
N_COLS = 16

# ---- interaction modes ------------------------------------------------------------------
MODE_CUTTING = 0    # cutting with full wearflat contact
MODE_LOST_CONTACT = 1  # cutting, wearflat contact partly or fully lost (V <= 0)
MODE_STUCK = 2      # OMEGA = 0 (eq. 32)
MODE_OFF_BOTTOM = 3  # delta < 0: bit above the rock, T = W = 0
MODE_NAMES = ("cutting", "lost_contact", "stuck", "off_bottom")

# ---- statistics accumulators --------------------------------------------------------------
A_COUNT = 0         # steps accumulated (tau >= P_TAU_AVG)
A_WF = 1
A_TOB = 2
A_DOC = 3
A_WOB = 4
A_OMEGA = 5
A_T_PIPE = 6
A_V = 7
A_OMEGA_MIN = 8
A_OMEGA_MAX = 9
A_STUCK = 10        # steps stuck within the window
A_FIRST_STICK = 11  # tau of the first stick (nan if none), whole run
A_FIRST_BOUNCE = 12  # tau of the first off-bottom step (nan if none), whole run
N_ACC = 13

STATUS_OK = 0
STATUS_NONFINITE = 1
STATUS_HISTORY_FULL = 2


def new_accumulators() -> np.ndarray:
    """Zeroed statistics with the extremes and first-event times unset."""
    acc = np.zeros(N_ACC)
    acc[A_OMEGA_MIN] = np.inf
    acc[A_OMEGA_MAX] = -np.inf
    acc[A_FIRST_STICK] = np.nan
    acc[A_FIRST_BOUNCE] = np.nan
    return acc


@njit(cache=True, inline="always")
def _wearflat_contact(v: float, w_app: float, doc: float, lam: float,
                      kick: float) -> tuple[float, float]:
    """Axial update with the contact law of eq. (31), implicit in the new velocity.

    ``kick = psi * dtau``. Returns ``(v_new, w_f)`` with ``w_f = lam`` if ``v_new > 0``,
    ``0`` if ``v_new < 0`` and ``v_new = 0, 0 <= w_f <= lam`` from the balance of linear
    momentum otherwise (eq. 31, last line; eq. 25 left with W = delta + W_f, eq. 29).
    """
    v_free = v + kick * (w_app - doc)        # no wearflat force
    if v_free < 0.0:
        return v_free, 0.0                   # moving up: contact lost
    v_full = v_free - kick * lam             # full wearflat force
    if v_full > 0.0:
        return v_full, lam                   # moving down: full contact
    return 0.0, v_free / kick                # V = 0: set-valued contact force


@njit(cache=True, inline="always")
def _stuck_wearflat(w_app: float, doc: float, lam: float) -> float:
    """Wearflat force while the bit sticks (eq. 31 last line, eq. 25 left with V = 0).

    The bit is immobile, so the axial balance W = W_APP holds with W = delta_k + W_f
    (eq. 29): the wearflat carries what the cutting face does not, within its contact law
    ``0 <= W_f <= lam``.
    """
    return min(max(w_app - doc, 0.0), lam)


@njit(cache=True, inline="always")
def _bit_response(v: float, omega: float, t_pipe: float, w_app: float, doc: float,
                  stuck: bool, beta: float, lam: float, kick: float,
                  dt: float) -> tuple[float, float, float, float, float, int, bool]:
    """Bit-rock forces and the new velocities (eqs. 25, 29-33).

    Returns ``(v_new, omega_new, w_f, wob, tob, mode, stuck_new)``.
    """
    if stuck and doc >= 0.0 and t_pipe <= doc + beta * lam:
        # Stick (eq. 32): the bit is immobile and the rock reacts the pipe torque and the
        # applied weight, until the pipe torque exceeds the cutting + friction torque
        # delta_k + beta lam (eqs. 14, 33 in the form valid for any top-drive speed).
        # The wearflat is in full contact as the paper assumes and carries W_APP - delta_k
        # (eq. 31, last line), so W = delta_k + W_f (eq. 29) and <U''> = 0 give eq. 44.
        w_f = _stuck_wearflat(w_app, doc, lam)
        return 0.0, 0.0, w_f, doc + w_f, t_pipe, MODE_STUCK, True
    if doc >= 0.0:
        v_new, w_f = _wearflat_contact(v, w_app, doc, lam, kick)
        wob = doc + w_f                       # eq. (29): W = delta + W_f
        tob = doc + beta * w_f                # eq. (30): T = delta + beta W_f
        mode = MODE_CUTTING if w_f >= lam else MODE_LOST_CONTACT
    else:
        v_new = v + kick * w_app              # off bottom: T = W = 0, the bit falls
        w_f, wob, tob, mode = 0.0, 0.0, 0.0, MODE_OFF_BOTTOM
    omega_new = omega + (t_pipe - tob) * dt   # eq. (25) right, in absolute angles
    if omega_new > 0.0:
        return v_new, omega_new, w_f, wob, tob, mode, False
    if doc >= 0.0:                            # eq. (32): the bit sticks on the rock
        return 0.0, 0.0, w_f, wob, tob, mode, True
    return v_new, 0.0, w_f, wob, tob, mode, False   # never backward rotation


@njit(cache=True)
def _first_countdown(step: int, every: int) -> int:
    """Steps until the next global step that is a multiple of ``every`` (-1: never)."""
    if every <= 0:
        return -1
    return (every - step % every) % every


@njit(cache=True)
def _delayed_depth(hist_phi: np.ndarray, hist_u: np.ndarray, head: int, count: int,
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


@njit(cache=True)
def advance(st: np.ndarray, prm: np.ndarray, tgt: np.ndarray, profile: np.ndarray,
            hist: np.ndarray, meta: np.ndarray, acc: np.ndarray, out: np.ndarray,
            n_steps: int, every: int, exact: bool) -> tuple[int, int]:
    """Advance ``n_steps``; state, statistics and bookkeeping live in locals.

    Delay (eqs. 6-8, 26-28), two methods:

    - ``exact=False``, the production path: ``profile`` (shape (n_nodes,)) holds the rock
      height per node of one blade sector (2 pi / n). The bit reads the height left by the
      previous blade (eq. 6: U(t - t_n) where eq. 7 holds) by linear interpolation in angle,
      and re-cuts every node it passes to ``max(old, U_crossing)``. ``hist`` and ``meta``
      are ignored (pass :data:`NO_HISTORY`, :data:`NO_META`).
    - ``exact=True``, the reference path of RGD07 Appendix C: ``hist`` (shape (2,
      capacity)) is a ring buffer of (PHI, U) samples and ``meta`` (int64, 3) its head,
      count and cursor. Eq. (7) PHI(t) - PHI(t - t_n) = 2 pi / n is solved by interpolation
      in that history and delta = n (U(t) - U(t - t_n)) (eq. 8). Samples are stored only when
      the angle advances; those older than one sector are forgotten. ``profile`` is ignored.

    out: shape (rows, N_COLS); a row is written when the global step % every == 0.
    Returns ``(status, rows_written)``.
    """
    n, beta, lam, dt = prm[P_N], prm[P_BETA], prm[P_LAM], prm[P_DT]
    kick = prm[P_PSI] * dt
    omega_rate, w_rate, tau_avg = prm[P_OMEGA_RATE], prm[P_W_RATE], prm[P_TAU_AVG]
    tgt_omega, tgt_w, tgt_torque = tgt[I_OMEGA_S], tgt[I_W_APP], tgt[I_MOTOR_TORQUE]
    td_mode, td_j = int(prm[P_TD_MODE]), prm[P_TD_INERTIA]
    td_kp, td_ki, td_max = prm[P_TD_KP], prm[P_TD_KI], prm[P_TD_MAX_TORQUE]
    u, v, phi, omega = st[S_U], st[S_V], st[S_PHI], st[S_OMEGA]
    phi_s, omega_s, w_app = st[S_PHI_S], st[S_OMEGA_S], st[S_W_APP]
    omega_ref, integral, motor = st[S_OMEGA_REF], st[S_TD_INTEGRAL], st[S_MOTOR_TORQUE]
    stuck = st[S_STUCK] != 0.0
    step = int(st[S_STEP])
    sector = 2.0 * math.pi / n
    n_nodes = profile.shape[0]
    inv_spacing = n_nodes / sector
    node, frac, h_old = int(st[S_NODE]), st[S_FRAC], st[S_H_OLD]
    cap = hist.shape[1]
    head, count, cursor = meta[0], meta[1], meta[2]
    a_count, a_wf, a_tob, a_doc = acc[A_COUNT], acc[A_WF], acc[A_TOB], acc[A_DOC]
    a_wob, a_omega, a_tp, a_v = acc[A_WOB], acc[A_OMEGA], acc[A_T_PIPE], acc[A_V]
    a_stuck = acc[A_STUCK]
    om_min, om_max = acc[A_OMEGA_MIN], acc[A_OMEGA_MAX]
    first_stick, first_bounce = acc[A_FIRST_STICK], acc[A_FIRST_BOUNCE]
    countdown = _first_countdown(step, every)
    n_rows = 0
    status = STATUS_OK
    probe = 0.0                               # NaN would vanish in the contact/stick logic
    for _ in range(n_steps):
        tau = step * dt
        # ---- depth of cut: delta = n (U(tau) - U(tau - tau_n)), eqs. (8), (26)-(28)
        if exact:
            surface, cursor = _delayed_depth(hist[0], hist[1], head, count, cursor,
                                             phi - sector)
        else:
            nxt = node + 1 if node + 1 < n_nodes else 0
            surface = h_old + frac * (profile[nxt] - h_old)
        doc = n * (u - surface)
        t_pipe = phi_s - phi                  # pipe torque C (PHI_S - PHI), scaled
        v_new, omega_new, w_f, wob, tob, mode, stuck = _bit_response(
            v, omega, t_pipe, w_app, doc, stuck, beta, lam, kick, dt)
        # ---- top drive (RGD07 eq. 12 extended): its speed at the end of the step
        if td_mode == TD_KINEMATIC:           # the paper's imposed speed
            omega_s_next = ramp(omega_s, tgt_omega, omega_rate, dt)
            omega_ref = omega_s_next
            motor = kinematic_torque(omega_s, omega_s_next, t_pipe, td_j, dt)
        else:                                 # an inertia turned by the motor torque
            omega_ref = ramp(omega_ref, tgt_omega, omega_rate, dt)
            if td_mode == TD_SPEED:
                motor, integral = speed_loop(omega_ref, omega_s, integral, td_kp, td_ki,
                                             td_max, dt)
            else:
                motor = torque_command(tgt_torque, td_max)
            omega_s_next = omega_s + drive_acceleration(motor, t_pipe, td_j) * dt
        probe += w_f + tob + motor
        # ---- statistics
        if mode == MODE_STUCK and first_stick != first_stick:
            first_stick = tau
        if mode == MODE_OFF_BOTTOM and first_bounce != first_bounce:
            first_bounce = tau
        if tau >= tau_avg:
            a_count += 1.0
            a_wf += w_f
            a_tob += tob
            a_doc += doc
            a_wob += wob
            a_omega += omega
            a_tp += t_pipe
            a_v += v
            om_min = min(om_min, omega)
            om_max = max(om_max, omega)
            if mode == MODE_STUCK:
                a_stuck += 1.0
        # ---- sample at the start of the step
        if countdown == 0:
            if n_rows < out.shape[0]:
                r = out[n_rows]
                r[C_TAU], r[C_U], r[C_V], r[C_PHI], r[C_OMEGA] = tau, u, v, phi, omega
                r[C_PHI_S], r[C_OMEGA_S], r[C_W_APP] = phi_s, omega_s, w_app
                r[C_WOB], r[C_TOB], r[C_DOC], r[C_WF] = wob, tob, doc, w_f
                r[C_T_PIPE], r[C_MODE] = t_pipe, mode
                r[C_MOTOR_TORQUE], r[C_OMEGA_REF] = motor, omega_ref
                n_rows += 1
            countdown = every - 1
        else:
            countdown -= 1
        # ---- symplectic Euler (eq. C.1 with the updated velocities)
        u_new = u + v_new * dt
        phi_new = phi + omega_new * dt
        if exact:
            if phi_new > phi:                 # store (PHI, U) only when the bit turns
                if count == cap:
                    if cursor == 0:
                        status = STATUS_HISTORY_FULL
                        break
                    count -= 1
                    cursor -= 1
                hist[0, head] = phi_new
                hist[1, head] = u_new
                head = head + 1 if head + 1 < cap else 0
                count += 1
            while cursor > 1:                 # forget what is older than one sector
                count -= 1
                cursor -= 1
        else:
            # nodes passed during the step are re-cut to the bit depth (max rule)
            dfrac = (phi_new - phi) * inv_spacing
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
        u, v, phi, omega = u_new, v_new, phi_new, omega_new
        # kinematic: the angle advances at the speed the step started with (as before the
        # drive had inertia, bit for bit); an inertial drive: symplectic Euler like the bit
        phi_s += (omega_s if td_mode == TD_KINEMATIC else omega_s_next) * dt
        omega_s = omega_s_next
        w_app = ramp(w_app, tgt_w, w_rate, dt)
        step += 1
    st[S_U], st[S_V], st[S_PHI], st[S_OMEGA] = u, v, phi, omega
    st[S_PHI_S], st[S_OMEGA_S], st[S_W_APP] = phi_s, omega_s, w_app
    st[S_OMEGA_REF], st[S_TD_INTEGRAL], st[S_MOTOR_TORQUE] = omega_ref, integral, motor
    st[S_STUCK] = 1.0 if stuck else 0.0
    st[S_STEP] = step
    st[S_TAU] = step * dt
    st[S_NODE], st[S_FRAC], st[S_H_OLD] = node, frac, h_old
    meta[0], meta[1], meta[2] = head, count, cursor
    acc[A_COUNT], acc[A_WF], acc[A_TOB], acc[A_DOC] = a_count, a_wf, a_tob, a_doc
    acc[A_WOB], acc[A_OMEGA], acc[A_T_PIPE], acc[A_V] = a_wob, a_omega, a_tp, a_v
    acc[A_STUCK] = a_stuck
    acc[A_OMEGA_MIN], acc[A_OMEGA_MAX] = om_min, om_max
    acc[A_FIRST_STICK], acc[A_FIRST_BOUNCE] = first_stick, first_bounce
    if status == STATUS_OK and not (math.isfinite(u) and math.isfinite(v) and math.isfinite(phi)
                                    and math.isfinite(omega) and math.isfinite(probe)):
        status = STATUS_NONFINITE
    return status, n_rows


@njit(cache=True)
def advance_and_sample(st: np.ndarray, prm: np.ndarray, tgt: np.ndarray, profile: np.ndarray,
                       hist: np.ndarray, meta: np.ndarray, acc: np.ndarray, out: np.ndarray,
                       n_steps: int, every: int, exact: bool) -> tuple[int, int]:
    """:func:`advance`, then the sample of the state it ended in, in the next row of ``out``.

    That sample is what the next step records at its start: it is read from one step taken
    on copies of the state, the rock profile (or history) and the statistics, so the
    simulation itself does not move. ``n_steps = 0`` gives the sample of the current state.
    Returns ``(status, rows_written)`` with the end sample counted; on a failed status the
    end sample is not taken.
    """
    status, rows = STATUS_OK, 0
    if n_steps > 0:
        status, rows = advance(st, prm, tgt, profile, hist, meta, acc, out, n_steps, every,
                               exact)
    if status != STATUS_OK or rows >= out.shape[0]:
        return status, rows
    one = np.int64(1)               # not the literal 1: that would compile advance twice
    advance(st.copy(), prm, tgt, profile if exact else profile.copy(),
            hist.copy() if exact else hist, meta.copy(), acc.copy(), out[rows:rows + 1], one,
            one, exact)
    return status, rows + 1


NO_HISTORY = np.zeros((2, 1))             # what the profile path takes for hist and meta
NO_META = np.zeros(3, dtype=np.int64)
