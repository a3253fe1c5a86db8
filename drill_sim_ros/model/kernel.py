"""Compiled stepping of the RGD07 model (eqs. 25-33): a short loop over three seams.

Richard, Germay & Detournay (2007), J. Sound Vib. 305, 432-456. Everything here is
dimensionless (time unit t*, length unit L*, weight unit zeta*eps*a*L*, torque unit C).

A step reads as three calls on one state:

1. the bit-rock law (:mod:`drill_sim_ros.model.bit_rock`): the depth of cut from the delay
   (eqs. 6-8, 26-28), then the forces and the bit's new velocities (eqs. 29-33), given the
   string's bottom end in affine form, the sliding torque from the law ``P_BIT_LAW``
   (RGD07's by default) at the bit's speed at the start of the step;
2. the top drive (:mod:`drill_sim_ros.model.top_drive`): its speed at the end of the step
   against the string torque at the quill (kinematic, speed loop or torque mode);
3. the string (:mod:`drill_sim_ros.model.string`), one seam: ``string.ends`` before the
   bit law, ``string.advance`` after it. ``lumped`` is RGD07's spring C with the BHA at the
   bit (eq. 25, symplectic Euler as eq. C.1 with the updated velocities); ``distributed`` is
   a chain of wave-guide sections carrying torsional and axial waves, moved on by one step
   between the drive's and the bit's new speeds, or by one step of its own every
   ``P_SUBSTEPS`` steps between their means, the waves at its ends held in between
   (:func:`_held_means`).

The loop (:func:`_steps`) keeps the bookkeeping: the sample rows, the statistics, the dry
step, the status. The physics of a step is in scalar helpers (:func:`_respond`,
:func:`_drive`, :func:`_moved`) that take and return named tuples (compiled as plain
locals); the arrays are touched in the loop only, since an array handed down through an
inlined helper costs reference counting in the hot path (measured: up to twice the time).

Absolute variables (so the surface inputs may change at any step): ``U`` bit depth (down
positive), ``V = dU/dtau``; ``PHI`` bit angle, ``OMEGA = dPHI/dtau`` (never negative);
``PHI_S`` top-drive angle turning at ``OMEGA_S``; ``W_APP`` the applied weight. In the lumped
string the pipe torque is ``PHI_S - PHI`` (eq. 25 right, ``phi'' + phi = T0 - T`` with
``phi = PHI - PHI_0`` is ``PHI'' = (PHI_S - PHI) - T``) and ``U'' = psi (W_APP - W)`` (eq. 25
left). In the distributed string the hook holds the top axially, its speed set by a slow
PI loop on the string force at the top (the applied-WOB estimate) so that W_APP sets the
weight on bit in steady drilling.

``advance`` with ``exact=True`` is the reference path of RGD07 Appendix C for the delay.
Kernels never raise: they return a status code (``STATUS_*``); no loop in them is unbounded
whatever the state (a step that would pass a whole blade sector is a runaway). The loop is
compiled with numba's ``error_model="numpy"``: a division by zero gives inf or nan, which
the simulator's finite check reports as a fault, where the default (Python) error model
tests every divisor and would raise ZeroDivisionError. The results are the same bit for bit
for every nonzero divisor; the tests cost about 30 % of the distributed string's step
(docs/benchmarks.md, issue 32).
"""

from __future__ import annotations

import math
from collections import namedtuple

import numpy as np
from numba import njit

from drill_sim_ros.model import bit_rock as br
from drill_sim_ros.model import string as sg
from drill_sim_ros.model.bit_rock import (  # noqa: F401  (the modes, re-exported)
    MODE_CUTTING,
    MODE_LOST_CONTACT,
    MODE_NAMES,
    MODE_OFF_BOTTOM,
    MODE_STUCK,
)
from drill_sim_ros.model.lag import lag_step
from drill_sim_ros.model.top_drive import TD_KINEMATIC, drive_step, ramp

