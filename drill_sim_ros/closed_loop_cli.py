"""``drill_sim closed-loop``: a controller against the sim, scored (in process or over DDS)."""

from __future__ import annotations

import argparse
import json
import math
import sys
from contextlib import ExitStack
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from drill_sim_ros.control.bench import ClosedLoopRun, run_in_process
from drill_sim_ros.control.controllers import CONTROL_MODES
from drill_sim_ros.control.registry import display_name
from drill_sim_ros.control.rig import RigPhysics, rig_physics
from drill_sim_ros.control.scenario import (
    ENSEMBLE_KEY,
    ENSEMBLE_STEP,
    Scenario,
    check_ensemble,
    ensemble_caption,
    load_scenario,
    scenario_path,
    seeded,
)
from drill_sim_ros.control.schedule import Schedule, check_points, late_points
from drill_sim_ros.control.scorecard import SCORE_FIELDS, score, status_text, summarize
from drill_sim_ros.model.errors import DrillSimError
from drill_sim_ros.model.presets import Preset
from drill_sim_ros.model.telemetry import TELEMETRY_FIELDS
from drill_sim_ros.plot_file import (
    add_plot_arguments,
    commit_output,
    commit_plot,
    output_into,
    plot_into,
)
from drill_sim_ros.terminal import StatusLine

LABELS = {"ssi_before_mean": "SSI before switch-on (mean)", "ssi_mean": "SSI after (mean)",
          "ssi_max": "SSI after (max)", "ssi_last": "SSI last 20 s",
          "stick_fraction": "stick fraction after", "stick_longest_s": "longest stick [s]",
          "utr": "UTR", "bit_rpm_max": "bit speed max [rpm]",
          "time_to_suppress_s": "time to suppress [s]",
          "rop_m_h": "mean ROP [m/h]", "mse_mpa": "MSE at the bit [MPa]",
          "quill_torque_peak_nm": "quill torque peak [N m]",
          "quill_torque_rms_nm": "quill torque RMS [N m]",
          "motor_torque_std_nm": "motor torque RMS about mean [N m]",
          "motor_torque_rate_mean_knm_s": "motor torque abs. rate [kN m/s]",
          "motor_energy_mj": "motor work, net [MJ]",
          "motor_energy_in_mj": "motor work, positive [MJ]",
          "saturation_count": "saturated samples",
          "saturation_fraction": "at the torque limit", "period_s": "stick-slip period [s]",
          "ring_rms_rpm": "collar ring RMS [rpm]", "ring_hz": "collar ring freq. [Hz]",
          "cutoff_hz": "cut-off [Hz]", "off_bottom_fraction": "bit off the rock",
          "wob_rms_n": "WOB at the bit, RMS about mean [N]", "status": "status",
          "stall_time_s": "stalled at [s]"}


def add_parser(sub: Any) -> None:
    p = sub.add_parser("closed-loop", help="a top-drive controller against the sim, scored")
    p.add_argument("--params", help="physical preset (default: the scenario's, else "
                   "field_8p5in_shale)")
    p.add_argument("--controller", help="none | stiff | soft_torque | z_torque | "
                   "package.module:Class (default: the scenario's, else stiff)")
    p.add_argument("--mode", choices=CONTROL_MODES, help="speed: the controller sends the "
                   "drive's speed setpoint; torque: it sends the motor torque (default speed)")
    p.add_argument("--t-end", type=float, help="simulated seconds (default 180)")
    p.add_argument("--enable-at", type=float, help="switch-on time, s (default 60, or a third "
                   "of a shorter --t-end)")
    p.add_argument("--scenario", help="a scenario of config/scenarios by name, or a YAML "
                   "file (see drill_sim_ros/control/scenario.py); the options above "
                   "override it")
    p.add_argument("--set", action="append", default=[], metavar="NAME=VALUE",
                   help="a controller parameter, e.g. --set impedance_factor=1.5 (repeatable)")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    add_plot_arguments(p, "speeds with the setpoint, quill and motor torque with its limit, "
                       "WOB; stuck and saturated spans shaded; the last 10 s and the bit "
                       "speed's spectrum with the string's modes; beside the uncontrolled run",
                       others=", --save-traces or --record")
    p.add_argument("--no-baseline", action="store_true", help="skip the uncontrolled run "
                   "(by default it runs too, for the comparison)")
    p.add_argument("--ensemble", type=int, default=1, metavar="N",
                   help="also run N - 1 more members of the same case, member k with the "
                        "bit's sigma l x (1 + k 1e-12), and print the spread of the scores "
                        "(in process; 1-64, default 1: one run)")
    p.add_argument("--ros", action="store_true", help="run sim_node and the "
                   "top_drive_controller node as processes over loopback DDS, score the "
                   "recording")
    p.add_argument("--record", type=Path, metavar="FILE.mcap", help="with --ros: keep "
                   "sim_node's recording (MCAP) of the controlled run in FILE.mcap (without "
                   "it, the recording goes to a temporary directory deleted once scored)")
    p.add_argument("--save-traces", type=Path, metavar="FILE.npz", help="write the runs' "
                   "telemetry rows (every TELEMETRY_FIELDS column, SI) to FILE.npz: arrays "
                   "fields, controlled, baseline (docs/closed-loop.md)")


