"""The closed-loop picture: why stick-slip stopped or did not (needs matplotlib).

One column per run (e.g. no control beside a controller, or every controller of a suite on
one scenario), six panels:

1. speeds: the bit, the bit low-passed at the rig's cut-off (what the scorecard judges),
   the drive, the drive's speed setpoint in force (what the controller commands, in speed
   mode) and the operator's setpoint;
2. the string torque at the quill (torque sub);
3. the motor torque with its limit (+-);
4. the WOB at the bit and the applied WOB with the operator's setpoint (these two only while
   the bit is on bottom; a grey band along the bottom where it is picked up);
5. the last ``ZOOM_S`` seconds of the bit and drive speeds, where a ring of the collars
   (which paints the 180 s panels solid) can be seen;
6. the amplitude spectrum of the bit speed after the switch-on (log-log,
   ``SPECTRUM_MIN_HZ`` to ``SPECTRUM_MAX_HZ``), with the string's
   first torsional modes (dotted) and the scorecard's cut-off (dashed) from ``RigPhysics``.

The first four share the time axis. Shaded: red where the bit is stuck (the scorecard's
rule: the low-passed bit speed below ``STUCK_RPM``), orange (a band along the top) where
the drive is saturated (motor torque at its limit, or the speed setpoint at 0 or at the rpm
limit). The switch-on is a red dashed line, each scheduled change of the setpoints a grey
dotted one.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from drill_sim_ros.control.rig import RigPhysics
from drill_sim_ros.control.schedule import Schedule
from drill_sim_ros.control.scorecard import (
    STUCK_RPM,
    lowpassed_bit_rpm,
    sample_period_s,
    saturated,
)
from drill_sim_ros.model import analysis
from drill_sim_ros.model.errors import DrillSimError
from drill_sim_ros.model.telemetry import TELEMETRY_INDEX

F = TELEMETRY_INDEX
ZOOM_S = 10.0            # the zoom panel: the last 10 s of the run
SPECTRUM_MIN_HZ = 0.05   # the spectrum panel's range, log (within Nyquist): the modes
SPECTRUM_MAX_HZ = 25.0   # near 0.2-1.3 Hz stay apart from the ring near 16 Hz
SPECTRUM_DECADES = 4     # and its depth below the highest peak
ROW_LABELS = ("speed [rpm]", "quill torque [kN m]", "motor torque [kN m]", "WOB [kN]",
              f"speed, last {ZOOM_S:g} s [rpm]", "bit speed amplitude [rpm]")


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
    """What the runs of one picture share: the schedule, the switch-on, the rig (its limits,
    torsional modes and cut-off)."""

    title: str
    schedule: Schedule
    enable_at_s: float
    rig: RigPhysics
    events: tuple[tuple[float, str], ...] = ()     # (time s, label) of scheduled changes


def schedule_events(schedule: Schedule) -> tuple[tuple[float, str], ...]:
    """(time, label) of each change of the operator's setpoints."""
    out = [(c.t_s, f"{c.value:g} rpm") for c in schedule.rpm_changes]
    out += [(c.t_s, f"WOB {c.value * 1e-3:g} kN") for c in schedule.wob_changes]
    return tuple(sorted(out))


def pyplot() -> Any:
    """matplotlib's pyplot on the Agg backend (files only), or one line saying how to
    install it."""
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError as exc:
        raise DrillSimError("--plot needs matplotlib: .venv/bin/pip install matplotlib") from exc
    return plt


def plot_runs(path: Path, runs: Sequence[PlotRun], ctx: PlotContext) -> None:
    """Write the PNG of ``runs`` side by side (module doc)."""
    plt = pyplot()
    ncols = len(runs)
    fig, axes = plt.subplots(6, ncols, figsize=(4.2 * ncols + 1.5, 14.0), sharey="row",
                             squeeze=False)
    for group in (axes[:4].ravel(), axes[4], axes[5]):     # time, zoom, frequency
        for ax in group[1:]:
            ax.sharex(group[0])
    peaks = []
    for col, run in enumerate(runs):
        rows = run.rows[run.rows[:, F["sim_time_s"]] > 0.0]
        _column(axes[:4, col], rows, run, ctx)
        _zoom(axes[4, col], rows, ctx)
        peaks.append(_spectrum(axes[5, col], rows, ctx))
        axes[0, col].set_title(f"{run.label}\n{run.status}", fontsize=10)
        for ax in axes[:3, col]:
            ax.tick_params(labelbottom=False)
        axes[3, col].set_xlabel("simulated time [s]")
        axes[4, col].set_xlabel("simulated time [s]")
        axes[5, col].set_xlabel("frequency [Hz]")
    top = max(peaks)
    if top > 0.0:
        axes[5, 0].set_ylim(top * 10.0**-SPECTRUM_DECADES, top * 3.0)
    for ax, label in zip(axes[:, 0], ROW_LABELS, strict=True):
        ax.set_ylabel(label)
    _legend(fig, axes)
    fig.suptitle(ctx.title, fontsize=11)
    fig.tight_layout(rect=(0, 0.05, 1, 0.98))
    fig.savefig(path, dpi=90)
    plt.close(fig)


