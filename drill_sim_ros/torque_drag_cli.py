"""``drill_sim torque-drag``: the static soft-string torque and drag of a preset's string in
its well (model/torque_drag.py): hook loads picking up, slacking off and rotating, and the
rotating surface torque, then the profiles along the string as one JSON line (``--json``:
only that line).
"""

from __future__ import annotations

import json
import sys
from pathlib import Path
from typing import Any

import numpy as np

from drill_sim_ros.model import torque_drag
from drill_sim_ros.model.checks import number_in
from drill_sim_ros.model.errors import ParameterError
from drill_sim_ros.model.presets import Preset, load_preset
from drill_sim_ros.model.well import Well
from drill_sim_ros.plot_file import add_plot_arguments, commit_plot, plot_into
from drill_sim_ros.string_cli import rounded

PROFILE_STEP_M = 50.0
MAX_WOB_N = 1e7


def add_parser(sub: Any) -> None:
    p = sub.add_parser("torque-drag", help="static soft-string hook loads (pick-up, "
                       "slack-off, rotating) and rotating torque of a preset's string in its "
                       "well", description="Johancsik et al.'s soft string (SPE 11380): the "
                       "wall's normal force is the buoyed weight across the hole plus tension "
                       "x curvature; sliding friction is the well's side_friction.dynamic.")
    p.add_argument("--params", required=True, help="a physical preset with a well: block "
                   "(name or YAML path)")
    p.add_argument("--wob-n", type=float, default=0.0, help="force on the bit, N, in "
                   f"[0, {MAX_WOB_N:g}] (default 0: off bottom)")
    p.add_argument("--json", action="store_true", help="print only the JSON line")
    add_plot_arguments(p, "the well's path, the tension and the torque along the string")


def require_well(preset: Preset) -> Well:
    """The preset's well, or one line saying what is missing."""
    if preset.physical is None or not preset.string.sections:
        raise ParameterError(f"preset '{preset.name}' has no string sections: torque-drag "
                             "needs a physical preset with string.sections and a well: block")
    if preset.string.well is None:
        raise ParameterError(f"preset '{preset.name}' has no well: block (a vertical hole "
                             "without wall contact has no torque and drag)")
    return preset.string.well


def torque_drag_of(preset: Preset, wob_n: float = 0.0) -> torque_drag.TorqueDrag:
    """The preset's static loads (sliding friction: its well's dynamic coefficient)."""
    well = require_well(preset)
    cells = torque_drag.string_cells(well.survey, preset.string.sections,
                                     well.mud_density_kg_m3)
    return torque_drag.torque_drag(cells, well.side_friction.dynamic, wob_n)


def scores(preset: Preset, wob_n: float) -> dict[str, Any]:
    """The JSON object: hook loads and surface torque, N and N m, and profiles every
    ``PROFILE_STEP_M`` and at the bit."""
    well = require_well(preset)
    loads = torque_drag_of(preset, wob_n)
    cells = torque_drag.string_cells(well.survey, preset.string.sections,
                                     well.mud_density_kg_m3)
    static_nm = float(np.sum(well.side_friction.static * loads.normal_n_m * cells.radius_m
                             * cells.length_m))
    depth = loads.depth_m
    picks = np.unique(np.append(np.arange(0.0, depth[-1], PROFILE_STEP_M), depth[-1]))

    def at(values: np.ndarray) -> list[float | None]:
        return [rounded(v) for v in np.interp(picks, depth, values)]
    return {
        "preset": preset.name, "wob_n": wob_n, "mu_dynamic": well.side_friction.dynamic,
        "hook_load_n": {"pickup": rounded(loads.pickup_n[0]),
                        "slackoff": rounded(loads.slackoff_n[0]),
                        "rotating": rounded(loads.rotating_n[0])},
        "surface_torque_nm": rounded(loads.surface_torque_nm),
        "static_torque_nm": rounded(static_nm),
        "max_dogleg_deg_per_30m": rounded(float(np.max(
            well.survey.dogleg_severity_deg_per_30m(), initial=0.0))),
        "profile": {"depth_m": [rounded(x) for x in picks], "pickup_n": at(loads.pickup_n),
                    "slackoff_n": at(loads.slackoff_n), "rotating_n": at(loads.rotating_n),
                    "torque_nm": at(loads.torque_nm)},
    }


