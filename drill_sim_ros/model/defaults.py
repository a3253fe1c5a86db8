"""The defaults a run takes when nothing overrides them, in one place (ROS-free).

sim_node's parameter table (ros/parameters.py) and the in-process bench (control/bench.py)
both read these, so the bench and a default sim_node are the same run by construction.
A preset's own values (rpm, WOB, step, nodes, drive, string) come from the preset.
"""

from __future__ import annotations

from drill_sim_ros.model.presets import Preset

PERTURB_V = 1e-3              # dimensionless axial-velocity kick at t = 0 (model.perturb_v)
WINDOW_S = 20.0               # seconds behind the stick-slip severity (diagnostics.window_s)
MAX_SURFACE_RPM = 300.0       # drive speed command limit, rev/min (limits.max_surface_rpm)
MAX_WOB_FACTOR = 10.0         # WOB command limit as a multiple of the preset's WOB
DTAU = 1e-4                   # the largest step of a preset that names none (model.dtau)
N_NODES = 2048                # bottom-hole profile nodes when a preset names none


def max_wob_n(preset_wob_n: float) -> float:
    """The applied-WOB command limit for a preset whose WOB is ``preset_wob_n`` (N)."""
    return max(MAX_WOB_FACTOR * preset_wob_n, 1.0)


def n_nodes(preset: Preset | None) -> int:
    """The preset's profile nodes, or the default."""
    return N_NODES if preset is None or preset.n_nodes is None else preset.n_nodes
