"""``drill_sim fit``: calibrate a preset's parameters to a rig's surface log (docs/fit.md).

Reads the log (fit.log), finds its start-ups, replays each with the drive following the
logged surface speed (model/replay.py) and fits the ``--fit`` parameters by least squares
(fit.engine) on the drift-free misfit of fit.objective; prints each fitted value with its
95 % interval, the misfit before and after, the correlations and warnings, the recorded and
fitted cycles, then, as the last line of stdout, one JSON object (``--json``: only that).
"""

from __future__ import annotations

import datetime as dt
import json
import math
import sys
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from drill_sim_ros.fit import engine
from drill_sim_ros.fit.log import TORQUE_KINDS, SurfaceLog, find_startups, read_log
from drill_sim_ros.fit.objective import Target, make_target
from drill_sim_ros.fit.params import DEFAULT_BOUNDS, parse_fit, parse_span, with_values
from drill_sim_ros.model.errors import DrillSimError
from drill_sim_ros.model.presets import (
    preset_from_dict,
    preset_path,
    read_preset_data,
    submerged_string_weight_n,
)
from drill_sim_ros.model.replay import FOLLOW
from drill_sim_ros.plot_file import (
    add_plot_arguments,
    commit_output,
    commit_plot,
    output_into,
    plot_into,
)
from drill_sim_ros.terminal import StatusLine

REPLAYS_RANGE = (1, 64)      # --replays: one replay a point up to 64


def add_parser(sub: Any) -> None:
    bounds = "; ".join(f"{path} [{low:g}, {high:g}]" for path, (low, high)
                       in DEFAULT_BOUNDS.items())
    p = sub.add_parser("fit", help="calibrate preset parameters to a rig's surface log "
                       "(off-bottom start-ups)", description=__doc__.split("\n\n")[1] +
                       " Default bounds: " + bounds + "; any other path: [value/4, value*4].")
    p.add_argument("--params", required=True, help="the preset to calibrate (name or YAML), "
                   "a physical one with a distributed string and the rig's well")
    p.add_argument("--log", required=True, type=Path, help="CSV, LAS (.las) or sim_node "
                   "recording (.mcap); columns: docs/fit.md")
    p.add_argument("--fit", required=True, help="comma-separated dotted preset paths, each "
                   "optionally =LOW:HIGH, e.g. well.side_friction.static,"
                   "string.torsional_damping_per_s=0.05:2")
    p.add_argument("--window", help="T0:T1, the part of the log to use, s as logged")
    p.add_argument("--torque", choices=TORQUE_KINDS, help="which logged torque to fit when "
                   "the log has both (default: the torque sub's string torque)")
    p.add_argument("--each", action="store_true", help="fit each start-up on its own and "
                   "report the spread (default: all jointly)")
    p.add_argument("--out", type=Path, help="write the preset with the fitted values here "
                   "(.yaml; with --each their mean over the start-ups)")
    p.add_argument("--cache", type=Path, help="the evaluations' cache (default: beside "
                   "--out as OUT.fit-cache.jsonl; none without --out): a fit run again "
                   "resumes from it")
    p.add_argument("--scheduler", help="tcp://HOST:PORT of a Dask scheduler to run on "
                   "(default: a local cluster)")
    p.add_argument("--workers", type=int, help="local cluster's workers (default: one a core)")
    p.add_argument("--in-process", action="store_true", help="no Dask: replay in this process")
    p.add_argument("--replays", type=int, default=engine.REPLAYS_PER_POINT,
                   help=f"replays averaged per parameter vector, {REPLAYS_RANGE[0]}.."
                   f"{REPLAYS_RANGE[1]} (default {engine.REPLAYS_PER_POINT}: fewer are "
                   "faster and leave the misfit rougher, docs/fit.md)")
    p.add_argument("--follow", choices=FOLLOW, default="speed",
                   help="what the replays' drive follows: the logged speed (default), or "
                   "the logged setpoint through the preset's own speed loop (needs a "
                   "setpoint_rpm column and the rig's drive in the preset; no sensor noise "
                   "in the replayed speed: --replays is not used, each point averages "
                   f"{engine.SETPOINT_REPLAYS} replays of the setpoint shifted by under half "
                   "a sample; docs/fit.md)")
    p.add_argument("--json", action="store_true", help="print only the JSON line")
    add_plot_arguments(p, "the recorded and fitted surface speed and torque", "--out")


