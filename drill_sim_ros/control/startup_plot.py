"""The start-up picture (``drill_sim startup --plot``; needs matplotlib).

Three panels against simulated time, sharing it:

1. speeds: the bit, the drive and the speed loop's setpoint (the ramp), rev/min;
2. torques: the motor's and the string's at the top (the torque sub's), kN m;
3. the string's twist, turns.

The break-away (the bit first above 1 rpm) is a red dashed line on every panel, its time in
the legend; spans where the bit is stuck (|bit speed| below 1 rpm) are shaded; both judged,
as the scores are, on the bit speed below the cut-off (drawn navy over the raw speed). The legends
stand right of the panels, off the curves.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from drill_sim_ros.control.plot import pyplot
from drill_sim_ros.model.startup import TURNING_RPM, StartupRun, judged_rpm

KN_PER_N = 1e-3


def plot_startup(path: Path, run: StartupRun, title: str, breakaway_s: float | None) -> None:
    """Write the PNG of ``run`` (module doc) to ``path``."""
    plt = pyplot()
    fig, (ax_speed, ax_torque, ax_twist) = plt.subplots(3, 1, figsize=(11.0, 8.0),
                                                        sharex=True)
    t, judged = run.t_s, judged_rpm(run)
    ax_speed.plot(t, run.bit_rpm, color="tab:blue", lw=0.5, alpha=0.6, label="bit")
    if judged is not run.bit_rpm:
        ax_speed.plot(t, judged, color="navy", lw=1.2,
                      label=f"bit below the cut-off ({run.cutoff_hz:.2f} Hz)")
    ax_speed.plot(t, run.drive_rpm, color="tab:green", lw=1.2, label="drive")
    ax_speed.plot(t, run.setpoint_rpm, color="black", lw=0.8, ls="--",
                  label="drive setpoint (ramp)")
    ax_speed.set_ylabel("speed [rpm]")
    ax_torque.plot(t, run.motor_torque_nm * KN_PER_N, color="tab:olive", lw=0.8,
                   label="motor torque")
    ax_torque.plot(t, run.surface_torque_nm * KN_PER_N, color="tab:brown", lw=0.8,
                   label="string torque at the top")
    ax_torque.set_ylabel("torque [kN m]")
    ax_twist.plot(t, run.twist_turns, color="tab:purple", lw=0.8, label="twist")
    ax_twist.set_ylabel("twist of the string [turns]")
    ax_twist.set_xlabel("simulated time [s]")
    stuck = np.abs(judged) < TURNING_RPM
    for ax in (ax_speed, ax_torque, ax_twist):
        _mark(ax, t, stuck, breakaway_s)
        ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8, frameon=False)
    ax_speed.set_title(title, fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)


def _mark(ax: Any, t: np.ndarray, stuck: np.ndarray, breakaway_s: float | None) -> None:
    """The stuck spans shaded, the break-away line and a light grid on ``ax``."""
    ax.fill_between(t, 0, 1, where=stuck, transform=ax.get_xaxis_transform(),
                    color="tab:red", alpha=0.12, lw=0, label="bit stuck")
    if breakaway_s is not None:
        ax.axvline(breakaway_s, color="tab:red", ls="--", lw=1.0,
                   label=f"break-away {breakaway_s:.2f} s")
    ax.grid(alpha=0.3)