@dataclass(frozen=True)
class _Outputs:
    """The temporary files beside --plot, --save-traces and --record (None: not asked)."""

    plot: Path | None = None
    traces: Path | None = None
    record: Path | None = None


def _scenario(args: argparse.Namespace) -> Scenario:
    base = load_scenario(scenario_path(args.scenario)) if args.scenario else Scenario()
    params = dict(base.params)
    for item in args.set:
        name, sep, value = item.partition("=")
        try:
            params[name.strip()] = float(value)
        except ValueError:
            sep = ""
        if not sep or not name.strip() or not math.isfinite(params[name.strip()]):
            raise DrillSimError(f"--set {item!r} must be NAME=NUMBER (a finite number)")
    enable_at_s = args.enable_at
    if enable_at_s is None and args.t_end is not None and args.t_end <= base.enable_at_s:
        enable_at_s = args.t_end / 3.0          # a short run: switch on after a third
    return base.with_(preset=args.params, controller=args.controller, mode=args.mode,
                      duration_s=args.t_end, enable_at_s=enable_at_s, params=params)


def _warn_late_points(scenario: Scenario) -> None:
    """One warning line for the schedule's points that a shorter --t-end leaves out (a
    scenario file's own points past its duration_s are refused; a shorter run of a valid
    file is allowed, so they are only named)."""
    points = check_points(list(scenario.schedule))
    late = late_points(points, scenario.duration_s)
    if late:
        times = ", ".join(f"{points[i]['t_s']:g}" for i in late)
        print(f"drill_sim: warning: the schedule's points at t_s = {times} s come at or after "
              f"the end of the run (--t-end = {scenario.duration_s:g} s) and never act",
              file=sys.stderr)


def _run(scenario: Scenario, ros: bool, label: str,
         record_path: Path | None = None) -> ClosedLoopRun:
    line = StatusLine()
    def progress(done: int, total: int) -> None:
        line.show(f"{label}: {done:,}/{total:,} periods ({100 * done / total:4.1f}%)")
    try:
        if ros:
            from drill_sim_ros.ros.closed_loop import run_over_dds
            if record_path is not None:          # sim_node refuses an existing file
                record_path.unlink(missing_ok=True)
            return run_over_dds(scenario, progress, record_path=record_path)
        return run_in_process(scenario, progress)
    finally:
        line.close()


def _table(columns: dict[str, dict[str, Any]]) -> str:
    def cell(value: Any) -> str:
        if value is None:
            return "-"
        if isinstance(value, (int, str)):
            return str(value)
        return f"{value:.4g}" if math.isfinite(value) else "-"
    names = list(columns)
    width = max(22, *(len(n) + 2 for n in names))     # a long name never meets its neighbour
    lines = [f"{'':34s}" + "".join(f"{n:>{width}s}" for n in names)]
    for key in SCORE_FIELDS:
        lines.append(f"{LABELS[key]:34s}" + "".join(f"{cell(columns[n][key]):>{width}s}"
                                                    for n in names))
    return "\n".join(lines)


def cmd_closed_loop(args: argparse.Namespace) -> int:
    check_ensemble(args.ensemble)
    if args.ensemble > 1 and args.ros:
        raise DrillSimError("--ensemble runs in process; drop --ros (or --ensemble)")
    scenario = _scenario(args)
    _warn_late_points(scenario)
    if scenario.enable_at_s >= scenario.duration_s:
        raise DrillSimError(f"--enable-at = {scenario.enable_at_s:g} s must come before the "
                            f"end of the run (--t-end = {scenario.duration_s:g} s): nothing "
                            "would be scored after the switch-on")
    if args.record is not None and not args.ros:
        raise DrillSimError(f"--record {args.record}: only a run over DDS records (add --ros)")
    preset = scenario.load_preset()
    with ExitStack() as stack:
        out = _Outputs(
            stack.enter_context(plot_into(args.plot, args.overwrite)),
            stack.enter_context(output_into(args.save_traces, args.overwrite,
                                            "--save-traces", (".npz",))),
            stack.enter_context(output_into(args.record, args.overwrite, "--record",
                                            (".mcap",))))
        return _closed_loop(args, scenario, preset, out)