# ---- parameter vector (float64) -------------------------------------------------------
P_N = 0             # number of blades n
P_BETA = 1          # beta = mu gamma zeta (eq. 10), of the rock being drilled
P_LAM = 2           # bluntness lambda (eq. 24), of the rock being drilled
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
P_TD_LAG_ALPHA = 13  # motor torque lag per step, 1 - exp(-dtau / lag) (1: none)
P_CUT = 14          # cutting-force factor eps / eps_ref of the rock being drilled (eq. 4)
P_LAYER_U = 15      # bit depth U at which the next formation layer starts (inf: none)
P_STRING = 16       # string model: string.STRING_LUMPED | STRING_DISTRIBUTED
P_PARTS_T = 17      # distributed: parts of the torsional line (the axial ones follow)
P_BIT_INERTIA = 18  # distributed: lumped inertia at the bit / I
P_HOOK_KP = 19      # distributed: hook speed per unit force error (WOB loop, P)
P_HOOK_KI = 20      # distributed: hook speed per unit force error x tau (WOB loop, I)
P_OFF_BOTTOM = 21   # 1: the bit hangs free off bottom (T = W = 0), the hook fixed; 2: and
                    # the torsional line ends without reflection (an anechoic bottom);
                    # OFF_BOTTOM_LIFTED: the hook picks the string up off bottom and holds it
P_BHA_PART = 22     # distributed: the part at whose top the BHA speed is read
P_PICKUP = 23       # distributed: the hook's pick-up speed off bottom (L* per t*)
P_CLEARANCE = 24    # distributed: the bit's clearance above the rock it picks up to (L*)
P_TAG_SPEED = 25    # distributed: the hook's lowering speed cap, L* per t* (inf until a tag)
P_SUBSTEPS = 26     # distributed: steps of the bit law and the drive per wave-guide step
P_BIT_LAW = 27      # the bit law: bit_rock.LAW_RGD07 | LAW_WEAKENING_FRICTION | ...
P_BIT_LAW_A = 28    # its parameters (bit_rock.BitLaw): for the weakening laws the floor
P_BIT_LAW_B = 29    # ratio and the e-folding speed (omega t*)
P_TD_TORQUE_RATE = 30  # motor torque rate limit, scaled rate_SI t* / C (inf: none)
P_BIT_LAW_ALPHA = 31  # the speed the bit law reads follows the bit's per step by this share,
                      # 1 - exp(-dtau / response) (1: the bit's speed itself; BitLaw.response)
P_DOC_MAX = 32      # the depth-of-cut limit per revolution, L* (inf: none; BitLaw.doc_max)
P_BETA_LIMIT = 33   # its contact's friction mu gamma zeta (BitLaw.beta_limit)
N_PARAMS = 34
OFF_BOTTOM_LIFTED = 3.0

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
S_V_HOOK = 16       # distributed: hook speed (down positive)
S_HOOK_INTEGRAL = 17  # distributed: the WOB loop's integral term (a speed)
S_SUB_COUNT = 18    # distributed, P_SUBSTEPS > 1: steps taken since the wave guide's last
S_SUB_OMEGA_TOP = 19  # and the sums of the end speeds over them: the drive's,
S_SUB_V_TOP = 20    # the hook's,
S_SUB_OMEGA_BIT = 21  # the bit's angular
S_SUB_V_BIT = 22    # and axial
S_LAW_OMEGA = 23    # the bit speed the bit law reads (P_BIT_LAW_ALPHA: lagged, or the bit's)
N_STATE = 24

# ---- sample columns ---------------------------------------------------------------------
C_TAU = 0
C_U = 1             # bit depth
C_V = 2             # rate of penetration
C_PHI = 3           # bit angle
C_OMEGA = 4         # bit angular speed
C_PHI_S = 5         # top-drive angle
C_OMEGA_S = 6       # top-drive speed
C_W_APP = 7         # applied weight (the command, ramped)
C_WOB = 8           # weight on bit W
C_TOB = 9           # torque on bit T
C_DOC = 10          # depth of cut delta (negative: clearance above the rock)
C_WF = 11           # wearflat contact weight W_f
C_T_PIPE = 12       # string torque at the quill (lumped: PHI_S - PHI)
C_MODE = 13
C_MOTOR_TORQUE = 14  # top-drive motor torque over the step
C_OMEGA_REF = 15    # top-drive speed setpoint in force
C_F_TOP = 16        # string force at the hook above its weight (applied WOB estimate)
C_OMEGA_BHA = 17    # BHA speed (lumped: the bit's)
N_COLS = 18

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