def _column(axes: Sequence[Any], rows: np.ndarray, run: PlotRun, ctx: PlotContext) -> None:
    """The four panels over the whole run (module doc, 1-4)."""
    t = rows[:, F["sim_time_s"]]
    operator_rpm = np.array([ctx.schedule.rpm_at(x) for x in t])
    ax_speed, ax_quill, ax_motor, ax_wob = axes
    ax_speed.plot(t, operator_rpm, color="black", lw=0.8, ls="--", label="operator setpoint")
    _speeds(ax_speed, t, rows, ctx, run.speed_mode)
    ax_quill.plot(t, rows[:, F["surface_torque_nm"]] * 1e-3, color="tab:brown", lw=0.8,
                  label="quill torque")
    ax_motor.plot(t, rows[:, F["motor_torque_nm"]] * 1e-3, color="tab:olive", lw=0.8,
                  label="motor torque")
    limit_nm = ctx.rig.max_torque_nm
    if np.isfinite(limit_nm):                  # -limit too when the torque goes that way
        low = rows[:, F["motor_torque_nm"]].min() < -0.5 * limit_nm
        for sign in (1, -1) if low else (1,):
            ax_motor.axhline(sign * limit_nm * 1e-3, color="tab:red", lw=1.0, ls="-.",
                             label="torque limit" if sign > 0 else None)
    _wob(ax_wob, t, rows, ctx)
    for ax in axes:
        _shade(ax, t, rows, ctx)
        ax.axvline(ctx.enable_at_s, color="tab:red", ls="--", lw=1.0)
        for at_s, _ in ctx.events:
            ax.axvline(at_s, color="0.4", ls=":", lw=1.0)
    ax_speed.text(ctx.enable_at_s, 0.02, " switch-on", color="tab:red", fontsize=8,
                  transform=ax_speed.get_xaxis_transform())
    for at_s, text in ctx.events:
        ax_speed.text(at_s, 0.86, f" {text}", color="0.3", fontsize=8,
                      transform=ax_speed.get_xaxis_transform())


def _wob(ax: Any, t: np.ndarray, rows: np.ndarray, ctx: PlotContext) -> None:
    """The WOB at the bit; the applied WOB and the operator's setpoint only while the bit is
    on bottom (picked up, the hook carries the string and no WOB is applied: a grey band
    along the bottom marks those spans)."""
    off_bottom = np.array([ctx.schedule.off_bottom_at(x) for x in t], dtype=bool)
    operator_wob_n = np.array([ctx.schedule.wob_at(x) for x in t])
    ax.plot(t, rows[:, F["wob_n"]] * 1e-3, color="tab:cyan", lw=0.5, alpha=0.5,
            label="WOB at bit")
    ax.plot(t, np.where(off_bottom, np.nan, rows[:, F["applied_wob_n"]]) * 1e-3,
            color="tab:gray", lw=1.5, label="applied WOB")
    ax.plot(t, np.where(off_bottom, np.nan, operator_wob_n) * 1e-3, color="black", lw=0.8,
            ls="--", label="operator setpoint")
    if off_bottom.any():
        ax.fill_between(t, 0, 0.07, where=off_bottom, transform=ax.get_xaxis_transform(),
                        color="0.5", alpha=0.6, lw=0, label="bit off bottom")
    low_kn, high_kn = ax.get_ylim()          # at least 0-10 kN: a zero WOB is not magnified
    ax.set_ylim(min(low_kn, 0.0), max(high_kn, 10.0))


