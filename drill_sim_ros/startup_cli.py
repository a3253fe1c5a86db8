"""``drill_sim startup``: the start of rotation off bottom, from rest and untwisted.

Simulates the start-up (model/startup.py) and prints its figures, then, as the last line of
stdout, one JSON object (``--json``: only that line), as ``drill_sim modes`` does.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path
from typing import Any

from drill_sim_ros.model import startup
from drill_sim_ros.model.checks import number_in
from drill_sim_ros.model.consistency import check_stick_band
from drill_sim_ros.model.defaults import MAX_SURFACE_RPM
from drill_sim_ros.model.presets import DEFAULT_PRESET, Preset, load_preset
from drill_sim_ros.plot_file import add_plot_arguments, commit_output, commit_plot, plot_into
from drill_sim_ros.string_cli import rounded
from drill_sim_ros.terminal import StatusLine

DEFINITIONS = (
    f"Break-away: the bit first above {startup.TURNING_RPM:g} rpm; first slip: the bit first "
    f"above {startup.SLIP_RPM:g} rpm. Over the second half of the run: a stick is the bit "
    f"below {startup.TURNING_RPM:g} rpm (|speed|); stick-slip means at least one stick of at "
    f"least {startup.MIN_STICK_S:g} s followed by a slip (the bit above "
    f"{startup.SLIP_RPM:g} rpm) before the next such stick; period_s is the mean time between "
    "such slips (null with fewer than two).")


def add_parser(sub: Any) -> None:
    p = sub.add_parser("startup", help="the start of rotation off bottom from rest: "
                       "break-away, first slip and whether the string then sticks and slips",
                       description="The string hangs off bottom at rest and untwisted, the "
                       "hook fixed; the drive's speed loop ramps its setpoint from 0 to --rpm "
                       "in --ramp-s. " + DEFINITIONS)
    p.add_argument("--params", default=DEFAULT_PRESET, help="a physical preset with a "
                   "distributed string (name or YAML path), e.g. with a deviated well: block")
    p.add_argument("--rpm", type=float, default=60.0,
                   help="the drive's speed at the end of the ramp, rev/min, in "
                   f"(0, {MAX_SURFACE_RPM:g}] (default 60)")
    p.add_argument("--ramp-s", type=float, default=10.0, help="the ramp's length, s, in "
                   f"[0, {startup.MAX_RAMP_S:g}] (0: a step; default 10)")
    p.add_argument("--seconds", type=float, default=60.0, help="length of the run, s of "
                   f"simulated time, in (0, {startup.MAX_SECONDS:g}] (default 60)")
    p.add_argument("--log-csv", type=Path, help="also write the start-up's surface log "
                   "as a rig would record it (measured drive speed and torque-sub torque, "
                   "100 Hz, after 1 s at rest), a CSV that `drill_sim fit --log` reads")
    p.add_argument("--sensors", default="noisy_delayed_sensors", help="the scenario whose "
                   "sensors' noise and quantisation measure --log-csv (default "
                   "noisy_delayed_sensors; their delays left out)")
    p.add_argument("--seed", type=int, default=0, help="the sensors' noise seed (default 0)")
    p.add_argument("--json", action="store_true", help="print only the JSON line")
    add_plot_arguments(p, "the speeds, torques and twist against time, the break-away "
                       "marked", "--log-csv")


def _check_args(args: Any) -> None:
    """Each bad argument one line naming it and its range, before anything runs."""
    number_in("--rpm", args.rpm, 0.0, MAX_SURFACE_RPM, low_open=True)
    number_in("--ramp-s", args.ramp_s, 0.0, startup.MAX_RAMP_S)
    number_in("--seconds", args.seconds, 0.0, startup.MAX_SECONDS, low_open=True)


def cmd_startup(args: Any) -> int:
    _check_args(args)
    preset = load_preset(args.params)
    startup.require_startup_preset(preset)
    well = preset.string.well
    if well is not None and well.has_friction:
        check_stick_band("--rpm", args.rpm, well.side_friction.stick_speed_rad_s)
    with plot_into(args.plot, args.overwrite) as plot_tmp:
        return _startup(args, preset, plot_tmp)


def _startup(args: Any, preset: Preset, plot_tmp: Path | None) -> int:
    """:func:`cmd_startup` once its arguments are checked; the picture into ``plot_tmp``."""
    line = StatusLine()

    def progress(fraction: float) -> None:
        line.show(f"startup: {fraction * args.seconds:7.1f} of {args.seconds:g} s simulated "
                  f"({100 * fraction:5.1f}%)")
    try:
        run = startup.run_startup(preset, args.rpm, args.ramp_s, args.seconds,
                                  on_progress=progress)
    finally:
        line.close()
    scores = _json_ready(startup.startup_scores(run))
    if args.log_csv is not None:
        _write_log(args, preset, run)
    if not args.json:
        print(_summary(preset.name, args, scores))
    if plot_tmp is not None:
        from drill_sim_ros.control.startup_plot import plot_startup
        plot_startup(plot_tmp, run, f"{preset.name}: start-up off bottom, 0 to {args.rpm:g} "
                     f"rpm in {args.ramp_s:g} s", scores["breakaway_s"])
        commit_plot(plot_tmp, args.plot, args.overwrite)
        print(f"wrote {args.plot}", file=sys.stderr)
    print(json.dumps(scores))
    return 0


def _write_log(args: Any, preset: Preset, run: startup.StartupRun) -> None:
    """The run's surface log as a rig records it (fit.synthetic) into ``--log-csv``."""
    from drill_sim_ros.fit import synthetic
    from drill_sim_ros.plot_file import output_into
    log = synthetic.measured_log(run, synthetic.scenario_sensors(args.seed, args.sensors),
                                 1.0, f"drill_sim startup of {preset.name}")
    with output_into(args.log_csv, args.overwrite, "--log-csv", (".csv",)) as tmp:
        synthetic.write_csv(log, str(tmp))
        commit_output(tmp, args.log_csv, args.overwrite, "--log-csv")
    print(f"wrote {args.log_csv}", file=sys.stderr)