# ---- what a step carries (named tuples: compiled as plain locals) ----------------------
Loop = namedtuple("Loop", (
    "u", "v", "phi", "omega", "phi_s", "omega_s", "w_app", "stuck", "node", "frac", "h_old",
    "step", "omega_ref", "integral", "motor", "v_hook", "hook_int", "law_omega", "head",
    "count", "cursor"))
Loop.__doc__ = """The loop-carried state of a run (the ``S_*`` slots and the history's bookkeeping
``meta``: head, count, cursor)."""
Law = namedtuple("Law", (
    "dt", "tau_avg", "beta", "lam", "n_blades", "psi", "off_bottom", "layer_u", "cut_factor",
    "sector", "tgt_w", "w_rate", "inv_spacing", "hook_kp", "hook_ki", "pickup", "clearance",
    "tag_speed", "substeps", "bit_law", "law_a", "law_b", "law_alpha", "doc_max",
    "beta_limit"))
Law.__doc__ = """A run's constants of the bit law, the rock and the hook: dtau, the statistics
window start, beta, lambda, n, psi, off bottom, the next layer's top, the cutting factor, the
blade sector 2 pi / n, the applied weight's target and ramp rate, the profile's nodes per
radian, the hook's WOB loop gains, its pick-up speed (0 on bottom), the clearance it picks
up to, its lowering speed's cap (the tag speed; inf until a tag), the steps per step of
the wave guide (:func:`_held_means`), the bit law with its two parameters
(bit_rock.sliding_torque) and the share by which the speed it reads follows the bit's, and
the depth-of-cut limit with its contact's friction (bit_rock.bit_response)."""
Drive = namedtuple("Drive", (
    "mode", "omega", "torque", "omega_rate", "inertia", "kp", "ki", "max_torque", "lag_alpha",
    "max_torque_rate"))
Drive.__doc__ = """A run's top-drive parameters and commands (top_drive.drive_step)."""
Response = namedtuple("Response", (
    "cursor", "doc", "t_top", "f_top", "v_new", "omega_new", "u_new", "phi_new", "w_f", "wob",
    "tob", "mode", "stuck", "v_hook", "hook_int"))
Response.__doc__ = """What a step computes on the bit's side before anything moves: the exact
delay's cursor, the depth of cut, the string's torque and force at the top, the bit's new
speeds, depth and angle, forces and mode (eqs. 29-33, C.1), the hook's speed and integral."""
DriveStep = namedtuple("DriveStep", ("omega_s_next", "omega_ref", "integral", "motor"))
DriveStep.__doc__ = """The drive over a step: its speed at the end, the setpoint in force, the
speed loop's integral, the motor torque (top_drive.drive_step)."""

STATUS_OK = 0
STATUS_NONFINITE = 1
STATUS_HISTORY_FULL = 2
STATUS_RUNAWAY = 3  # a step would pass a whole blade sector: the state ran away
STATUS_LAYER = 4    # the bit reached P_LAYER_U: stopped after that step for the next layer


def new_accumulators() -> np.ndarray:
    """Zeroed statistics with the extremes and first-event times unset."""
    acc = np.zeros(N_ACC)
    acc[A_OMEGA_MIN] = np.inf
    acc[A_OMEGA_MAX] = -np.inf
    acc[A_FIRST_STICK] = np.nan
    acc[A_FIRST_BOUNCE] = np.nan
    return acc


@njit(cache=True)
def _first_countdown(step: int, every: int) -> int:
    """Steps until the next global step that is a multiple of ``every`` (-1: never)."""
    if every <= 0:
        return -1
    return (every - step % every) % every