def cmd_torque_drag(args: Any) -> int:
    number_in("--wob-n", args.wob_n, 0.0, MAX_WOB_N)
    preset = load_preset(args.params)
    result = scores(preset, float(args.wob_n))
    with plot_into(args.plot, args.overwrite) as plot_tmp:
        if not args.json:
            print(_summary(result))
        if plot_tmp is not None:
            _plot(plot_tmp, preset, float(args.wob_n))
            commit_plot(plot_tmp, args.plot, args.overwrite)
            print(f"wrote {args.plot}", file=sys.stderr)
    print(json.dumps(result))
    return 0


def _summary(s: dict[str, Any]) -> str:
    hook = s["hook_load_n"]
    where = "off bottom" if s["wob_n"] == 0.0 else f"{s['wob_n'] / 1e3:g} kN on the bit"
    return "\n".join([
        f"{s['preset']}: static soft-string torque and drag, {where}, sliding friction "
        f"{s['mu_dynamic']:g} (largest dog-leg {s['max_dogleg_deg_per_30m']:.2f} deg/30 m)",
        f"  hook load (string only)  pick-up {hook['pickup'] / 1e3:.1f} kN, slack-off "
        f"{hook['slackoff'] / 1e3:.1f} kN, rotating {hook['rotating'] / 1e3:.1f} kN",
        f"  surface torque rotating  {s['surface_torque_nm'] / 1e3:.2f} kN m (static "
        f"friction, break-away: {s['static_torque_nm'] / 1e3:.2f} kN m)",
    ])


def _plot(path: Path, preset: Preset, wob_n: float) -> None:
    """Four panels: the path in plan (north against east) and in section (true vertical
    depth against horizontal departure), the tension and the rotating torque against
    measured depth."""
    from drill_sim_ros.control.plot import pyplot
    plt = pyplot()
    well, loads = require_well(preset), torque_drag_of(preset, wob_n)
    fig, (ax_plan, ax_path, ax_t, ax_m) = plt.subplots(1, 4, figsize=(16.0, 6.0))
    pos = well.survey.positions_m(loads.depth_m)
    ax_plan.plot(pos[:, 0], pos[:, 1], color="black")
    ax_plan.set(xlabel="east, m", ylabel="north, m", title="plan")
    ax_plan.set_aspect("equal", adjustable="datalim")
    ax_plan.grid(alpha=0.3)
    ax_path.plot(np.hypot(pos[:, 0], pos[:, 1]), pos[:, 2], color="black")
    ax_path.set(xlabel="horizontal departure, m", ylabel="true vertical depth, m",
                title="section")
    for values, label, color in ((loads.pickup_n, "pick-up", "tab:red"),
                                 (loads.rotating_n, "rotating", "tab:green"),
                                 (loads.slackoff_n, "slack-off", "tab:blue")):
        ax_t.plot(values / 1e3, loads.depth_m, color=color, label=label)
    ax_t.set(xlabel="tension, kN", ylabel="measured depth, m", title="tension")
    ax_t.legend()
    ax_m.plot(loads.torque_nm / 1e3, loads.depth_m, color="tab:purple")
    ax_m.set(xlabel="torque rotating, kN m", ylabel="measured depth, m", title="torque")
    for ax in (ax_path, ax_t, ax_m):
        ax.invert_yaxis()
        ax.grid(alpha=0.3)
    fig.suptitle(f"{preset.name}: soft-string torque and drag, mu "
                 f"{well.side_friction.dynamic:g}, "
                 + ("off bottom" if wob_n == 0.0 else f"{wob_n / 1e3:g} kN on the bit"))
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
