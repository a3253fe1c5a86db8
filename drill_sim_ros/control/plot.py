"""The closed-loop picture: why stick-slip stopped or did not (needs matplotlib).

One column per run (e.g. no control beside a controller, or every controller of a suite on
one scenario), four panels sharing the time axis:

1. speeds: the bit, the drive, the drive's speed setpoint in force (what the controller
   commands, in speed mode) and the operator's setpoint;
2. the string torque at the quill (torque sub);
3. the motor torque with its limit (+-);
4. the WOB at the bit and the applied WOB with the operator's setpoint.

Shaded: red where the bit is stuck, orange (a band along the top) where the drive is
saturated (motor torque at its limit, or the speed setpoint at 0 or at the rpm limit). The
switch-on is a red dashed line, each scheduled change of the setpoints a grey dotted one.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from drill_sim_ros.control.schedule import Schedule
from drill_sim_ros.model.errors import DrillSimError
from drill_sim_ros.model.telemetry import TELEMETRY_INDEX

F = TELEMETRY_INDEX
STUCK = 2


@dataclass(frozen=True)
class PlotRun:
    """One column: a label, the run's SI telemetry rows, whether the controller sent the
    speed setpoint (speed mode), and its status text (e.g. ``stalled at 42 s``)."""

    label: str
    rows: np.ndarray
    speed_mode: bool = True
    status: str = ""


@dataclass(frozen=True)
class PlotContext:
    """What the runs of one picture share: the schedule, the switch-on, the limits."""

    title: str
    schedule: Schedule
    enable_at_s: float
    max_torque_nm: float = math.inf
    max_surface_rpm: float = math.inf
    events: tuple[tuple[float, str], ...] = ()     # (time s, label) of scheduled changes


def schedule_events(schedule: Schedule) -> tuple[tuple[float, str], ...]:
    """(time, label) of each change of the operator's setpoints."""
    out = [(c.t_s, f"{c.value:g} rpm") for c in schedule.rpm_changes]
    out += [(c.t_s, f"WOB {c.value * 1e-3:g} kN") for c in schedule.wob_changes]
    return tuple(sorted(out))


def saturated(rows: np.ndarray, max_torque_nm: float, max_surface_rpm: float) -> np.ndarray:
    """Samples where the drive is saturated (the scorecard's definition)."""
    setpoint = rows[:, F["speed_setpoint_rpm"]]
    return (np.abs(rows[:, F["motor_torque_nm"]]) >= max_torque_nm * (1 - 1e-9)) | \
        (setpoint <= 0.0) | (setpoint >= max_surface_rpm)


def _pyplot() -> Any:
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError as exc:
        raise DrillSimError("--plot needs matplotlib: .venv/bin/pip install matplotlib") from exc
    return plt


def plot_runs(path: Path, runs: Sequence[PlotRun], ctx: PlotContext) -> None:
    """Write the PNG of ``runs`` side by side (module doc)."""
    plt = _pyplot()
    ncols = len(runs)
    fig, axes = plt.subplots(4, ncols, figsize=(4.2 * ncols + 1.5, 9.5), sharex=True,
                             sharey="row", squeeze=False)
    for col, run in enumerate(runs):
        _column(axes[:, col], run, ctx)
        axes[0, col].set_title(f"{run.label}\n{run.status}", fontsize=10)
        axes[-1, col].set_xlabel("simulated time [s]")
    for ax, label in zip(axes[:, 0], ("speed [rpm]", "quill torque [kN m]",
                                      "motor torque [kN m]", "WOB [kN]"), strict=True):
        ax.set_ylabel(label)
    _legend(fig, axes)
    fig.suptitle(ctx.title, fontsize=11)
    fig.tight_layout(rect=(0, 0.06, 1, 0.97))
    fig.savefig(path, dpi=90)
    plt.close(fig)


def _column(axes: Sequence[Any], run: PlotRun, ctx: PlotContext) -> None:
    rows = run.rows[run.rows[:, F["sim_time_s"]] > 0.0]
    t = rows[:, F["sim_time_s"]]
    operator_rpm = np.array([ctx.schedule.rpm_at(x) for x in t])
    operator_wob = np.array([ctx.schedule.wob_at(x) for x in t])
    ax_speed, ax_quill, ax_motor, ax_wob = axes
    ax_speed.plot(t, operator_rpm, color="black", lw=0.8, ls="--", label="operator setpoint")
    ax_speed.plot(t, rows[:, F["bit_rpm"]], color="tab:blue", lw=0.8, label="bit")
    if run.speed_mode:
        ax_speed.plot(t, rows[:, F["speed_setpoint_rpm"]], color="tab:purple", lw=0.6,
                      label="drive setpoint (command)")
    ax_speed.plot(t, rows[:, F["surface_rpm"]], color="tab:green", lw=1.0, label="drive")
    ax_quill.plot(t, rows[:, F["surface_torque_nm"]] * 1e-3, color="tab:brown", lw=0.8,
                  label="quill torque")
    ax_motor.plot(t, rows[:, F["motor_torque_nm"]] * 1e-3, color="tab:olive", lw=0.8,
                  label="motor torque")
    if math.isfinite(ctx.max_torque_nm):       # -limit too when the torque goes that way
        low = rows[:, F["motor_torque_nm"]].min() < -0.5 * ctx.max_torque_nm
        for sign in (1, -1) if low else (1,):
            ax_motor.axhline(sign * ctx.max_torque_nm * 1e-3, color="tab:red", lw=1.0,
                             ls="-.", label="torque limit" if sign > 0 else None)
    ax_wob.plot(t, rows[:, F["wob_n"]] * 1e-3, color="tab:cyan", lw=0.5, alpha=0.5,
                label="WOB at bit")
    ax_wob.plot(t, rows[:, F["applied_wob_n"]] * 1e-3, color="tab:gray", lw=1.5,
                label="applied WOB")
    ax_wob.plot(t, operator_wob * 1e-3, color="black", lw=0.8, ls="--")
    stuck = rows[:, F["mode"]] == STUCK
    sat = saturated(rows, ctx.max_torque_nm, ctx.max_surface_rpm)
    for ax in axes:
        ax.fill_between(t, 0, 1, where=stuck, transform=ax.get_xaxis_transform(),
                        color="tab:red", alpha=0.15, lw=0, label="bit stuck")
        ax.fill_between(t, 0.93, 1, where=sat, transform=ax.get_xaxis_transform(),
                        color="tab:orange", alpha=0.7, lw=0, label="drive saturated")
        ax.axvline(ctx.enable_at_s, color="tab:red", ls="--", lw=1.0)
        for at_s, _ in ctx.events:
            ax.axvline(at_s, color="0.4", ls=":", lw=1.0)
        ax.grid(alpha=0.3)
    ax_speed.text(ctx.enable_at_s, 0.02, " switch-on", color="tab:red", fontsize=8,
                  transform=ax_speed.get_xaxis_transform())
    for at_s, text in ctx.events:
        ax_speed.text(at_s, 0.86, f" {text}", color="0.3", fontsize=8,
                      transform=ax_speed.get_xaxis_transform())


def _legend(fig: Any, axes: Any) -> None:
    """One legend for the whole picture, below it."""
    handles, labels = [], []
    for ax in axes[:, 0]:
        for handle, label in zip(*ax.get_legend_handles_labels(), strict=True):
            if label not in labels and not label.startswith("_"):
                handles.append(handle)
                labels.append(label)
    fig.legend(handles, labels, loc="lower center", ncol=min(len(labels), 6), fontsize=8,
               frameon=False)