@njit(cache=True, inline="always")
def _accumulate(acc: np.ndarray, tau: float, tau_avg: float, mode: int, w_f: float,
                tob: float, doc: float, wob: float, omega: float, t_pipe: float,
                v: float) -> None:
    """One step into the statistics ``acc`` (``A_*``), in place: first stick and bounce
    times always, the window sums for tau >= tau_avg. (In place, not a tuple of locals:
    thirteen loop-carried values fewer for the register allocator.)"""
    if mode == MODE_STUCK and acc[A_FIRST_STICK] != acc[A_FIRST_STICK]:
        acc[A_FIRST_STICK] = tau
    if mode == MODE_OFF_BOTTOM and acc[A_FIRST_BOUNCE] != acc[A_FIRST_BOUNCE]:
        acc[A_FIRST_BOUNCE] = tau
    if tau < tau_avg:
        return
    acc[A_COUNT] += 1.0
    acc[A_WF] += w_f
    acc[A_TOB] += tob
    acc[A_DOC] += doc
    acc[A_WOB] += wob
    acc[A_OMEGA] += omega
    acc[A_T_PIPE] += t_pipe
    acc[A_V] += v
    acc[A_OMEGA_MIN] = min(acc[A_OMEGA_MIN], omega)
    acc[A_OMEGA_MAX] = max(acc[A_OMEGA_MAX], omega)
    if mode == MODE_STUCK:
        acc[A_STUCK] += 1.0


@njit(cache=True, inline="always")
def _hook(law: Law, w_app: float, f_top: float, integral: float,
          clearance_left: float) -> tuple[float, float]:
    """The hook's speed over the step (down positive): a PI loop (gains ``hook_kp``,
    ``hook_ki``) on the applied-WOB error, so the string force at the top (the applied WOB
    the rig infers from the hook load) follows W_APP, lowering at most at the tag speed
    (its integral then held); zero when hung off bottom. Picking up off bottom
    (``pickup`` > 0), it rises at ``pickup`` until the bit's clearance above the rock lacks
    nothing (``clearance_left`` <= 0), then holds; the loop's integral is kept for the tag.
    Returns ``(speed, integral)``."""
    if law.off_bottom:
        return 0.0, integral
    if law.pickup > 0.0:
        return (-law.pickup if clearance_left > 0.0 else 0.0), integral
    err = w_app - f_top
    held = integral
    integral += law.hook_ki * err * law.dt
    speed = law.hook_kp * err + integral
    if speed > law.tag_speed:            # slacking off onto the rock: the driller's speed
        return law.tag_speed, held
    return speed, integral


@njit(cache=True, inline="always")
def _cutting(cut_factor: float, off_bottom: bool, doc: float) -> float:
    """The depth that sets the cutting forces (eq. 4): delta x eps / eps_ref of the rock
    being drilled; negative (no contact) when the bit hangs off bottom."""
    if off_bottom:
        return -1.0
    return doc if cut_factor == 1.0 else cut_factor * doc


@njit(cache=True, inline="always")
def _write_row(out: np.ndarray, n_rows: int, x: Loop, r: Response, d: DriveStep,
               dt: float, omega_bha: float) -> int:
    """Sample row ``n_rows`` of ``out`` (columns C_*): the state ``x`` at the start of the
    step and what the step ``r``, ``d`` computed from it; returns the rows written. Called only
    when a row is due: an array handed to an inlined function costs a reference count (two
    calls, around which every register spills), so ``out`` stays out of the per-step path."""
    row = out[n_rows]
    row[C_TAU], row[C_U], row[C_V], row[C_PHI], row[C_OMEGA] = \
        x.step * dt, x.u, x.v, x.phi, x.omega
    row[C_PHI_S], row[C_OMEGA_S], row[C_W_APP] = x.phi_s, x.omega_s, x.w_app
    row[C_WOB], row[C_TOB], row[C_DOC], row[C_WF] = r.wob, r.tob, r.doc, r.w_f
    row[C_T_PIPE], row[C_MODE] = r.t_top, r.mode
    row[C_MOTOR_TORQUE], row[C_OMEGA_REF] = d.motor, d.omega_ref
    row[C_F_TOP], row[C_OMEGA_BHA] = r.f_top, omega_bha
    return n_rows + 1


