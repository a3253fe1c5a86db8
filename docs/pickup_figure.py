"""A driller picks up a stuck bit (docs/string.md, the stalls): draws the PNG.

The default field preset drilling at 35 rpm and 60 kN through the bench (``controller:
none``, the drive's own speed loop). At 15 s the driller stops the drive (its setpoint
ramped to 0 over 2 s), the bit sticks with the string's last torque trapped in it; at 30 s
he picks up off bottom (the hook rises at the string's pick-up speed). The rock pushes and
cannot pull, so once the hook has taken the string's compression out, the string pulls the
stuck bit up, the bit leaves the rock and the trapped torque spins it free. Three panels
against time: the bit's and the drive's speed; the hook load and the WOB at the bit; the
bit's height above the rock (minus the depth of cut per blade). Stuck spans shaded, the
pick-up dashed.

Usage: .venv/bin/python docs/pickup_figure.py [--out docs/img/stuck_pickup.png]  (about 5 s)
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from drill_sim_ros.control.bench import run_in_process
from drill_sim_ros.control.scenario import Scenario
from drill_sim_ros.model.bit_rock import MODE_STUCK
from drill_sim_ros.model.presets import load_preset
from drill_sim_ros.model.telemetry import TELEMETRY_INDEX as F

OUT = Path(__file__).resolve().parent / "img" / "stuck_pickup.png"
PRESET = "field_8p5in_shale"
STOP_S, PICKUP_S, END_S = 15.0, 30.0, 45.0


def scenario() -> Scenario:
    """Drilling, the drive stopped at STOP_S, the bit picked up at PICKUP_S."""
    return Scenario(preset=PRESET, duration_s=END_S, control_rate_hz=100.0,
                    controller="none", enable_at_s=0.0,
                    schedule=({"t_s": 0.0, "rpm": 35.0, "wob_n": 60e3},
                              {"t_s": STOP_S, "rpm": 0.0, "ramp_s": 2.0},
                              {"t_s": PICKUP_S, "off_bottom": True}))


def draw(rows: np.ndarray, out: Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    t = rows[:, F["sim_time_s"]]
    stuck = rows[:, F["mode"]] == MODE_STUCK
    blades = load_preset(PRESET).physical.n_blades
    fig, (ax_w, ax_f, ax_h) = plt.subplots(3, 1, figsize=(9, 8), sharex=True)
    ax_w.plot(t, rows[:, F["bit_rpm"]], lw=0.8, label="bit")
    ax_w.plot(t, rows[:, F["surface_rpm"]], lw=1.2, color="black", label="drive")
    ax_w.set_ylabel("speed, rpm")
    ax_w.legend(loc="upper right")
    ax_f.plot(t, rows[:, F["hook_load_n"]] * 1e-3, color="tab:green", label="hook load")
    ax_f.set_ylabel("hook load, kN", color="tab:green")
    ax_b = ax_f.twinx()
    ax_b.plot(t, rows[:, F["wob_n"]] * 1e-3, color="tab:red", lw=0.8, label="WOB at the bit")
    ax_b.set_ylabel("WOB at the bit, kN", color="tab:red")
    height_mm = -1e3 * rows[:, F["depth_of_cut_m"]] / blades
    ax_h.plot(t, height_mm, color="tab:purple")
    ax_h.set_yscale("symlog", linthresh=1.0)
    ax_h.set_ylabel("bit above the rock, mm\n(minus the cut per blade)")
    ax_h.set_xlabel("time, s")
    for ax in (ax_w, ax_f, ax_h):
        ax.fill_between(t, 0, 1, where=stuck, transform=ax.get_xaxis_transform(),
                        color="grey", alpha=0.2, lw=0)
        ax.axvline(PICKUP_S, color="black", ls="--", lw=0.8)
    ax_w.set_title(f"{PRESET}: the drive stopped at {STOP_S:g} s, the stuck bit picked up at "
                   f"{PICKUP_S:g} s (grey: stuck)")
    fig.tight_layout()
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=110)
    print(f"wrote {out}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=OUT, help="PNG to write")
    args = parser.parse_args()
    rows = run_in_process(scenario()).rows
    t, mode = rows[:, F["sim_time_s"]], rows[:, F["mode"]]
    after = t >= PICKUP_S
    left = t[after & (mode != MODE_STUCK)]
    print(f"the bit stuck at {t[(t > STOP_S) & (mode == MODE_STUCK)][0]:.2f} s; picked up at "
          f"{PICKUP_S:g} s, it left the stick at {left[0]:.2f} s; hook load "
          f"{rows[after, F['hook_load_n']][0] * 1e-3:.1f} kN at the pick-up, "
          f"{rows[-1, F['hook_load_n']] * 1e-3:.1f} kN at the end")
    draw(rows, args.out)


if __name__ == "__main__":
    main()
