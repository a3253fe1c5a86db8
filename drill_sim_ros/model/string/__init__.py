"""The drill string between the top drive and the bit: lumped (RGD07) or a wave guide.

* ``lumped``: RGD07 eq. (1) and (25), a torsional spring C with the BHA inertia I and mass M
  at the bit (the paper's model, bit for bit).
* ``distributed``: a chain of uniform hollow sections (drill pipe, heavy-weight pipe,
  collars, ...), each carrying torsional waves at c_t = sqrt(G / rho) and axial waves at
  c_a = sqrt(E / rho), with impedances Z_t = J_p sqrt(G rho) and Z_a = A sqrt(E rho).

The distributed string is solved by the method of characteristics. In a uniform lossless
section the Riemann invariants ``a = T + Z w`` (travelling down) and ``b = T - Z w``
(travelling up), with T the torque the upper part applies to the lower and w the angular
speed, are carried unchanged at the wave speed: a section whose travel time is a whole
number of steps is a pair of delay lines, exact, with no numerical dispersion or diffusion.
Section boundaries are rounded to whole steps on the cumulative travel time (each within
half a step). At a junction, speed is continuous and the torques balance; with a point
damper D there (torque D w), w = (a_in - b_in) / (Z_up + Z_down + D), and the outgoing waves
follow. Distributed viscous damping (force per length proportional to the local speed,
rate ``gamma`` = damping per unit mass, 1/s) is lumped into ``damping_points`` point dampers
per section, each at the middle of an equal part. A string in a well whose wall holds a
friction is cut instead into cells of one wave step (:func:`wall_cells`), and every junction
between two cells carries the damping and the wall's Coulomb friction of half of each
(:func:`to_junctions`): the friction's resolution is the wave step. Axial waves use the same
machinery with force and velocity; a torsional junction and the axial one nearest in depth
share one wall contact (:func:`junction_pairs`).

Everything compiled here works in the kernel's units (time t*, torque C, force unit
zeta eps a L*, length L*; RGD07 eqs. 19-20).

Split by concept (docs/string.md): :mod:`.spec` (the sections and the spec, SI),
:mod:`.modes` (the analytic modes), :mod:`.lines` (building the delay lines in kernel
units), :mod:`.step` (the compiled step) and :mod:`.readings` (Python-side readings). The
public names are re-exported here.
"""

from __future__ import annotations

from drill_sim_ros.model.string.balance import (
    B_BIT,
    B_DAMPER,
    B_STORED,
    B_TOP,
    B_WALL,
    BALANCE_DAMPER,
    BALANCE_DRIFT,
    BALANCE_OK,
    BALANCE_WALL,
    N_BALANCE,
    RELATIVE_TOLERANCE,
    call_tolerance,
    check_lines,
    line_balance,
    mark_lines,
)
from drill_sim_ros.model.string.lines import (
    LUMPED,
    KernelString,
    WaveLine,
    build_lines,
    fill_steady,
    junction_pairs,
    kernel_string,
    line_steps,
    section_part_counts,
    section_parts,
    steady_friction,
    to_junctions,
    wall_cells,
    walled,
    wave_line,
)
from drill_sim_ros.model.string.modes import (
    analytic_damping_ratios,
    analytic_modes_hz,
    modal_inertias,
)
from drill_sim_ros.model.string.readings import (
    cell_depths_m,
    cells_state,
    line_energy,
    line_state,
)
from drill_sim_ros.model.string.spec import (
    STEEL_DENSITY_KG_M3,
    STEEL_SHEAR_MODULUS_PA,
    STEEL_YOUNGS_MODULUS_PA,
    STRING_DISTRIBUTED,
    STRING_LUMPED,
    STRING_MODELS,
    LineProperties,
    Section,
    StringSpec,
    axial_compliance_m_per_n,
    bit_inertia_of,
    fastest_hook_loop_s,
    line_properties,
    lumped_equivalent,
)
from drill_sim_ros.model.string.step import (
    W_BAND2,
    W_BIT,
    W_D,
    W_DAMP,
    W_DAMP_GAVE,
    W_FD,
    W_FS,
    W_INT_ROWS,
    W_KD,
    W_LAST,
    W_LEN,
    W_OFF,
    W_PAIR,
    W_POS,
    W_ROWS,
    W_RUN,
    W_SLIP,
    W_TOP,
    W_VS,
    W_WALL_GAVE,
    W_WORK,
    W_Z,
    W_ZJ,
    advance,
    arriving,
    bha_speed,
    bottom_end,
    drive_line,
    ends,
    junction_speed,
    layout,
    scatter,
    speed_at_top_of,
    wall_junction,
    wall_slips,
)

__all__ = [
    "BALANCE_DAMPER",
    "BALANCE_DRIFT",
    "BALANCE_OK",
    "BALANCE_WALL",
    "B_BIT",
    "B_DAMPER",
    "B_STORED",
    "B_TOP",
    "B_WALL",
    "LUMPED",
    "N_BALANCE",
    "RELATIVE_TOLERANCE",
    "STEEL_DENSITY_KG_M3",
    "STEEL_SHEAR_MODULUS_PA",
    "STEEL_YOUNGS_MODULUS_PA",
    "STRING_DISTRIBUTED",
    "STRING_LUMPED",
    "STRING_MODELS",
    "W_BAND2",
    "W_BIT",
    "W_D",
    "W_DAMP",
    "W_DAMP_GAVE",
    "W_FD",
    "W_FS",
    "W_INT_ROWS",
    "W_KD",
    "W_LAST",
    "W_LEN",
    "W_OFF",
    "W_PAIR",
    "W_POS",
    "W_ROWS",
    "W_RUN",
    "W_SLIP",
    "W_TOP",
    "W_VS",
    "W_WALL_GAVE",
    "W_WORK",
    "W_Z",
    "W_ZJ",
    "KernelString",
    "LineProperties",
    "Section",
    "StringSpec",
    "WaveLine",
    "advance",
    "analytic_damping_ratios",
    "analytic_modes_hz",
    "arriving",
    "axial_compliance_m_per_n",
    "bha_speed",
    "bit_inertia_of",
    "bottom_end",
    "build_lines",
    "call_tolerance",
    "cell_depths_m",
    "cells_state",
    "check_lines",
    "drive_line",
    "ends",
    "fastest_hook_loop_s",
    "fill_steady",
    "junction_pairs",
    "junction_speed",
    "kernel_string",
    "layout",
    "line_balance",
    "line_energy",
    "line_properties",
    "line_state",
    "line_steps",
    "lumped_equivalent",
    "mark_lines",
    "modal_inertias",
    "scatter",
    "section_part_counts",
    "section_parts",
    "speed_at_top_of",
    "steady_friction",
    "to_junctions",
    "wall_cells",
    "wall_junction",
    "wall_slips",
    "walled",
    "wave_line",
]