@njit(cache=True)
def advance(st: np.ndarray, prm: np.ndarray, tgt: np.ndarray, profile: np.ndarray,
            hist: np.ndarray, meta: np.ndarray, acc: np.ndarray, out: np.ndarray,
            wave: np.ndarray, wave_i: np.ndarray, wave_f: np.ndarray,
            n_steps: int, every: int, exact: bool) -> tuple[int, int]:
    """Up to ``n_steps`` of bit law, drive and string (module doc). Returns (status, rows)."""
    return _steps(st, prm, tgt, profile, hist, meta, acc, out, wave, wave_i, wave_f, n_steps,
                  every, exact, np.bool_(False))     # not the literal: see advance_and_sample


@njit(cache=True, error_model="numpy")
def _steps(st: np.ndarray, prm: np.ndarray, tgt: np.ndarray, profile: np.ndarray,
           hist: np.ndarray, meta: np.ndarray, acc: np.ndarray, out: np.ndarray,
           wave: np.ndarray, wave_i: np.ndarray, wave_f: np.ndarray,
           n_steps: int, every: int, exact: bool, dry: bool) -> tuple[int, int]:
    """:func:`advance` (module doc); ``dry``: the first step's row only, nothing else written."""
    x, law, drive, lay = _unpack(st, meta), *_run_params(prm, tgt, profile, wave_i)
    countdown, n_rows, status, probe = _first_countdown(x.step, every), 0, STATUS_OK, 0.0
    for _ in range(n_steps):      # the delay: U(tau - tau_n), eqs. 6-7, 26-28
        surface, cursor = br.delayed_depth(hist[0], hist[1], x.head, x.count, x.cursor,
            x.phi - law.sector) if exact else (br.profile_surface(profile, x.node, x.frac,
                                                                   x.h_old), x.cursor)
        r = _respond(x, law, surface, cursor, sg.ends(
            wave, wave_i, wave_f, lay, law.psi, law.dt, x.phi_s, x.phi, x.v, x.omega, x.w_app,
            x.omega_s, x.v_hook), wave is None)
        d = _drive(x, drive, law.dt, st[S_MOTOR_TORQUE], r.t_top)  # the lag's last torque
        if countdown == 0 and n_rows < out.shape[0]:      # the sample at the step's start
            n_rows = _write_row(out, n_rows, x, r, d, law.dt,
                                sg.bha_speed(wave, wave_i, wave_f, lay, x.omega))
        countdown = every - 1 if countdown == 0 else countdown - 1
        if dry:                       # (nothing written before this line but the row)
            return STATUS_OK, n_rows
        st[S_MOTOR_TORQUE] = d.motor      # (read back: no register held through the bit law)
        probe += r.w_f + r.tob + d.motor
        _accumulate(acc, x.step * law.dt, law.tau_avg, r.mode, r.w_f, r.tob, r.doc, r.wob,
                    x.omega, r.t_top, x.v)
        ends_now = (d.omega_s_next, r.v_hook, r.omega_new, r.v_new)
        due = True
        if law.substeps > 1:          # the wave guide once every substeps (_held_means)
            sums = (st[S_SUB_OMEGA_TOP], st[S_SUB_V_TOP], st[S_SUB_OMEGA_BIT], st[S_SUB_V_BIT])
            due, sub_count, sums, ends_now = _held_means(st[S_SUB_COUNT], sums, ends_now,
                                                         law.substeps)
            st[S_SUB_COUNT] = sub_count
            st[S_SUB_OMEGA_TOP], st[S_SUB_V_TOP], st[S_SUB_OMEGA_BIT], st[S_SUB_V_BIT] = sums
        if due:
            sg.advance(wave, wave_i, wave_f, lay, ends_now[0], ends_now[1], ends_now[2],
                       ends_now[3])
        head, count, node, frac, h_old = x.head, x.count, x.node, x.frac, x.h_old
        if exact:                     # the rock: the history stored, or re-cut under a blade
            head, count, cursor, ok = br.history_store(hist, head, count, r.cursor, x.phi,
                                                       r.phi_new, r.u_new)
        else:
            node, frac, h_old, ok = br.profile_recut(profile, node, frac, h_old, x.u, r.u_new,
                                                     (r.phi_new - x.phi) * law.inv_spacing)
        x = _moved(x, r, d, law, drive.mode == TD_KINEMATIC and wave is None, node, frac,
                   h_old, head, count, cursor)
        status = _stopped(ok, exact, x.u, law.layer_u)
        if status != STATUS_OK:
            break
    _pack(st, meta, x, law.dt)
    return _finish(status, (x.u, x.v, x.phi, x.omega, x.omega_s, probe)), n_rows


