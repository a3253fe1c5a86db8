"""``drill_sim modes`` and ``drill_sim reflection``: the string instruments on the command line.

Both simulate in the time domain (model/string_instruments.py) and print a table, then, as
the last line of stdout, one JSON object (``--json``: only that line).
"""

from __future__ import annotations

import json
import sys
from pathlib import Path
from typing import Any

from drill_sim_ros.control.reflection import (
    CONTROL_RATE_HZ,
    band_top_hz,
    measure_reflection_with,
)
from drill_sim_ros.model import string as sg
from drill_sim_ros.model import string_instruments as si
from drill_sim_ros.model.errors import ParameterError
from drill_sim_ros.model.presets import DEFAULT_PRESET, Preset, load_preset
from drill_sim_ros.plot_file import add_plot_arguments, commit_plot, plot_into


def add_parsers(sub: Any) -> None:
    modes = sub.add_parser("modes", help="natural frequencies and damping ratios of the "
                           "string from simulated ring-downs, beside the analytic ones")
    modes.add_argument("--params", default=DEFAULT_PRESET, help="preset name or YAML path")
    modes.add_argument("--count", type=int, default=3, help="modes of each kind (1-6)")
    modes.add_argument("--json", action="store_true", help="print only the JSON line")
    refl = sub.add_parser("reflection", help="the top drive's reflection of torsional waves "
                          "|r| against frequency, measured in the time domain")
    refl.add_argument("--params", default=DEFAULT_PRESET, help="preset name or YAML path")
    refl.add_argument("--controller", action="append", default=[],
                      help="measure with this controller in the loop through the closed-loop "
                      "bench (a built-in or path/file.py:Class); repeat for several; "
                      "without: the drive's own speed loop, beside the formula")
    refl.add_argument("--mode", choices=("speed", "torque"), default="speed",
                      help="the drive's mode under --controller (default speed)")
    refl.add_argument("--seconds", type=float, default=120.0,
                      help="length of the record after the pulse, s of simulated time "
                      "(20-3600)")
    refl.add_argument("--json", action="store_true", help="print only the JSON line")
    add_plot_arguments(refl, "|r| against frequency")


def cmd_modes(args: Any) -> int:
    if not 1 <= args.count <= 6:
        raise ParameterError(f"--count = {args.count} must be in [1, 6]")
    preset = load_preset(args.params)
    modes = si.identify_modes(preset, count=args.count).as_dict()
    out = {kind: {key: [rounded(v) for v in values] for key, values in d.items()}
           for kind, d in modes.items()}
    if not args.json:
        print("mode  kind        identified Hz  analytic Hz    error  identified zeta  "
              "analytic zeta")
        for kind in ("torsional", "axial"):
            for i in range(len(out[kind]["analytic_hz"])):
                print(_modes_row(i, kind, out[kind]))
        well = preset.string.well
        if well is not None and well.has_friction:
            print(WALL_NOTE)
    print(json.dumps(out))
    return 0


WALL_NOTE = ("note: the string rings in its well, on the wall; the analytic columns are the "
             "free string's. Turning, the wall's sliding friction lies along the slip and "
             "damps axial motion as a viscous force mu_d N / (r_o omega) per metre "
             "(docs/string.md, 'The wall's friction'), so axial rings may die too fast to "
             "identify (n/a)")


def rounded(value: float | None) -> float | None:
    """6 decimals, no negative zero; None stays None (JSON null)."""
    return None if value is None else round(float(value), 6) + 0.0


def _modes_row(i: int, kind: str, d: dict[str, list[float | None]]) -> str:
    """One line of the modes table: mode i + 1 of ``kind`` (``n/a``: not identified)."""
    def cell(key: str, width: int) -> str:
        values = d[key]
        value = values[i] if i < len(values) else None
        return f"{value:{width}.4f}" if value is not None else f"{'n/a':>{width}s}"

    found, analytic = d["identified_hz"], d["analytic_hz"][i]
    hz = found[i] if i < len(found) else None
    error = "n/a" if hz is None else f"{(hz - analytic) / analytic:+.2%}"
    return (f"{i + 1:4d}  {kind:10s}  {cell('identified_hz', 12)}  {cell('analytic_hz', 11)}"
            f"  {error:>7s}  {cell('identified_damping_ratio', 15)}  "
            f"{cell('analytic_damping_ratio', 13)}")


