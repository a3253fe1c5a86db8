"""A second, plain implementation of the RGD07 step (eqs. 25-34, App. C) for the tests.

Written from the equations with the wearflat accounting of the committed behaviour before
issue 13 (W_f = lam, W = W0 while stuck), a prescribed constant top-drive speed (the paper's
kinematic boundary condition: the motor torque equals the string torque), no ramps, no
rebasing and the bottom-hole profile delay. The dynamics never read W_f while stuck, so
the production kernel must reproduce every figure of this path to the last digit except
W_f (and what is derived from it) in stuck samples. Columns follow ``kernel.C_*``.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from drill_sim_ros.model import kernel as k
from drill_sim_ros.model.params import DimensionlessParams


def initial_state(p: DimensionlessParams, perturb_v: float,
                  perturb_omega: float, n_nodes: int) -> tuple[np.ndarray, np.ndarray]:
    """Trivial motion (eq. 34) up to tau = 0: (u, v, phi, omega, phi_s, h_old), profile."""
    doc0 = max(p.w0 - p.lam, 0.0)
    v0 = p.omega0 * doc0 / (2.0 * math.pi)                      # eq. (34)
    t0 = doc0 + p.beta * min(p.w0, p.lam)                       # eq. (34), (18)
    sector = 2.0 * math.pi / p.n
    slope = doc0 / (2.0 * math.pi)                               # U = v0 tau, PHI = omega0 tau
    profile = slope * (np.arange(n_nodes) * (sector / n_nodes) - sector)
    profile[0] = 0.0
    state = np.array([0.0, v0 + perturb_v, 0.0, p.omega0 + perturb_omega, t0,
                      -slope * sector])
    return state, profile


@njit(cache=True)
def run_reference(state: np.ndarray, profile: np.ndarray, n: float, beta: float, lam: float,
                  psi: float, w0: float, omega0: float, dt: float, n_steps: int,
                  every: int, tau_avg: float) -> tuple[np.ndarray, np.ndarray]:
    """Step the bit ``n_steps`` times; a row of ``kernel.C_*`` columns every ``every``,
    and the sums over the steps with tau >= ``tau_avg`` at the ``kernel.A_*`` indices."""
    u, v, phi, omega, phi_s, h_old = state[0], state[1], state[2], state[3], state[4], state[5]
    n_nodes = profile.shape[0]
    sector = 2.0 * math.pi / n
    node, frac, stuck = 0, 0.0, False
    kick = psi * dt
    out = np.zeros((n_steps // every + 1, k.N_COLS))
    sums = np.zeros(k.N_ACC)
    for step in range(n_steps):
        nxt = (node + 1) % n_nodes
        doc = n * (u - (h_old + frac * (profile[nxt] - h_old)))   # eqs. (8), (26)-(28)
        torque = phi_s - phi                                      # C (PHI_S - PHI)
        if stuck and doc >= 0.0 and torque <= doc + beta * lam:  # eqs. (14), (33)
            v_new, omega_new, w_f, wob, tob, mode = 0.0, 0.0, lam, w0, torque, k.MODE_STUCK
        else:
            if doc < 0.0:                                         # off bottom
                v_new, w_f, wob, tob, mode = v + kick * w0, 0.0, 0.0, 0.0, k.MODE_OFF_BOTTOM
            else:                                                 # eqs. (29)-(31)
                v_free = v + kick * (w0 - doc)                    # no wearflat force
                if v_free < 0.0:
                    v_new, w_f = v_free, 0.0                          # lifting: no contact
                elif v_free - kick * lam > 0.0:
                    v_new, w_f = v_free - kick * lam, lam             # sinking: full contact
                else:
                    v_new, w_f = 0.0, v_free / kick                   # V = 0: the balance
                wob, tob = doc + w_f, doc + beta * w_f
                mode = k.MODE_CUTTING if w_f >= lam else k.MODE_LOST_CONTACT
            omega_new = omega + (torque - tob) * dt                # eq. (25) right
            stuck = False
            if omega_new <= 0.0:                                  # eq. (32)
                omega_new = 0.0
                if doc >= 0.0:
                    v_new, stuck = 0.0, True
        if step * dt >= tau_avg:
            sums[k.A_COUNT] += 1.0
            sums[k.A_WF] += w_f
            sums[k.A_TOB] += tob
            sums[k.A_DOC] += doc
            sums[k.A_WOB] += wob
            sums[k.A_OMEGA] += omega
            sums[k.A_T_PIPE] += torque
            sums[k.A_V] += v
            sums[k.A_STUCK] += 1.0 if mode == k.MODE_STUCK else 0.0
        if step % every == 0:
            r = out[step // every]
            r[k.C_TAU], r[k.C_U], r[k.C_V], r[k.C_PHI], r[k.C_OMEGA] = step * dt, u, v, phi, omega
            r[k.C_PHI_S], r[k.C_OMEGA_S], r[k.C_W_APP] = phi_s, omega0, w0
            r[k.C_WOB], r[k.C_TOB], r[k.C_DOC], r[k.C_WF] = wob, tob, doc, w_f
            r[k.C_T_PIPE], r[k.C_MODE] = torque, mode
            r[k.C_MOTOR_TORQUE], r[k.C_OMEGA_REF] = torque, omega0   # no drive acceleration
            r[k.C_F_TOP], r[k.C_OMEGA_BHA] = w0, omega     # lumped: the hook holds W0
        u_new, phi_new = u + v_new * dt, phi + omega_new * dt      # eq. (C.1)
        dfrac = (phi_new - phi) * (n_nodes / sector)
        f_start = frac
        frac += dfrac
        while frac >= 1.0:                     # a passed node keeps the deepest cut
            frac -= 1.0
            node = (node + 1) % n_nodes
            u_cross = u + (u_new - u) * (1.0 - f_start) / dfrac
            f_start -= 1.0
            h_old = profile[node]
            profile[node] = max(h_old, u_cross)
        u, v, phi, omega = u_new, v_new, phi_new, omega_new
        phi_s += omega0 * dt
    return out[:(n_steps + every - 1) // every], sums