PLAIN_PROGRESS_S = 30.0   # without a terminal, a progress line this often (a fit takes minutes)


def _window(log: SurfaceLog, text: str | None) -> SurfaceLog:
    if text is None:
        return log
    t0, t1 = parse_span(text, f"--window {text!r}: expected T0:T1 in s",
                        f"--window {text!r}: T0 must be below T1")
    return log.window(t0, t1)


def cmd_fit(args: Any) -> int:
    low, high = REPLAYS_RANGE
    if not low <= args.replays <= high:
        raise DrillSimError(f"--replays {args.replays}: must be within {low}..{high}")
    path = preset_path(args.params)
    data = read_preset_data(path)
    preset = preset_from_dict(path.stem, data)
    params = parse_fit(args.fit, data)
    log = _window(read_log(args.log, args.torque), args.window)
    segments = [log.part(a, b) for a, b in find_startups(log)]
    targets = [make_target(seg, preset) for seg in segments]
    engine.require_follow(args.follow, segments)
    fitted_together = [[seg] for seg in segments] if args.each else [segments]
    for warning in dict.fromkeys(w for group in fitted_together for w in
                                 engine.one_speed_warning(params, [s.speed_rad_s for s in group])):
        print(f"drill_sim fit: warning: {warning}", file=sys.stderr)
    cache = args.cache or (args.out.with_suffix(".fit-cache.jsonl") if args.out else None)
    with plot_into(args.plot, args.overwrite) as plot_tmp, \
            output_into(args.out, args.overwrite, "--out", (".yaml", ".yml")) as out_tmp:
        report = _run(args, data, params, targets, cache)
        results = report.pop("_results")
        if plot_tmp is not None:
            from drill_sim_ros.fit.plot import plot_fit
            plot_fit(plot_tmp, data, params, targets, results, args.follow)
            commit_plot(plot_tmp, args.plot, args.overwrite)
            print(f"wrote {args.plot}", file=sys.stderr)
        if out_tmp is not None:
            _write_preset(out_tmp, data, report, args)
            commit_output(out_tmp, args.out, args.overwrite, "--out")
            print(f"wrote {args.out}", file=sys.stderr)
    if not args.json:
        print(_summary(report))
    print(json.dumps(report))
    return 0


def _run(args: Any, data: dict[str, Any], params: list, targets: list[Target],
         cache: Path | None) -> dict[str, Any]:
    line = StatusLine(every_s=PLAIN_PROGRESS_S)
    groups = [[t] for t in targets] if args.each else [targets]
    try:
        if args.in_process:
            results = [_fit(data, params, g, None, cache, line, args.replays, args.follow)
                       for g in groups]
        else:
            from drill_sim_ros.study.engine import connect
            with connect(args.scheduler, args.workers) as client:
                results = [_fit(data, params, g, client, cache, line, args.replays,
                                args.follow) for g in groups]
    finally:
        line.close()
    return _report(args, data, params, targets, groups, results)


def _fit(data: dict[str, Any], params: list, group: list[Target], client: Any,
         cache: Path | None, line: StatusLine, replays: int, follow: str = "speed"
         ) -> tuple[engine.FitResult, list]:
    evaluator = engine.Evaluator(data, params, group, client, cache, line.show, replays,
                                 follow)
    result = engine.fit(evaluator)
    values = evaluator.values_of(result.x)
    runs = evaluator.map_runs(values)
    return result, runs


def _cycle(target: Target, torque_lp: np.ndarray) -> dict[str, float] | None:
    part = target.torque
    if not part.used.size:
        return None
    from drill_sim_ros.fit.objective import cycle_features
    window = torque_lp[part.cycle]
    f = cycle_features(window, target.log.sample_s)
    return {"period_s": float(f[0]), "mean_nm": float(f[1]), "std_nm": float(f[2]),
            "amplitude_nm": float(0.5 * (np.max(window) - np.min(window)))}


CYCLE_NAMES = ("period_s", "mean_nm", "std_nm")