def _interrupted(run: ClosedLoopRun) -> int:
    done_s = (len(run.rows) - 1) * run.scenario.period_s
    print(f"drill_sim closed-loop: interrupted at t = {done_s:g} s of "
          f"{run.scenario.duration_s:g} s ({len(run.rows) - 1:,} of {run.scenario.periods:,} "
          "periods); nothing scored or written", file=sys.stderr)
    return 130


def _baseline(args: argparse.Namespace, scenario: Scenario) -> ClosedLoopRun | None:
    """The uncontrolled run beside the controller's (in process), unless there is none."""
    if args.no_baseline or scenario.controller == "none":
        return None
    return _run(scenario.with_(controller="none", mode="speed", params={}), False,
                "no control")


def _members(args: argparse.Namespace, scenario: Scenario, label: str,
             columns: dict[str, dict[str, Any]], schedule: Schedule,
             rig: RigPhysics,
             timed: list[ClosedLoopRun]) -> dict[str, list[dict[str, Any]]] | None:
    """Every column's scorecards over the ensemble: member 0 (the run above) and members
    1 .. N - 1 run here (``control.scenario.seeded``; the seed changes neither the
    setpoints nor the rig's modes; each run is added to ``timed``); None after Ctrl-C."""
    cases = {label: scenario}
    if "no control" in columns:
        cases["no control"] = scenario.with_(controller="none", mode="speed", params={})
    cards: dict[str, list[dict[str, Any]]] = {name: [columns[name]] for name in cases}
    for member in range(1, args.ensemble):
        for name, case in cases.items():
            run = _run(seeded(case, member), False, f"{name}, member {member} of "
                       f"{args.ensemble - 1}")
            if run.interrupted:
                _interrupted(run)
                return None
            timed.append(run)
            cards[name].append(score(run.rows, case.enable_at_s, schedule, rig,
                                     case.period_s))
    return cards


ENSEMBLE_ROWS = (("runs", "runs"), ("counts", "stick-slip / ok / stalled / other"),
                 ("ssi_mean", "SSI after: median (range)"),
                 ("ssi_last", "SSI last 20 s: median (range)"),
                 ("stick_fraction", "stick fraction: median (range)"),
                 ("saturation_fraction", "at the torque limit: median (max)"))


def _ensemble_table(members: dict[str, list[dict[str, Any]]]) -> str:
    cells = {name: summarize(cards) for name, cards in members.items()}
    names = sorted(cells, key=lambda n: n != "no control")
    width = max(24, *(len(n) + 2 for n in names))
    lines = [f"{'':34s}" + "".join(f"{n:>{width}s}" for n in names)]
    lines += [f"{head:34s}" + "".join(f"{cells[n][key]:>{width}s}" for n in names)
              for key, head in ENSEMBLE_ROWS]
    return "\n".join(lines)


def _throughput(timed: list[ClosedLoopRun], ros: bool) -> str:
    """The speed of every run timed (``timed[0]`` the controller's; over DDS with ``ros``,
    the others in process): periods, wall seconds of the runs, periods/s."""
    periods = sum(len(run.rows) - 1 for run in timed)
    wall_s = sum(run.wall_s for run in timed)
    rate = periods / wall_s if wall_s > 0 else math.nan
    period_s = timed[0].scenario.period_s
    runs = f"{len(timed)} run{'s' if len(timed) > 1 else ''}"
    where = "in process"
    if ros:
        where = "over DDS" if len(timed) == 1 else "the controller's over DDS, the rest in process"
    return (f"{periods:,} periods of {period_s * 1e3:g} ms in {runs} ({where}), "
            f"{wall_s:.1f} s: {rate:,.0f} periods/s ({rate * period_s:,.0f}x real time)")


