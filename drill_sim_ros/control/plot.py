"""The closed-loop picture: bit rpm and quill torque against time, controlled beside
uncontrolled, the switch-on marked (needs matplotlib)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from drill_sim_ros.model.errors import DrillSimError
from drill_sim_ros.model.telemetry import TELEMETRY_INDEX

F = TELEMETRY_INDEX


def plot_runs(path: Path, controlled: np.ndarray, baseline: np.ndarray | None,
              enable_at_s: float, title: str) -> None:
    """Write a PNG of two panels (bit rpm; string torque at the quill, kN m)."""
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError as exc:
        raise DrillSimError("--plot needs matplotlib: .venv/bin/pip install matplotlib") from exc
    fig, (ax_rpm, ax_torque) = plt.subplots(2, 1, figsize=(10, 6), sharex=True)
    runs = [("controlled", controlled, "tab:blue", 1.0)]
    if baseline is not None:
        runs.insert(0, ("no control", baseline, "tab:gray", 0.8))
    for label, rows, color, width in runs:
        t = rows[:, F["sim_time_s"]]
        ax_rpm.plot(t, rows[:, F["bit_rpm"]], color=color, lw=width, label=label)
        ax_torque.plot(t, rows[:, F["surface_torque_nm"]] * 1e-3, color=color, lw=width,
                       label=label)
    for ax in (ax_rpm, ax_torque):
        ax.axvline(enable_at_s, color="tab:red", ls="--", lw=1.0)
        ax.grid(alpha=0.3)
    ax_rpm.text(enable_at_s, ax_rpm.get_ylim()[1], " switch-on", color="tab:red", va="top")
    ax_rpm.set_ylabel("bit speed [rpm]")
    ax_torque.set_ylabel("quill torque [kN m]")
    ax_torque.set_xlabel("simulated time [s]")
    ax_rpm.legend(loc="upper right")
    ax_rpm.set_title(title)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
