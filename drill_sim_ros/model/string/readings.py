"""Python-side readings of the delay lines: force and speed of every cell, cell depths,
the lines' energy."""

from __future__ import annotations

import numpy as np
from numba import njit

from drill_sim_ros.model.string.lines import WaveLine
from drill_sim_ros.model.string.step import W_LEN, W_OFF, W_POS, W_RUN, W_Z


# ---- Python-side readings ------------------------------------------------------------------
def line_state(wave: np.ndarray, wave_i: np.ndarray, wave_f: np.ndarray, lo: int,
               hi: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(force, speed, impedance) of every cell of parts lo..hi-1, top to bottom, now."""
    cells = int(wave_i[W_LEN, lo:hi].sum())
    force, speed, z = np.empty(cells), np.empty(cells), np.empty(cells)
    _line_state_into(wave, wave_i, wave_f, lo, hi, force, speed, z)
    return force, speed, z


@njit(cache=True)
def _line_state_into(wave: np.ndarray, wave_i: np.ndarray, wave_f: np.ndarray, lo: int,
                     hi: int, force: np.ndarray, speed: np.ndarray, zs: np.ndarray) -> None:
    """:func:`line_state` into the caller's arrays. The slot pos - 1 - k holds the a that
    entered k steps ago (k cells below the top); the b at k cells below the top entered
    n - 1 - k steps ago at the bottom (slot pos + k)."""
    i = 0
    for j in range(lo, hi):
        n, off, pos, z = wave_i[W_LEN, j], wave_i[W_OFF, j], wave_i[W_POS, j], wave_f[W_Z, j]
        ia = pos - 1 if pos > 0 else n - 1     # walks down the a slots, wrapping
        ib = pos                               # walks up the b slots, wrapping
        for _ in range(n):
            a, b = wave[off + ia], wave[off + n + ib]
            force[i] = 0.5 * (a + b)
            speed[i] = (a - b) / (2.0 * z)
            zs[i] = z
            i += 1
            ia = ia - 1 if ia > 0 else n - 1
            ib = ib + 1 if ib + 1 < n else 0


def cells_state(wave: np.ndarray, wave_i: np.ndarray, wave_f: np.ndarray, lo: int,
                cells: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(force, speed) of the ``cells`` (ascending indices among the cells that
    :func:`line_state` lists for the line whose parts start at column ``lo``) now, the same
    values it gives there, reading no other cell."""
    force, speed = np.empty(cells.size), np.empty(cells.size)
    _cells_state_into(wave, wave_i, wave_f, lo, cells, force, speed)
    return force, speed


@njit(cache=True)
def _cells_state_into(wave: np.ndarray, wave_i: np.ndarray, wave_f: np.ndarray, lo: int,
                      cells: np.ndarray, force: np.ndarray, speed: np.ndarray) -> None:
    """:func:`cells_state` into the caller's arrays: cell k of a part (k below its top)
    holds the a in slot pos - 1 - k and the b in slot pos + k, wrapping (see
    :func:`_line_state_into`)."""
    j, top = lo, 0                 # the part of cells[i], and the index of its first cell
    for i in range(cells.size):
        cell = cells[i]
        while cell >= top + wave_i[W_LEN, j]:
            top += wave_i[W_LEN, j]
            j += 1
        n, off, pos, z = wave_i[W_LEN, j], wave_i[W_OFF, j], wave_i[W_POS, j], wave_f[W_Z, j]
        k = cell - top
        a, b = wave[off + (pos - 1 - k) % n], wave[off + n + (pos + k) % n]
        force[i] = 0.5 * (a + b)
        speed[i] = (a - b) / (2.0 * z)


def cell_depths_m(line: WaveLine, wave_i: np.ndarray, lo: int) -> np.ndarray:
    """Depth below the top of the middle of every cell of a line (its parts start at
    column ``lo`` of ``wave_i``), m."""
    depths, top = [], 0.0
    for j, length in enumerate(line.length_m):
        n = int(wave_i[W_LEN, lo + j])
        depths.append(top + (np.arange(n) + 0.5) * (length / n))
        top += length
    return np.concatenate(depths)


@njit(cache=True)
def line_energy(wave: np.ndarray, wave_i: np.ndarray, wave_f: np.ndarray, lo: int, hi: int,
                dtau: float) -> float:
    """Kinetic + strain energy of a line, sum of (a^2 + b^2) dtau / (4 Z) over its cells
    (a cell's T = (a + b) / 2 and Z w = (a - b) / 2 hold (T^2 + Z^2 w^2) dtau / 2 Z). The
    parts' slots follow each other in ``wave``, so a run of parts of one impedance (a
    section, or a walled section's cells; W_RUN, worked out once instead of a search over
    the parts at every call: 1.4 us of the deviated string's 5.5 us check, measured) is
    summed at once: the guard reads it after every run (string.balance)."""
    total = 0.0
    j = lo
    while j < hi:
        z, end = wave_f[W_Z, j], min(hi, wave_i[W_RUN, j])
        stop = wave_i[W_OFF, end - 1] + 2 * wave_i[W_LEN, end - 1]
        run = wave[wave_i[W_OFF, j]:stop]
        total += np.dot(run, run) * dtau / (4.0 * z)     # BLAS: 3x a plain loop, measured
        j = end
    return total