@njit(cache=True, inline="always")
def _respond(x: Loop, law: Law, surface: float, cursor: int, ends: tuple,
             lumped: bool) -> Response:
    """The bit's side of a step from ``x``, given the rock surface under the bit and what
    the string presents at its ends (string.ends): the depth of cut (eq. 8), the bit law
    (eqs. 29-33) and the bit's new depth and angle (symplectic Euler, eq. C.1), and the
    hook's WOB loop on the force at the top."""
    doc = law.n_blades * (x.u - surface)        # delta = n (U - U(tau - tau_n)), eq. 8
    v0, kick_v, f_ext, omega0, kick_w, t_ext, t_top, f_top = ends
    limited = doc >= law.doc_max                # the limiter on the rock (bit_rock doc)
    cut = _cutting(law.cut_factor, law.off_bottom, law.doc_max if limited else doc)
    v_new, omega_new, w_f, wob, tob, mode, stuck = br.bit_response(
        v0, kick_v, f_ext, omega0, kick_w, t_ext, cut, x.stuck, law.beta, law.lam,
        law.bit_law, x.law_omega, law.law_a, law.law_b, limited and not law.off_bottom,
        law.beta_limit)
    v_hook, hook_int = x.v_hook, x.hook_int
    if not lumped:                # the hook's WOB loop
        v_hook, hook_int = _hook(law, x.w_app, f_top, hook_int,
                                 law.clearance + doc / law.n_blades)
    return Response(cursor, doc, t_top, f_top, v_new, omega_new, x.u + v_new * law.dt,
                    x.phi + omega_new * law.dt, w_f, wob, tob, mode, stuck, v_hook, hook_int)


@njit(cache=True, inline="always")
def _held_means(count: float, sums: tuple, ends_now: tuple, substeps: int
                ) -> tuple[bool, float, tuple, tuple]:
    """The wave guide steps once every ``substeps`` steps of the bit law and the drive
    (string.StringSpec.bit_substeps), between the means of the end speeds over them (the
    drive's, the hook's, the bit's angular and axial); in between, the waves arriving at
    the ends are held, and the ends meet them through the line's impedance at every step
    (string.ends). The count and the sums live in the state (S_SUB_*), so a wave step may
    straddle two calls. Passive: with the mean end speed w the line takes in b w + Z w^2,
    the end gave b w + Z mean(w^2), Z var(w) more, and that is lost.
    Returns (whether the wave guide steps now, the count and the sums after this step, the
    speeds to step it with)."""
    sums = (sums[0] + ends_now[0], sums[1] + ends_now[1], sums[2] + ends_now[2],
            sums[3] + ends_now[3])
    count += 1.0
    if count < substeps:
        return False, count, sums, ends_now
    return True, 0.0, (0.0, 0.0, 0.0, 0.0), (sums[0] / substeps, sums[1] / substeps,
                                             sums[2] / substeps, sums[3] / substeps)


@njit(cache=True, inline="always")
def _drive(x: Loop, drive: Drive, dt: float, last_motor: float, t_top: float) -> DriveStep:
    """The top drive over the step against the string torque at the quill ``t_top``, its
    motor torque lagging from ``last_motor`` (top_drive.drive_step)."""
    return DriveStep(*drive_step(drive.mode, x.omega_s, x.omega_ref, x.integral, last_motor,
                                 t_top, drive.omega, drive.torque, drive.omega_rate,
                                 drive.inertia, drive.kp, drive.ki, drive.max_torque,
                                 drive.lag_alpha, drive.max_torque_rate, dt))