def cmd_reflection(args: Any) -> int:
    if not 20.0 <= args.seconds <= 3600.0:
        raise ParameterError(f"--seconds = {args.seconds!r} must be in [20, 3600]")
    preset = load_preset(args.params)
    si.require_distributed(preset)
    with plot_into(args.plot, args.overwrite) as plot_tmp:
        return _reflection(args, preset, plot_tmp)


def _reflection(args: Any, preset: Preset, plot_tmp: Path | None) -> int:
    """:func:`cmd_reflection` once its arguments are checked; the picture into
    ``plot_tmp``."""
    curves: dict[str, list[float]] = {}
    # with a controller, on to near its Nyquist rate, where a sampled law lags most
    top_hz = band_top_hz(CONTROL_RATE_HZ) if args.controller else si.REFLECTION_TOP_HZ
    f_hz = si.frequencies_with_modes(preset.string, up_to_hz=top_hz)
    modes = {round(float(f), 6): k + 1 for k, f in enumerate(sg.analytic_modes_hz(preset.string))}
    if args.controller:
        for name in args.controller:
            result = measure_reflection_with(args.params, name, args.mode, args.seconds,
                                             f_hz=f_hz)
            curves[name] = [round(r, 5) for r in result.r_measured]
        analytic = None
    else:
        result = si.measure_reflection(preset, seconds=args.seconds, f_hz=f_hz)
        curves["speed loop"] = [round(r, 5) for r in result.r_measured]
        analytic = [round(r, 5) for r in result.r_analytic]
    out: dict[str, Any] = {"f_hz": [round(f, 6) for f in result.f_hz],
                           "r_measured": next(iter(curves.values())), "r_analytic": analytic}
    if len(curves) > 1:
        out["controllers"] = curves
    if not args.json:
        print("f Hz    " + "".join(f"{name:>14s}" for name in curves)
              + ("    analytic" if analytic else ""))
        for i, f in enumerate(out["f_hz"]):
            mode = f"  <- torsional mode {modes[f]}" if f in modes else ""
            print(f"{f:6.3f}  " + "".join(f"{c[i]:14.4f}" for c in curves.values())
                  + (f"  {analytic[i]:10.4f}" if analytic else "") + mode)
    if plot_tmp is not None:
        _plot(plot_tmp, preset.name, out["f_hz"], curves, analytic)
        commit_plot(plot_tmp, args.plot, args.overwrite)
        print(f"wrote {args.plot}", file=sys.stderr)
    print(json.dumps(out))
    return 0


def _plot(path: Path, name: str, f_hz: list[float], curves: dict[str, list[float]],
          analytic: list[float] | None) -> None:
    """|r| against frequency, whole (left) and near 1 from 1 Hz up (right), where a drive
    that returns a little more than it receives shows."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, (ax, zoom) = plt.subplots(1, 2, figsize=(11, 4), width_ratios=(3, 2))
    for axis in (ax, zoom):
        for label, values in curves.items():
            axis.semilogx(f_hz, values, "o-", ms=4, label=f"{label} (measured in the time "
                          "domain)")
        if analytic is not None:
            axis.semilogx(f_hz, analytic, "k--", label="|Z - Z_TD| / |Z + Z_TD|")
        axis.axhline(1.0, color="0.5", lw=0.8)
        axis.set_xlabel("frequency, Hz")
        axis.grid(True, which="both", alpha=0.3)
    ax.set_ylabel("|r| of torsional waves at the top drive")
    ax.set_ylim(0.0, max(1.05, 1.05 * max(max(v) for v in curves.values())))
    ax.legend(fontsize=8)
    high = [v for values in curves.values() for f, v in zip(f_hz, values, strict=True)
            if f >= 1.0]
    spread = max(0.01, max(abs(v - 1.0) for v in high) * 1.2) if high else 0.01
    zoom.set_xlim(1.0, max(f_hz) * 1.1)
    zoom.set_ylim(1.0 - spread, 1.0 + spread)
    zoom.axhspan(1.0, 1.0 + spread, color="tab:red", alpha=0.06)
    zoom.set_title("near 1, from 1 Hz (shaded: the drive feeds the wave)", fontsize=9)
    fig.suptitle(f"{name}: reflection at the top drive (> 1: the drive feeds the wave)")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
