"""The string's energy balance, the physics guard's check (issue 52): per wave line
(torsional, axial), the energy its delay lines hold against the work done on it.

The compiled step (:mod:`.step`) sums, over the wave steps, the power that enters each line
at its top (the drive, the hook), the power that leaves it at its bottom (the bit), and the
power its junctions take: their walls' friction (W_WORK) and their point dampers' D w^2
(W_DAMP), summed over the line's junctions. The method of characteristics moves every
wave unchanged along its part and applies the losses at the junctions, so the line's
energy, sum (a^2 + b^2) dtau / 4 Z over its slots, changes over a wave step by exactly

    top work - bit work - wall work - damper work

(each slot's old wave is read and replaced once a step, :func:`.step.scatter`): the balance
is an identity of the scheme, and the loss is counted where the scheme applies it, so no
discretisation error enters it (how close the point dampers come to a distributed damping
is another question, docs/string.md#losses-and-the-default-case). What is left is rounding:
every wave written carries a relative error of about eps = 2.2e-16, so a wave step moves the
balance by a few eps of the energy the line holds and moves; summed over a call of m wave
steps, at most about 4 m eps of it (a random walk in practice, far less), and the sums of
the works themselves carry eps of their own size. :data:`RELATIVE_TOLERANCE` bounds the
drift of one call relative to the energy stored and the works summed since the start.

A wall's or a damper's power below zero at any junction in any step means an element gave
the string energy: no tolerance there (each step's power is limit |w|, c w^2 or D w^2,
>= 0 for physical values, exactly 0 at rest). The step keeps, per junction, what its wall
and its damper gave (W_WALL_GAVE, W_DAMP_GAVE: the power summed over the steps in which it
was below zero), so the guard names the junction.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from drill_sim_ros.model.string.readings import line_energy
from drill_sim_ros.model.string.step import (
    W_BIT,
    W_DAMP,
    W_DAMP_GAVE,
    W_TOP,
    W_WALL_GAVE,
    W_WORK,
)

# a line's balance, kernel units (torque C x rad; axially force unit x L*): a row of the
# guard's mark, one per line
B_STORED, B_TOP, B_BIT, B_WALL, B_DAMPER = range(5)
N_BALANCE = 5
# what :func:`check_lines` finds
BALANCE_OK, BALANCE_WALL, BALANCE_DAMPER, BALANCE_DRIFT = range(4)

# |drift of one call| <= RELATIVE_TOLERANCE x (energy stored before and after + |each work|
# summed since the start), per line. The rounding bound of the module doc, 4 m eps, reaches
# it at m = 1.1e6 wave steps in one call (1100 s at a 1 ms wave step; the node's and the
# bench's calls are 10 ms): see :func:`call_tolerance`. Measured on the shipped presets:
# docs/when-things-go-wrong.md#the-physics-guard-at-run-time.
RELATIVE_TOLERANCE = 1e-9
EPS = float(np.finfo(np.float64).eps)


def call_tolerance(wave_steps: int) -> float:
    """The relative tolerance of a call of ``wave_steps`` wave steps: RELATIVE_TOLERANCE,
    or the rounding bound 4 m eps of a longer call."""
    return max(RELATIVE_TOLERANCE, 4.0 * EPS * wave_steps)


@njit(cache=True)
def line_balance(wave: np.ndarray, wave_i: np.ndarray, wave_f: np.ndarray, lo: int, hi: int,
                 dtau: float, out: np.ndarray) -> int:
    """A line's (parts ``lo .. hi - 1``) balance into ``out`` (B_* slots): the energy it
    holds now, and the work done at its top, at its bottom (the bit), by the walls and by
    the dampers since the step's sums were last zeroed (Simulator: the start, a reset).
    Returns the first (topmost) column whose wall or damper gave energy, else -1."""
    out[B_STORED] = line_energy(wave, wave_i, wave_f, lo, hi, dtau)
    out[B_TOP] = wave_f[W_TOP, lo] * dtau
    out[B_BIT] = wave_f[W_BIT, hi - 1] * dtau
    out[B_WALL] = wave_f[W_WORK, lo] * dtau
    out[B_DAMPER] = wave_f[W_DAMP, lo] * dtau
    if not _any_gave(wave_f, lo, hi):
        return -1
    for j in range(lo, hi):
        if wave_f[W_WALL_GAVE, j] < 0.0 or wave_f[W_DAMP_GAVE, j] < 0.0:
            return j
    return -1


@njit(cache=True)
def _any_gave(wave_f: np.ndarray, lo: int, hi: int) -> bool:
    """Whether a wall or a damper of parts ``lo .. hi - 1`` ever gave energy (one pass
    without an early exit, which the compiler runs in vector lanes)."""
    gave = False
    for j in range(lo, hi):
        gave |= (wave_f[W_WALL_GAVE, j] < 0.0) | (wave_f[W_DAMP_GAVE, j] < 0.0)
    return gave


@njit(cache=True)
def mark_lines(wave: np.ndarray, wave_i: np.ndarray, wave_f: np.ndarray, parts_t: int,
               dtau: float, mark: np.ndarray) -> None:
    """Both lines' balance now into ``mark`` (rows: torsional, axial), where the next
    :func:`check_lines` starts from."""
    line_balance(wave, wave_i, wave_f, 0, parts_t, dtau, mark[0])
    line_balance(wave, wave_i, wave_f, parts_t, wave_i.shape[1], dtau, mark[1])


@njit(cache=True)
def check_lines(wave: np.ndarray, wave_i: np.ndarray, wave_f: np.ndarray, parts_t: int,
                dtau: float, mark: np.ndarray, tolerance: float
                ) -> tuple[int, int, int, float, float]:
    """The guard's check of both lines since ``mark`` (:func:`mark_lines`), which it moves
    on to now. Returns ``(finding, line, column, value, bound)``: BALANCE_OK; BALANCE_WALL
    or BALANCE_DAMPER with the topmost junction (column) whose wall (damper) gave energy
    and the work it did while it gave it (below zero); BALANCE_DRIFT with the line's
    drift, stored change - (top - bit - wall - damper work) since the mark, beyond
    ``bound`` = ``tolerance`` x (stored before and after + |each work since the start|).
    ``line`` 0 torsional, 1 axial; kernel units."""
    now = np.empty(N_BALANCE)
    for line in range(2):
        lo, hi = (0, parts_t) if line == 0 else (parts_t, wave_i.shape[1])
        j = line_balance(wave, wave_i, wave_f, lo, hi, dtau, now)
        if j >= 0 and wave_f[W_WALL_GAVE, j] < 0.0:
            return BALANCE_WALL, line, j, wave_f[W_WALL_GAVE, j] * dtau, 0.0
        if j >= 0:
            return BALANCE_DAMPER, line, j, wave_f[W_DAMP_GAVE, j] * dtau, 0.0
        before = mark[line]
        drift = (now[B_STORED] - before[B_STORED]) - (
            (now[B_TOP] - before[B_TOP]) - (now[B_BIT] - before[B_BIT])
            - (now[B_WALL] - before[B_WALL]) - (now[B_DAMPER] - before[B_DAMPER]))
        bound = tolerance * (now[B_STORED] + before[B_STORED] + abs(now[B_TOP])
                             + abs(now[B_BIT]) + abs(now[B_WALL]) + abs(now[B_DAMPER]))
        if not abs(drift) <= bound:          # (a nan drifts too)
            return BALANCE_DRIFT, line, -1, drift, bound
        mark[line, :] = now
    return BALANCE_OK, 0, -1, 0.0, 0.0
