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

The bit law has a seam like the top drive's modes: a law index (``LAW_*``, kernel slot
``P_BIT_LAW``) and one small function per law giving the sliding torque from the depth of
cut, the wearflat force and the bit's speed, with two parameters ``a`` and ``b`` (slots
``P_BIT_LAW_A``, ``P_BIT_LAW_B``). Whatever the law, the stick is RGD07's: the bit stuck holds
any string torque up to the static torque delta + beta lambda (eqs. 14, 32-33; a bit that the
string pulls up rises and holds delta alone, :func:`bit_response`), and a law's
torque at omega = 0 is that static level (f(0) = 1 below), so the torque is continuous at
the slip. A new law is one function here, its index, its branch in :func:`sliding_torque`
and its :class:`BitLaw` parameters.

* ``rgd07`` (0): T = delta + beta W_f (eq. 30), rate-independent.
* ``weakening_friction`` (1): T = delta + beta W_f f(omega), the wearflat friction falling
  with the bit's speed (NORCE Simulator4nDOF's form, docs/model.md);
* ``weakening_bit`` (2): T = (delta + beta W_f) f(omega), the whole bit torque falling
  (the COPPE/UFRJ form);

with f(omega) = 1 - (1 - a)(1 - exp(-omega / b)): a the floor ratio f(inf) in (0, 1], b the
e-folding speed (scaled, omega t*). Written so that f(0) = 1 and a = 1 give exactly 1.