def _speeds(ax: Any, t: np.ndarray, rows: np.ndarray, ctx: PlotContext,
            speed_mode: bool) -> None:
    """The bit (raw and low-passed), the drive and, in speed mode, its setpoint."""
    ax.plot(t, rows[:, F["bit_rpm"]], color="tab:blue", lw=0.5, alpha=0.6, label="bit")
    if speed_mode:
        ax.plot(t, rows[:, F["speed_setpoint_rpm"]], color="tab:purple", lw=0.6,
                label="drive setpoint (command)")
    ax.plot(t, rows[:, F["surface_rpm"]], color="tab:green", lw=1.0, label="drive")
    ax.plot(t, lowpassed_bit_rpm(rows, ctx.rig.cutoff_hz), color="navy", lw=1.2,
            label=f"bit below the cut-off ({ctx.rig.cutoff_hz:.2f} Hz)")


def _shade(ax: Any, t: np.ndarray, rows: np.ndarray, ctx: PlotContext) -> None:
    """Red where the bit is stuck (the scorecard's rule), an orange band where the drive is
    saturated; a light grid."""
    stuck = lowpassed_bit_rpm(rows, ctx.rig.cutoff_hz) < STUCK_RPM
    ax.fill_between(t, 0, 1, where=stuck, transform=ax.get_xaxis_transform(),
                    color="tab:red", alpha=0.15, lw=0, label="bit stuck")
    ax.fill_between(t, 0.93, 1, where=saturated(rows, ctx.rig),
                    transform=ax.get_xaxis_transform(), color="tab:orange", alpha=0.7, lw=0,
                    label="drive saturated")
    ax.grid(alpha=0.3)


def _zoom(ax: Any, rows: np.ndarray, ctx: PlotContext) -> None:
    """The last ZOOM_S seconds of the bit (raw and low-passed) and drive speeds."""
    t = rows[:, F["sim_time_s"]]
    last = t >= t[-1] - ZOOM_S
    ax.plot(t[last], rows[last, F["bit_rpm"]], color="tab:blue", lw=0.7)
    ax.plot(t[last], rows[last, F["surface_rpm"]], color="tab:green", lw=1.0)
    ax.plot(t[last], lowpassed_bit_rpm(rows, ctx.rig.cutoff_hz)[last], color="navy", lw=1.2)
    _shade(ax, t[last], rows[last], ctx)


def _spectrum(ax: Any, rows: np.ndarray, ctx: PlotContext) -> float:
    """The bit speed's amplitude spectrum after the switch-on (all of the run if it ends
    before), the modes and the cut-off; its highest peak in range (rpm)."""
    after = rows[rows[:, F["sim_time_s"]] > ctx.enable_at_s]
    after = after if len(after) > 1 else rows
    freq_hz, amplitude = analysis.amplitude_spectrum(after[:, F["bit_rpm"]],
                                                     sample_period_s(after))
    shown = (freq_hz >= SPECTRUM_MIN_HZ) & (freq_hz <= SPECTRUM_MAX_HZ)
    if (amplitude[shown] > 0.0).any():
        ax.loglog(freq_hz[shown], amplitude[shown], color="tab:blue", lw=0.7)
    else:                       # a bit at rest throughout: nothing to put on a log scale
        ax.set_xscale("log")
        ax.text(0.5, 0.5, "the bit does not move: no spectrum", ha="center", va="center",
                fontsize=8, color="0.3", transform=ax.transAxes)
    ax.set_xlim(SPECTRUM_MIN_HZ, min(SPECTRUM_MAX_HZ, float(freq_hz[-1])))
    for i, mode_hz in enumerate(ctx.rig.torsional_modes_hz):
        ax.axvline(mode_hz, color="0.3", ls=":", lw=1.0,
                   label="string's torsional modes" if i == 0 else None)
        ax.text(mode_hz, 0.97, f" f{i + 1}", color="0.3", fontsize=7, va="top",
                transform=ax.get_xaxis_transform())
    if np.isfinite(ctx.rig.cutoff_hz):
        ax.axvline(ctx.rig.cutoff_hz, color="tab:red", ls="--", lw=1.0, label="cut-off (2 f3)")
        ax.text(ctx.rig.cutoff_hz, 0.97, f" cut-off\n {ctx.rig.cutoff_hz:.2f} Hz",
                color="tab:red", fontsize=7, va="top", transform=ax.get_xaxis_transform())
    from matplotlib.ticker import FuncFormatter
    ax.xaxis.set_major_formatter(FuncFormatter(lambda value, _: f"{value:g}"))
    ax.grid(alpha=0.3, which="both")
    peak = amplitude[shown]
    return float(peak.max()) if peak.size and np.isfinite(peak).all() else 0.0


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