def _print_scores(args: argparse.Namespace, scenario: Scenario,
                  columns: dict[str, dict[str, Any]], label: str,
                  timed: list[ClosedLoopRun],
                  members: dict[str, list[dict[str, Any]]] | None = None) -> None:
    """The scorecards as one JSON object (``--json``; ``periods_per_s``: the controller's
    run) or as a table and the speed of every run timed (:func:`_throughput`); with an
    ensemble, its members' scorecards (JSON) or their spread (table)."""
    wall_s = timed[0].wall_s
    rate = scenario.periods / wall_s if wall_s > 0 else math.nan
    if args.json:
        out = {"scenario": scenario.to_dict(), "path": "ros" if args.ros else "in-process",
               "periods": scenario.periods, "periods_per_s": rate, "score": columns[label],
               "baseline": columns.get("no control"),
               "recording": str(args.record) if args.record else None}
        if members is not None:
            out["ensemble"] = {"members": args.ensemble, "step": ENSEMBLE_STEP,
                               "seeded": ENSEMBLE_KEY, "score": members[label],
                               "baseline": members.get("no control")}
        print(json.dumps(out))
        return
    print(_table(columns))
    print(_throughput(timed, args.ros))
    if (recording := _recording_line(args)) is not None:
        print(recording)
    if members is not None:
        print("\n" + ensemble_caption(args.ensemble))
        print(_ensemble_table(members))


def _write_plot(args: argparse.Namespace, plot_tmp: Path, title: str, scenario: Scenario,
                runs: dict[str, ClosedLoopRun], columns: dict[str, dict[str, Any]],
                schedule: Schedule, rig: RigPhysics) -> None:
    """The runs' picture into ``plot_tmp``, then committed to ``--plot``."""
    from drill_sim_ros.control.plot import PlotContext, PlotRun, plot_runs, schedule_events
    plots = [PlotRun(name, run.rows, name == "no control" or scenario.mode == "speed",
                     status_text(columns[name])) for name, run in runs.items()]
    plot_runs(plot_tmp, plots, PlotContext(title, schedule, scenario.enable_at_s, rig,
                                           schedule_events(schedule)))
    commit_plot(plot_tmp, args.plot, args.overwrite)


def _recording_line(args: argparse.Namespace) -> str | None:
    """Where the run over DDS was recorded (None in process)."""
    if not args.ros:
        return None
    if args.record is None:
        return ("recording: sim_node's MCAP went to a temporary directory, deleted once "
                "scored (--record FILE.mcap keeps it)")
    return f"recording: {args.record} (sim_node's MCAP of the controlled run)"


def _save_traces(args: argparse.Namespace, temporary: Path, scenario: Scenario,
                 runs: dict[str, ClosedLoopRun], label: str) -> None:
    """The runs' telemetry rows into ``temporary``, then onto ``--save-traces``: ``fields``
    (the column names, TELEMETRY_FIELDS: SI, the unit in each name), ``controlled`` and,
    when it ran, ``baseline`` (rows, t = 0 first), ``meta`` (JSON: the scenario, labels)."""
    arrays = {"fields": np.array(TELEMETRY_FIELDS), "controlled": runs[label].rows}
    if "no control" in runs:
        arrays["baseline"] = runs["no control"].rows
    meta = {"scenario": scenario.to_dict(), "controlled": label,
            "baseline": "no control" if "no control" in runs else None,
            "path": "ros" if args.ros else "in-process"}
    np.savez_compressed(temporary, **arrays, meta=np.array(json.dumps(meta)))
    commit_output(temporary, args.save_traces, args.overwrite, "--save-traces")


def _closed_loop(args: argparse.Namespace, scenario: Scenario, preset: Preset,
                 out: _Outputs) -> int:
    rig = rig_physics(preset)
    schedule = scenario.setpoints(preset)
    controlled = _run(scenario, args.ros, scenario.controller, out.record)
    if controlled.interrupted:
        return _interrupted(controlled)
    baseline = _baseline(args, scenario)
    if baseline is not None and baseline.interrupted:
        return _interrupted(baseline)
    label = f"{display_name(scenario.controller)} ({scenario.mode})"
    runs = {"no control": baseline} if baseline is not None else {}
    runs[label] = controlled
    columns = {name: score(run.rows, scenario.enable_at_s, schedule, rig, scenario.period_s)
               for name, run in runs.items()}
    timed = [controlled] + ([baseline] if baseline is not None else [])
    members = _members(args, scenario, label, columns, schedule, rig, timed) \
        if args.ensemble > 1 else None
    if members is None and args.ensemble > 1:
        return 130
    _print_scores(args, scenario, columns, label, timed, members)
    if out.record is not None:
        commit_output(out.record, args.record, args.overwrite, "--record")
    if out.traces is not None:
        _save_traces(args, out.traces, scenario, runs, label)
    if out.plot is not None:
        _write_plot(args, out.plot, f"{preset.name}: {label}, switched on at "
                    f"{scenario.enable_at_s:g} s", scenario, runs, columns, schedule, rig)
    return 0