Whatever the law, a bit may carry a depth-of-cut limit (:class:`DepthOfCutLimit`, off by
default): its cutters cut at most ``doc_max`` per revolution, and deeper than that the bit's
limiter (depth-of-cut control elements, the blade body behind the cutters) rides on the
rock. The kernel then hands :func:`bit_response` the capped cutting depth and ``limited``:
the limiter stops the bit's axial advance (a rigid unilateral contact, like the wearflat's
eq. 31 without its bound lambda) and carries the weight the cutters and the wearflat do not,
with its own friction ``beta_limit`` (mu gamma zeta of that contact, as beta is the
wearflat's, eq. 10). Without it (``limited`` False) the law is RGD07's, bit for bit.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields, replace

import numpy as np
from numba import njit

from drill_sim_ros.model.checks import check_known_keys, number_in
from drill_sim_ros.model.errors import ParameterError
from drill_sim_ros.model.lag import lag_share

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
def limiter_contact(v_new: float, kick: float) -> tuple[float, float]:
    """The depth-of-cut limiter in contact: it stops the bit's advance into the rock.

    Returns ``(v_new, w_l)``: a bit moving down (``v_new > 0``) is stopped, ``v_new = 0``,
    by the force ``w_l = v_new / kick`` >= 0 that the step's momentum balance needs
    (eq. 25 left); a bit moving up leaves the limiter, ``w_l = 0``.
    """
    if v_new > 0.0:
        return 0.0, v_new / kick
    return v_new, 0.0


@njit(cache=True, inline="always")
def stuck_wearflat(f_ext: float, doc: float, lam: float) -> float:
    """Wearflat force while the bit sticks (eq. 31 last line, eq. 25 left with V = 0).

    The bit is immobile, so the axial balance W = f_ext holds with W = delta_k + W_f
    (eq. 29): the wearflat carries what the cutting face does not, within ``[0, lam]``.
    """
    return min(max(f_ext - doc, 0.0), lam)


# ---- the bit laws (one function each; module doc) ----------------------------------------
LAW_RGD07 = 0
LAW_WEAKENING_FRICTION = 1
LAW_WEAKENING_BIT = 2
LAWS = ("rgd07", "weakening_friction", "weakening_bit")


@njit(cache=True, inline="always")
def weakening(omega: float, floor: float, speed: float) -> float:
    """f(omega) = 1 - (1 - floor)(1 - exp(-omega / speed)): 1 at rest, ``floor`` fast, the
    fall e-folding at ``speed``; exactly 1 at omega = 0 and at floor = 1."""
    return 1.0 - (1.0 - floor) * (1.0 - math.exp(-omega / speed))


@njit(cache=True, inline="always")
def rgd07_torque(doc: float, w_f: float, beta: float, omega: float, a: float,
                 b: float) -> float:
    """RGD07 eq. (30): T = delta + beta W_f, whatever the speed."""
    return doc + beta * w_f


@njit(cache=True, inline="always")
def weakening_friction_torque(doc: float, w_f: float, beta: float, omega: float, a: float,
                              b: float) -> float:
    """T = delta + beta W_f f(omega): the wearflat friction falls with the bit's speed."""
    return doc + beta * w_f * weakening(omega, a, b)


@njit(cache=True, inline="always")
def weakening_bit_torque(doc: float, w_f: float, beta: float, omega: float, a: float,
                         b: float) -> float:
    """T = (delta + beta W_f) f(omega): the whole bit torque falls with the bit's speed."""
    return (doc + beta * w_f) * weakening(omega, a, b)


@njit(cache=True, inline="always")
def sliding_torque(law: int, doc: float, w_f: float, beta: float, omega: float, a: float,
                   b: float) -> float:
    """The torque on bit of law ``law`` while the bit turns at ``omega`` (or is about to
    slip, omega = 0): cutting ``doc`` (the depth that sets the cutting forces), wearflat
    force ``w_f``, friction ``beta``, the law's parameters ``a``, ``b``."""
    if law == LAW_WEAKENING_FRICTION:
        return weakening_friction_torque(doc, w_f, beta, omega, a, b)
    if law == LAW_WEAKENING_BIT:
        return weakening_bit_torque(doc, w_f, beta, omega, a, b)
    return rgd07_torque(doc, w_f, beta, omega, a, b)


@njit(cache=True, inline="always")
def bit_response(v0: float, kick_v: float, f_ext: float, omega0: float, kick_w: float,
                 t_ext: float, doc: float, stuck: bool, beta: float, lam: float, law: int,
                 omega_bit: float, law_a: float, law_b: float, limited: bool,
                 beta_limit: float) -> tuple[float, float, float, float, float, int, bool]:
    """Bit-rock forces and the bit's new velocities (eqs. 25, 29-33), the sliding torque
    from the bit law ``law`` (:func:`sliding_torque`, parameters ``law_a``, ``law_b``) at
    the bit's speed at the start of the step ``omega_bit``. ``limited``: the bit is as
    deep as its depth-of-cut limit, ``doc`` is the capped cutting depth, and the
    limiter's contact (friction ``beta_limit``) carries the rest of the weight (module
    doc; False: RGD07's law).

    Returns ``(v_new, omega_new, w_f, wob, tob, mode, stuck_new)``.
    """
    if stuck and doc >= 0.0:
        v_up = v0 + kick_v * f_ext             # the bit's speed with no axial reaction
        if v_up < 0.0:
            # The string pulls the stuck bit up. The rock pushes and cannot pull (the
            # unilateral contact of eq. 31), so the bit rises with W = 0 and the wearflat
            # unloaded, held in rotation by its blades' step alone (delta_k: eq. 14 with
            # W_f = 0), a step that shrinks as the bit rises (eq. 8). A torque above it
            # slips the bit (the law below, in lost contact). RGD07's own runs never get
            # here: their f_ext is W_APP > 0 on a bit at rest (v0 = 0). As in RGD07, the
            # contact is read from the bit's speed, not from a gap: a bit that stops
            # rising is back on the rock.
            if t_ext <= doc:
                return v_up, 0.0, 0.0, 0.0, t_ext, MODE_STUCK, True
        else:
            # Stick (eq. 32): the bit is immobile and the rock reacts the string torque
            # and force, until the string torque exceeds the cutting + friction torque
            # delta_k + beta lam (eqs. 14, 33 in the form valid for any top-drive speed).
            # The wearflat is in full contact as the paper assumes and carries
            # f_ext - delta_k (eq. 31, last line), so W = delta_k + W_f (eq. 29) and
            # <U''> = 0 give eq. 44. A limiter in contact carries the rest, and its
            # friction adds to the hold.
            w_f = stuck_wearflat(f_ext, doc, lam)
            w_l = max(f_ext - doc - lam, 0.0) if limited else 0.0
            static = doc + beta * lam + beta_limit * w_l if limited else doc + beta * lam
            if t_ext <= static:
                return 0.0, 0.0, w_f, doc + w_f + w_l, t_ext, MODE_STUCK, True
    if doc >= 0.0:
        v_new, w_f = wearflat_contact(v0, f_ext, doc, lam, kick_v)
        wob = doc + w_f                       # eq. (29): W = delta + W_f
        tob = sliding_torque(law, doc, w_f, beta, omega_bit, law_a, law_b)   # eq. (30)
        if limited:                           # the limiter carries the rest
            v_new, w_l = limiter_contact(v_new, kick_v)
            wob += w_l
            tob += beta_limit * w_l
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


# ---- the law's parameters ---------------------------------------------------------------
APPLIES_TO = ("friction", "bit")       # friction_weakening.applies_to -> LAW_WEAKENING_*
WEAKENING = "physical.friction_weakening"
WEAKENING_RANGES = {"floor_ratio": (0.0, 1.0),      # (0, 1]; 1: RGD07's torque
                    "speed_rad_s": (0.0, 1.0e4),    # (0, 1e4] rad/s
                    "response_s": (0.0, 100.0)}     # [0, 100] s; 0: the bit's own speed


def _weakening_number(key: str, value: object) -> float:
    """``physical.friction_weakening.<key>`` as a float in its range (open below), or one
    ParameterError line naming it and the range."""
    return number_in(f"'{WEAKENING}.{key}'", value, *WEAKENING_RANGES[key],
                     low_open=key != "response_s")


@dataclass(frozen=True)
class BitLaw:
    """The bit law in kernel units, what the simulator takes: ``law`` (``LAW_*``) and its
    parameters ``a``, ``b`` (module doc: for the weakening laws the floor ratio and the
    e-folding speed, scaled omega t*), and ``response``, the time constant (scaled, tau)
    with which the speed the law reads follows the bit's (0: the bit's speed itself). The
    default is RGD07's law. ``doc_max``: the depth-of-cut limit per revolution (scaled,
    L*; inf: none) and ``beta_limit`` its contact's friction mu gamma zeta
    (:class:`DepthOfCutLimit`)."""

    law: int = LAW_RGD07
    a: float = 1.0
    b: float = 1.0
    response: float = 0.0
    doc_max: float = math.inf
    beta_limit: float = 0.0

    def __post_init__(self) -> None:
        if self.law not in range(len(LAWS)):
            raise ParameterError(f"bit law {self.law!r} must be one of 0..{len(LAWS) - 1} "
                                 f"({', '.join(LAWS)})")
        if not (math.isfinite(self.a) and math.isfinite(self.b) and self.b > 0.0):
            raise ParameterError(f"bit law parameters a = {self.a!r}, b = {self.b!r} must "
                                 "be finite, b > 0")
        if not (math.isfinite(self.response) and self.response >= 0.0):
            raise ParameterError(f"bit law response = {self.response!r} must be finite, "
                                 ">= 0")
        if not (self.doc_max > 0.0 and math.isfinite(self.beta_limit)
                and self.beta_limit >= 0.0):
            raise ParameterError(f"bit law doc_max = {self.doc_max!r}, beta_limit = "
                                 f"{self.beta_limit!r} must be > 0 (inf: none), >= 0")

    def alpha(self, dtau: float) -> float:
        """The share by which the speed the law reads follows the bit's over a step
        ``dtau``: the exact step of a first-order lag of time constant ``response`` for a
        speed held over the step, 1 - exp(-dtau / response); 1 without a lag."""
        return lag_share(self.response, dtau)

    def torque(self, doc: float, w_f: float, beta: float, omega: float) -> float:
        """The law's sliding torque (:func:`sliding_torque`), kernel units."""
        return float(sliding_torque(self.law, doc, w_f, beta, omega, self.a, self.b))


RGD07_LAW = BitLaw()


@dataclass(frozen=True)
class FrictionWeakening:
    """A bit torque that falls with the bit's speed, SI (a physical preset's
    ``physical.friction_weakening``;
    docs/model.md#the-bit-law-one-seam-and-a-bit-friction-that-falls-with-speed):
    f(omega) = floor_ratio + (1 - floor_ratio) exp(-omega / speed_rad_s) times the wearflat
    friction (``applies_to: friction``, NORCE Simulator4nDOF's form) or the whole bit torque
    (``bit``, the COPPE/UFRJ form). floor_ratio = 1 is RGD07's law. ``response_s``: the
    law reads the bit's speed through a first-order lag of this time constant (0: the bit's
    speed itself). The published laws are steady-state curves, torque against a held
    rotary speed; a lag keeps them out of the band above it, where the bit meets RGD07's
    rate-independent law (docs/model.md)."""

    floor_ratio: float = 1.0
    speed_rad_s: float = 7.0
    applies_to: str = "friction"
    response_s: float = 0.0

    def __post_init__(self) -> None:
        for key in WEAKENING_RANGES:
            _weakening_number(key, getattr(self, key))
        if self.applies_to not in APPLIES_TO:
            raise ParameterError(f"'{WEAKENING}.applies_to' = {self.applies_to!r} must be "
                                 f"one of {', '.join(APPLIES_TO)}")

    def scaled(self, time_s: float) -> BitLaw:
        """The law in kernel units: the e-folding speed times t*, the response over t*
        (eqs. 19-20)."""
        law = LAW_WEAKENING_FRICTION if self.applies_to == "friction" else LAW_WEAKENING_BIT
        return BitLaw(law, self.floor_ratio, self.speed_rad_s * time_s,
                      self.response_s / time_s)


def friction_weakening_from_dict(values: object) -> FrictionWeakening | None:
    """A preset's ``physical.friction_weakening`` mapping (None: absent, RGD07's law);
    ParameterError (one line) on an unknown key or a value out of range."""
    if values is None:
        return None
    known = tuple(f.name for f in fields(FrictionWeakening))
    if not isinstance(values, dict):
        raise ParameterError(f"'{WEAKENING}' must be a mapping of {', '.join(known)}; "
                             f"got {values!r}")
    check_known_keys(values, known, WEAKENING)
    numbers = {key: _weakening_number(key, values[key])
               for key in WEAKENING_RANGES if key in values}
    return FrictionWeakening(**{**values, **numbers})


# ---- the depth-of-cut limit ------------------------------------------------------------
# (docs/model.md#a-depth-of-cut-limit-an-option-off-by-default)
LIMIT = "physical.depth_of_cut_limit"
LIMIT_RANGES = {"max_depth_m_per_rev": (0.0, 1.0),    # (0, 1] m per revolution
                "mu_gamma": (0.0, 10.0)}              # [0, 10]: the limiter's mu gamma


@dataclass(frozen=True)
class DepthOfCutLimit:
    """A bit whose cutters cut at most ``max_depth_m_per_rev`` per revolution (SI; a
    physical preset's ``physical.depth_of_cut_limit``): deeper than that, its limiter (depth-
    of-cut control elements, the blade body behind the cutters) rides on the rock, stops
    the bit's advance and carries the weight the cutters and the wearflat do not, with the
    friction ``mu_gamma`` (mu gamma of that contact, as the wearflat's ``physical.mu_gamma``
    in eq. 11; None: the wearflat's).
    docs/model.md#a-depth-of-cut-limit-an-option-off-by-default."""

    max_depth_m_per_rev: float
    mu_gamma: float | None = None

    def __post_init__(self) -> None:
        for key, (low, high) in LIMIT_RANGES.items():
            value = getattr(self, key)
            if value is not None:
                number_in(f"'{LIMIT}.{key}'", value, low, high, low_open=key != "mu_gamma")

    def scaled(self, law: BitLaw, length_m: float, zeta: float, mu_gamma: float) -> BitLaw:
        """``law`` with this limit in kernel units: the depth over L*, the friction
        mu gamma zeta (eq. 10) with the bit's ``zeta`` and, without its own, the wearflat's
        ``mu_gamma``."""
        mu_gamma_limit = mu_gamma if self.mu_gamma is None else self.mu_gamma
        return replace(law, doc_max=self.max_depth_m_per_rev / length_m,
                       beta_limit=mu_gamma_limit * zeta)


def depth_of_cut_limit_from_dict(values: object) -> DepthOfCutLimit | None:
    """A preset's ``physical.depth_of_cut_limit`` mapping (None: absent, no limit);
    ParameterError (one line) on an unknown or missing key or a value out of range."""
    if values is None:
        return None
    known = tuple(f.name for f in fields(DepthOfCutLimit))
    if not isinstance(values, dict) or "max_depth_m_per_rev" not in values:
        raise ParameterError(f"'{LIMIT}' must be a mapping with max_depth_m_per_rev (and "
                             f"optionally mu_gamma); got {values!r}")
    check_known_keys(values, known, LIMIT)
    return DepthOfCutLimit(**{key: number_in(f"'{LIMIT}.{key}'", values[key],
                                             *LIMIT_RANGES[key], low_open=key != "mu_gamma")
                              for key in values})
