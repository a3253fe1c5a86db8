"""The picture of a fit: per start-up, the logged and fitted surface speed and torque (and
the bit speed where logged), the torque as logged, low-passed and replayed with the
preset's and with the fitted values, the transient's end marked."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from drill_sim_ros.fit.engine import followed_series, simulate
from drill_sim_ros.fit.objective import Target
from drill_sim_ros.model.analysis import lowpass
from drill_sim_ros.model.params import RPM_PER_RAD_S


def plot_fit(path: Path, data: dict[str, Any], params: list, targets: list[Target],
             results: list, follow: str = "speed") -> None:
    """Draw the fit (``results``: per group, (FitResult, runs)) into ``path`` (PNG); the
    replay with the preset's values follows what the fit's did (``follow``)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fitted = [(target, run) for (_, runs), group in zip(results, _groups(targets, results),
                                                         strict=True)
              for target, run in zip(group, runs, strict=True)]
    fig, axes = plt.subplots(2, len(fitted), figsize=(7.5 * len(fitted), 6.5), squeeze=False,
                             sharex="col")
    for col, (target, run) in enumerate(fitted):
        log = target.log
        t = log.t_s - log.t_s[0]
        before = simulate(data, {}, log.t_s, followed_series(log, follow), None,
                          target.cutoff_hz, follow)
        ax = axes[0, col]
        ax.plot(t, log.speed_rad_s * RPM_PER_RAD_S, color="0.6", lw=0.6, label="drive, logged")
        ax.plot(t, run[1] * RPM_PER_RAD_S, color="C1", lw=0.8, label="bit, fitted replay")
        if log.bit_speed_rad_s is not None:
            ax.plot(t, log.bit_speed_rad_s * RPM_PER_RAD_S, color="C2", lw=0.6,
                    label="bit, logged")
        ax.set_ylabel("speed [rpm]")
        ax.set_title(f"start-up at {log.t_s[0]:.1f} s of {Path(log.source).name}")
        ax.legend(loc="upper left", fontsize=8)
        ax = axes[1, col]
        ax.plot(t, log.torque_nm / 1e3, color="0.75", lw=0.5, label=f"{log.torque_kind} "
                "torque, logged")
        ax.plot(t, lowpass(log.torque_nm, log.sample_s, target.cutoff_hz) / 1e3, color="k",
                lw=1.0, label="logged, low-passed")
        if not isinstance(before, str):
            ax.plot(t, target.model_torque(before[0]) / 1e3, color="C0", lw=0.8, ls="--",
                    label="replay, preset's values")
        ax.plot(t, target.model_torque(run[0]) / 1e3, color="C3", lw=1.0,
                label="replay, fitted values")
        ax.axvline((target.first_slip_s or 0.0), color="0.4", ls=":", lw=0.8)
        ax.text((target.first_slip_s or 0.0), ax.get_ylim()[1], " transient | cycle", va="top",
                fontsize=8, color="0.3")
        ax.set_ylabel("torque [kN m]")
        ax.set_xlabel("time from the start-up [s]")
        ax.legend(loc="lower right", fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110, format="png")
    plt.close(fig)


def _groups(targets: list[Target], results: list) -> list[list[Target]]:
    """The targets as the fits grouped them (one group: jointly; else one each)."""
    return [targets] if len(results) == 1 else [[t] for t in targets]