def _spread(target: Target, cycles: np.ndarray | None) -> dict[str, dict[str, float]] | None:
    """The cycle over the replays averaged at the fitted values (engine's
    ``replayed_cycles``): each feature's mean, standard deviation, least and largest, and
    where the recorded one lies, ``recorded_z`` = (recorded - mean) / sd."""
    recorded = target.cycle_of(target.logged)
    if cycles is None or recorded is None or len(cycles) < 2:
        return None
    out = {}
    for name, values, logged in zip(CYCLE_NAMES, cycles.T, recorded, strict=True):
        sd = float(np.std(values, ddof=1))
        out[name] = {"mean": float(np.mean(values)), "sd": sd, "min": float(np.min(values)),
                     "max": float(np.max(values)),
                     "recorded_z": float((logged - np.mean(values)) / sd) if sd > 0 else 0.0}
    return out


HOOK_LOAD_WARN_SHARE = 0.05   # a logged hook load this far from the hanging weight: a warning


def _hook_load(target: Target, hanging_n: float) -> dict[str, float] | None:
    """The log's hook load (median over the start-up) against the model's: off bottom with
    the hook held, the string's buoyed weight along the hole (``submerged_string_weight_n``),
    whatever the wall's friction (turning, the friction lies along the slip, across the
    string), so it checks the string and the mud, not the fitted friction; None: not
    logged."""
    logged = target.log.hook_load_n
    if logged is None or hanging_n <= 0.0:
        return None
    median = float(np.median(logged))
    return {"logged_n": median, "model_n": hanging_n, "share": median / hanging_n - 1.0}


def _hook_warning(start_s: float, check: dict[str, float] | None) -> list[str]:
    if check is None or abs(check["share"]) <= HOOK_LOAD_WARN_SHARE:
        return []
    return [f"the start-up at {start_s:.1f} s logs a hook load of {check['logged_n'] / 1e3:.0f} "
            f"kN, {100 * check['share']:+.0f} % of the {check['model_n'] / 1e3:.0f} kN the "
            "preset's string hangs with off bottom: check the string's sections and the mud "
            "density, and whether the log's hook load includes the travelling block"]


def _report(args: Any, data: dict[str, Any], params: list, targets: list[Target],
            groups: list[list[Target]], results: list) -> dict[str, Any]:
    fits = []
    for group, (res, runs) in zip(groups, results, strict=True):
        cycles, hook_warnings = [], []
        fitted = with_values(data, {p.path: float(x) for p, x in zip(params, res.x,
                                                                      strict=True)})
        hanging_n = submerged_string_weight_n(preset_from_dict("fitted", fitted))
        spreads = res.cycles or (None,) * len(group)
        for target, run, spread in zip(group, runs, spreads, strict=True):
            logged = _logged_lp(target)
            hook = _hook_load(target, hanging_n)
            hook_warnings += _hook_warning(float(target.log.t_s[0]), hook)
            cycles.append({"start_s": float(target.log.t_s[0]),
                           "first_slip_s": (target.first_slip_s or 0.0),
                           "recorded": _cycle(target, logged),
                           "fitted": _cycle(target, target.model_torque(run[0])),
                           "replays": _spread(target, spread), "hook_load": hook})
        fits.append({
            "values": {p.path: {"value": float(x), "low95": float(lo), "high95": float(hi),
                                "initial": p.initial, "bounds": [p.low, p.high]}
                       for p, x, lo, hi in zip(params, res.x, res.low95, res.high95,
                                               strict=True)},
            "misfit_before": res.misfit_before, "misfit_after": res.misfit_after,
            "correlation": np.round(res.correlation, 4).tolist(),
            "warnings": [*res.warnings, *hook_warnings], "evaluations": res.evaluations,
            "replays": res.replays, "from_cache": res.reused, "seconds": res.seconds,
            "stages": {name: {"replays": n, "seconds": sec}
                       for name, (n, sec) in res.stages.items()},
            "startups": cycles})
    report: dict[str, Any] = {"log": str(args.log), "preset": args.params,
                              "mode": "each" if args.each else "joint",
                              "follow": args.follow,
                              "startups": len(targets), "fits": fits, "_results": results}
    if args.each and len(fits) > 1:
        report["spread"] = {p.path: {"mean": float(np.mean(v)), "std": float(np.std(v, ddof=1))}
                            for p, v in zip(params, np.array([r.x for r, _ in results]).T,
                                            strict=True)}
    return report


def _logged_lp(target: Target) -> np.ndarray:
    from drill_sim_ros.model.analysis import lowpass
    return lowpass(target.log.torque_nm, target.log.sample_s, target.cutoff_hz)