def _json_ready(value: Any) -> Any:
    """Floats to 6 decimals (``string_cli.rounded``), through dicts; bools and None stay."""
    if isinstance(value, dict):
        return {key: _json_ready(v) for key, v in value.items()}
    return rounded(value) if isinstance(value, float) else value


def _summary(name: str, args: Any, s: dict[str, Any]) -> str:
    """The human lines of the scores ``s``."""
    def f(value: float | None, fmt: str, unit: str = "", none: str = "never") -> str:
        return none if value is None else f"{value:{fmt}}{unit}"
    half_s = args.seconds / 2.0
    m, tw = s["motor_torque_nm"], s["twist_turns"]
    return "\n".join([
        f"{name}: start-up off bottom from rest, 0 to {args.rpm:g} rpm in {args.ramp_s:g} s, "
        f"{args.seconds:g} s",
        f"  break-away (bit > {startup.TURNING_RPM:g} rpm)  {f(s['breakaway_s'], '.2f', ' s')}"
        f"  after {f(s['breakaway_turns'], '.2f', ' drive turns')}, string torque at the top "
        f"{f(s['breakaway_torque_nm'], '.0f', ' N m')}",
        f"  first slip (bit > {startup.SLIP_RPM:g} rpm)  {f(s['first_slip_s'], '.2f', ' s')}",
        f"  peak motor torque  {s['peak_motor_torque_nm']:.0f} N m",
        f"  second half ({half_s:g}-{args.seconds:g} s): stick-slip "
        f"{'yes' if s['stick_slip'] else 'no'}, period {f(s['period_s'], '.2f', ' s', 'none')}, "
        f"stick fraction {s['stick_fraction']:.3f}, bit up to {s['bit_rpm_max']:.1f} rpm",
        f"    motor torque mean {m['mean']:.0f} N m ({m['min']:.0f} to {m['max']:.0f}); "
        f"twist mean {tw['mean']:.3f} turns ({tw['min']:.3f} to {tw['max']:.3f})",
    ])