@njit(cache=True, inline="always")
def _moved(x: Loop, r: Response, d: DriveStep, law: Law, lumped_kinematic: bool, node: int,
           frac: float, h_old: float, head: int, count: int, cursor: int) -> Loop:
    """The state after step ``r``, ``d`` over the rock's new bookkeeping: the bit moved
    (eq. C.1), the drive's angle on (RGD07's kinematic drive on the lumped string turns at
    the old speed), the applied weight ramped."""
    phi_s = x.phi_s + (x.omega_s if lumped_kinematic else d.omega_s_next) * law.dt
    law_omega = lag_step(x.law_omega, r.omega_new, law.law_alpha)
    return Loop(r.u_new, r.v_new, r.phi_new, r.omega_new, phi_s, d.omega_s_next,
                ramp(x.w_app, law.tgt_w, law.w_rate, law.dt), r.stuck, node, frac, h_old,
                x.step + 1, d.omega_ref, d.integral, d.motor, r.v_hook, r.hook_int,
                law_omega, head, count, cursor)


@njit(cache=True, inline="always")
def _string_layout(prm: np.ndarray, wave_i: np.ndarray | None) -> tuple:
    """The distributed string's layout for a run (string.layout) from the parameters."""
    return sg.layout(wave_i, int(prm[P_PARTS_T]), prm[P_BIT_INERTIA],
                     0.0 if prm[P_OFF_BOTTOM] == 2.0 else 1.0, int(prm[P_BHA_PART]))


@njit(cache=True, inline="always")
def _stopped(ok: bool, exact: bool, u: float, layer_u: float) -> int:
    """Whether a run stops after this step, and why: the next layer's top reached, a
    runaway or a full history (STATUS_OK: it goes on)."""
    if not ok:
        return STATUS_HISTORY_FULL if exact else STATUS_RUNAWAY
    return STATUS_LAYER if u >= layer_u else STATUS_OK


@njit(cache=True, inline="always")
def _run_params(prm: np.ndarray, tgt: np.ndarray, profile: np.ndarray,
                wave_i: np.ndarray | None) -> tuple[Law, Drive, tuple]:
    """A run's constants, read once: the bit law's and the hook's, the drive's, the
    string's layout."""
    return _law_params(prm, tgt, profile), _drive_params(prm, tgt), _string_layout(prm, wave_i)


@njit(cache=True, inline="always")
def _law_params(prm: np.ndarray, tgt: np.ndarray, profile: np.ndarray) -> Law:
    """The run's constants of the bit law, the rock and the hook, read once (:class:`Law`)."""
    sector = 2.0 * math.pi / prm[P_N]
    lifted = prm[P_OFF_BOTTOM] == OFF_BOTTOM_LIFTED
    return Law(prm[P_DT], prm[P_TAU_AVG], prm[P_BETA], prm[P_LAM], prm[P_N], prm[P_PSI],
               prm[P_OFF_BOTTOM] != 0.0 and not lifted, prm[P_LAYER_U], prm[P_CUT], sector,
               tgt[I_W_APP], prm[P_W_RATE], profile.shape[0] / sector, prm[P_HOOK_KP],
               prm[P_HOOK_KI], prm[P_PICKUP] if lifted else 0.0, prm[P_CLEARANCE],
               prm[P_TAG_SPEED], max(1, int(prm[P_SUBSTEPS])), int(prm[P_BIT_LAW]),
               prm[P_BIT_LAW_A], prm[P_BIT_LAW_B], prm[P_BIT_LAW_ALPHA], prm[P_DOC_MAX],
               prm[P_BETA_LIMIT])


@njit(cache=True, inline="always")
def _finish(status: int, values: tuple) -> int:
    """The status: a clean stop whose state is not finite becomes STATUS_NONFINITE."""
    if status in (STATUS_OK, STATUS_LAYER):
        for x in values:
            if not math.isfinite(x):
                return STATUS_NONFINITE
    return status