def _summary(report: dict[str, Any]) -> str:
    lines = [f"drill_sim fit: {report['startups']} start-up(s) of {report['log']} on "
             f"{report['preset']} ({report['mode']})"]
    for i, fit in enumerate(report["fits"]):
        if len(report["fits"]) > 1:
            lines.append(f" start-up {i + 1}:")
        for path, v in fit["values"].items():
            lines.append(f"  {path:42s} {v['value']:.5g}  95% [{v['low95']:.5g}, "
                         f"{v['high95']:.5g}]  (from {v['initial']:.5g}){_open(v)}")
        lines.append(f"  misfit (rms of weighted residuals; 1 = within noise) "
                     f"{fit['misfit_before']:.4g} before, {fit['misfit_after']:.4g} after; "
                     f"{fit['replays']} replays ({fit['from_cache']} from the cache) in "
                     f"{fit['seconds']:.1f} s")
        lines.append("  replays by stage: " + ", ".join(
            f"{name} {st['replays']} ({st['seconds']:.0f} s)"
            for name, st in fit["stages"].items()))
        names = list(fit["values"])
        corr = np.array(fit["correlation"])
        for a in range(len(names)):
            for b in range(a + 1, len(names)):
                lines.append(f"  correlation {names[a]} / {names[b]}: {corr[a, b]:+.3f}")
        for s in fit["startups"]:
            for which in ("recorded", "fitted"):
                c = s[which]
                if c:
                    lines.append(f"  cycle from {s['start_s'] + s['first_slip_s']:.1f} s, "
                                 f"{which:8s}: period {c['period_s']:.3f} s, mean "
                                 f"{c['mean_nm']:.0f} N m, std {c['std_nm']:.0f} N m, "
                                 f"amplitude {c['amplitude_nm']:.0f} N m")
            if s.get("hook_load"):
                h = s["hook_load"]
                lines.append(f"  hook load, logged {h['logged_n'] / 1e3:.1f} kN against the "
                             f"{h['model_n'] / 1e3:.1f} kN the string hangs with off bottom "
                             f"({100 * h['share']:+.1f} %; no part of the misfit: docs/fit.md)")
            if s.get("replays"):
                r = s["replays"]
                lines.append("  cycle over the fit's replays (mean +- sd; the recorded at z): "
                             + ", ".join(f"{name.split('_')[0]} {r[name]['mean']:.4g} +- "
                                         f"{r[name]['sd']:.3g} (z {r[name]['recorded_z']:+.1f})"
                                         for name in CYCLE_NAMES))
        lines += [f"  warning: {w}" for w in fit["warnings"]]
    for path, s in report.get("spread", {}).items():
        lines.append(f"  spread over start-ups: {path} {s['mean']:.5g} +- {s['std']:.3g}")
    return "\n".join(lines)


def _open(value: dict[str, Any]) -> str:
    """A note where a 95 % limit is the parameter's bound: the misfit did not rise that
    far, so the log does not limit it on that side."""
    low, high = value["bounds"]
    sides = [side for side, limit, bound in (("below", value["low95"], low),
                                             ("above", value["high95"], high))
             if math.isclose(limit, bound, rel_tol=1e-9, abs_tol=1e-12)]
    return f"; not limited {' or '.join(sides)} by the log: the bound" if sides else ""


def _write_preset(out: Path, data: dict[str, Any], report: dict[str, Any], args: Any
                  ) -> None:
    """The preset with the fitted values (with --each: their mean over the start-ups) and
    a comment naming the log, the date and the intervals."""
    values = {p: s["mean"] for p, s in report.get("spread", {}).items()} or \
        {p: v["value"] for p, v in report["fits"][0]["values"].items()}
    fitted = with_values(data, values)
    fitted["description"] = (str(data.get("description", "")).strip() +
                             f" Calibrated by drill_sim fit to {args.log}.")
    when = dt.datetime.now(dt.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    header = [f"# Fitted by drill_sim fit to the log {args.log} on {when}, from preset "
              f"{args.params} ({report['mode']} over {report['startups']} start-up(s)):"]
    header += [f"#   {p} = {v['value']:.6g}, 95% [{v['low95']:.6g}, {v['high95']:.6g}]"
               for p, v in report["fits"][0]["values"].items()]
    out.write_text("\n".join(header) + "\n" + yaml.safe_dump(fitted, sort_keys=False))