@njit(cache=True, inline="always")
def _drive_params(prm: np.ndarray, tgt: np.ndarray) -> Drive:
    """The drive's parameters and commands for a run, read once (top_drive.drive_step)."""
    return Drive(int(prm[P_TD_MODE]), tgt[I_OMEGA_S], tgt[I_MOTOR_TORQUE], prm[P_OMEGA_RATE],
                 prm[P_TD_INERTIA], prm[P_TD_KP], prm[P_TD_KI], prm[P_TD_MAX_TORQUE],
                 prm[P_TD_LAG_ALPHA], prm[P_TD_TORQUE_RATE])


@njit(cache=True, inline="always")
def _unpack(st: np.ndarray, meta: np.ndarray) -> Loop:
    """The state vector and the history's bookkeeping as the loop's state."""
    return Loop(st[S_U], st[S_V], st[S_PHI], st[S_OMEGA], st[S_PHI_S], st[S_OMEGA_S],
                st[S_W_APP], st[S_STUCK] != 0.0, int(st[S_NODE]), st[S_FRAC], st[S_H_OLD],
                int(st[S_STEP]), st[S_OMEGA_REF], st[S_TD_INTEGRAL], st[S_MOTOR_TORQUE],
                st[S_V_HOOK], st[S_HOOK_INTEGRAL], st[S_LAW_OMEGA], meta[0], meta[1], meta[2])


@njit(cache=True, inline="always")
def _pack(st: np.ndarray, meta: np.ndarray, x: Loop, dt: float) -> None:
    """The loop's state back into the state vector and the history's bookkeeping."""
    meta[0], meta[1], meta[2] = x.head, x.count, x.cursor
    st[S_U], st[S_V], st[S_PHI], st[S_OMEGA] = x.u, x.v, x.phi, x.omega
    st[S_PHI_S], st[S_OMEGA_S], st[S_W_APP] = x.phi_s, x.omega_s, x.w_app
    st[S_STUCK] = 1.0 if x.stuck else 0.0
    st[S_NODE], st[S_FRAC], st[S_H_OLD] = x.node, x.frac, x.h_old
    st[S_STEP], st[S_TAU] = x.step, x.step * dt
    st[S_OMEGA_REF], st[S_TD_INTEGRAL], st[S_MOTOR_TORQUE] = x.omega_ref, x.integral, x.motor
    st[S_V_HOOK], st[S_HOOK_INTEGRAL], st[S_LAW_OMEGA] = x.v_hook, x.hook_int, x.law_omega


@njit(cache=True)
def advance_and_sample(st: np.ndarray, prm: np.ndarray, tgt: np.ndarray, profile: np.ndarray,
                       hist: np.ndarray, meta: np.ndarray, acc: np.ndarray, out: np.ndarray,
                       wave: np.ndarray, wave_i: np.ndarray, wave_f: np.ndarray,
                       n_steps: int, every: int, exact: bool) -> tuple[int, int]:
    """:func:`advance`, then the sample of the state it ended in, in the next row of ``out``.

    That sample is what the next step records at its start: the row of a dry step
    (:func:`_steps`), so the simulation itself does not move. ``n_steps = 0`` gives the
    sample of the current state. Returns ``(status, rows_written)`` with the end sample
    counted; on a failed or early-stopped status the end sample is not taken.
    """
    status, rows = STATUS_OK, 0
    if n_steps > 0:
        status, rows = advance(st, prm, tgt, profile, hist, meta, acc, out, wave, wave_i,
                               wave_f, n_steps, every, exact)
    if status != STATUS_OK or rows >= out.shape[0]:
        return status, rows
    # not the literals 1 and True: each literal is a signature of its own, and _steps (the
    # whole step loop) would compile twice, once for advance and once here (a cold cache:
    # 7-12 s a string kind)
    one = np.int64(1)
    _steps(st, prm, tgt, profile, hist, meta, acc, out[rows:rows + 1], wave, wave_i, wave_f,
           one, one, exact, np.bool_(True))
    return status, rows + 1


NO_HISTORY = np.zeros((2, 1))             # what the profile path takes for hist and meta
NO_META = np.zeros(3, dtype=np.int64)
NO_WAVE = None                            # what the lumped string takes for the lines:
NO_WAVE_I = None                          # None, so the lumped loop is compiled on its own
NO_WAVE_F = None
