"""Offline command line ``drill_sim``: runs, maps, figures and closed-loop tests of the model.

Subcommands: ``run | sweep | presets | params | info | closed-loop | suite | modes |
reflection | stability | startup | torque-drag | map | map-plot | figures``.

``drill_sim run`` integrates the RGD07 model without ROS and prints a summary (or one JSON
object with ``--json``). The run is dimensionless unless ``--params`` names a physical
preset, in which case SI figures are added.
"""

from __future__ import annotations

import argparse
import csv
import io
import json
import math
import os
import signal
import sys
import time
from collections.abc import Iterator, Sequence
from dataclasses import dataclass, fields, replace
from pathlib import Path
from typing import Any, NoReturn, TextIO

from drill_sim_ros import (
    closed_loop_cli,
    fit_cli,
    stability_cli,
    startup_cli,
    string_cli,
    torque_drag_cli,
)
from drill_sim_ros.archive.output import open_output
from drill_sim_ros.archive.signals import stop_on_signals, stop_requested
from drill_sim_ros.model import analysis, telemetry
from drill_sim_ros.model import kernel as k
from drill_sim_ros.model.bit_rock import LAWS, RGD07_LAW, BitLaw
from drill_sim_ros.model.checks import check_blade_counts
from drill_sim_ros.model.errors import DrillSimError
from drill_sim_ros.model.params import GROUPS, UNIT_SCALES, DimensionlessParams, Scales
from drill_sim_ros.model.presets import DEFAULT_PRESET, Preset, available_presets, load_preset
from drill_sim_ros.model.simulator import SimConfig, Simulator
from drill_sim_ros.model.top_drive import (
    MODES,
    TopDrive,
    TopDrivePhysical,
    limit_of_setting,
    paper_drive,
)
from drill_sim_ros.plot_file import remove_unfinished
from drill_sim_ros.study import cli as study_cli
from drill_sim_ros.study import suite_cli
from drill_sim_ros.terminal import StatusLine

TRACE_COLUMNS = ("tau", "omega", "v", "wob", "tob", "depth_of_cut", "surface_torque", "mode")
TRACE_SI_COLUMNS = ("time_s", "bit_rpm", "rop_m_s", "wob_n", "tob_nm", "depth_of_cut_m",
                    "surface_torque_nm")
# The telemetry fields behind TRACE_SI_COLUMNS (ROP in m/s, speeds in rev/min).
TRACE_SI_FIELDS = ("sim_time_s", "bit_rpm", "rop_m_s", "wob_n", "tob_nm", "depth_of_cut_m",
                   "surface_torque_nm")
CHUNK_STEPS = 500_000
MAX_STEPS = 1e10           # about 3 min of the kernel at ~16 ns per step
MAX_SWEEP_VALUES = 10_000


@dataclass(frozen=True)
class RunSpec:
    """Everything a run needs, validated."""

    params: DimensionlessParams
    scales: Scales
    physical: bool
    tau_end: float
    dtau: float
    average_from: float
    perturb_v: float
    perturb_omega: float
    method: str
    n_nodes: int
    top_drive: TopDrive
    motor_torque: float | None
    bit_law: BitLaw = RGD07_LAW          # the preset's (Preset.bit_law); RGD07's without one


# ---- argument parsing ---------------------------------------------------------------------
def _add_model_args(p: argparse.ArgumentParser) -> None:
    g = p.add_argument_group("model (dimensionless groups, RGD07 eqs. 23-24)")
    g.add_argument("--params", help="preset name or YAML file (config/presets/*.yaml); "
                   "a physical preset makes the run report SI units too")
    g.add_argument("--n", type=int, help="number of blades (default 6)")
    g.add_argument("--psi", type=float, help="system number psi (default 50)")
    g.add_argument("--beta", type=float, help="bit-rock number beta (default 0.3)")
    g.add_argument("--lam", type=float, help="bluntness lambda (default 5)")
    g.add_argument("--w0", type=float, help="applied weight W0 (default 7)")
    g.add_argument("--omega0", type=float, help="top-drive speed omega0 (default 5)")
    d = p.add_argument_group("top drive (RGD07 eq. 12 extended; the paper's scaling: torque "
                             "unit C, time unit t*)")
    d.add_argument("--top-drive", choices=MODES, help="kinematic: the paper's imposed speed "
                   "(default of the dimensionless presets); speed: PI speed loop; torque: "
                   "constant motor torque")
    d.add_argument("--drive-inertia-ratio", type=float, help="J / I (default 14)")
    d.add_argument("--drive-kp", type=float, help="speed loop kp_SI / (C t*) (default 83)")
    d.add_argument("--drive-ki", type=float, help="speed loop ki_SI / C (default 123)")
    d.add_argument("--drive-max-torque-nm", type=float, help="motor torque limit, N m (in "
                   "SI, scaled once by the preset's C; 0 or inf: none; default: the preset's, "
                   "else none)")
    d.add_argument("--motor-torque", type=float, help="torque mode: motor torque / C "
                   "(default: the trivial torque T0, held)")
    r = p.add_argument_group("run")
    r.add_argument("--tau-end", type=float, default=None,
                   help="end of the run, dimensionless time (default 600)")
    r.add_argument("--t-end", type=float, default=None, help="end of the run in seconds "
                   "(physical presets only)")
    r.add_argument("--dtau", type=float, default=None, help="time step (default: the preset's, "
                   "else 1e-4)")
    r.add_argument("--average-from", type=float, default=None,
                   help="averages over [average-from, tau-end] (default tau-end / 2)")
    r.add_argument("--perturb-v", type=float, default=0.01,
                   help="added to the trivial axial velocity at tau = 0 (default 0.01)")
    r.add_argument("--perturb-omega", type=float, default=0.0,
                   help="added to the trivial angular velocity at tau = 0 (default 0)")
    r.add_argument("--method", choices=("profile", "exact"), default="profile",
                   help="delay evaluation: bottom-hole profile (default) or exact history")
    r.add_argument("--nodes", type=int, default=None, help="profile nodes per blade sector")
    r.add_argument("--progress", action="store_true", help="progress bar even when stderr "
                   "is not a terminal")


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="drill_sim", description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="command", required=True)
    run = sub.add_parser("run", help="one run; summary or --json")
    _add_model_args(run)
    run.add_argument("--json", action="store_true", help="print one JSON object")
    run.add_argument("--trace", type=Path, help="write samples to this CSV file (a new file)")
    run.add_argument("--overwrite", action="store_true", help="replace an existing --trace file")
    run.add_argument("--trace-every", type=int, default=100, help="a trace row every K steps")
    sweep = sub.add_parser("sweep", help="repeat a run over values of one group; JSON lines")
    _add_model_args(sweep)
    sweep.add_argument("--vary", required=True, choices=GROUPS, help="group to vary")
    sweep.add_argument("--values", required=True,
                       help="comma-separated values, or start:stop:count")
    sub.add_parser("presets", help="list the presets")
    params = sub.add_parser("params", help="every sim_node parameter: type, unit, range, "
                            "default, runtime-changeable (what `ros2 param describe` shows)")
    params.add_argument("--preset", default=DEFAULT_PRESET,
                        help="take the physical defaults from this preset")
    params.add_argument("--json", action="store_true", help="one JSON list, not a table")
    closed_loop_cli.add_parser(sub)
    info = sub.add_parser("info", help="groups, scales and stability of a preset")
    info.add_argument("preset", nargs="?", default="field_8p5in_shale")
    study_cli.add_parsers(sub, _add_model_args)
    string_cli.add_parsers(sub)
    stability_cli.add_parser(sub)
    startup_cli.add_parser(sub)
    torque_drag_cli.add_parser(sub)
    fit_cli.add_parser(sub)
    suite_cli.add_parser(sub)
    return parser


def _resolve(args: argparse.Namespace) -> RunSpec:
    """Turn parsed arguments into a validated :class:`RunSpec`."""
    preset: Preset | None = load_preset(args.params) if args.params else None
    base = preset.params if preset else DimensionlessParams()
    overrides = {g: getattr(args, g) for g in GROUPS if getattr(args, g) is not None}
    params = base.with_(**overrides) if overrides else base
    scales = preset.scales if preset else UNIT_SCALES
    physical = bool(preset and preset.is_physical)
    tau_end = _tau_end(args, scales, physical)
    dtau = args.dtau if args.dtau is not None else (preset.dtau if preset else 1e-4)
    nodes = args.nodes or (preset.n_nodes if preset and preset.n_nodes else None)
    average_from = tau_end / 2.0 if args.average_from is None else args.average_from
    if not 0.0 <= average_from <= tau_end:
        raise DrillSimError(f"--average-from = {average_from!r} must lie in [0, tau-end = "
                            f"{tau_end!r}]")
    config = SimConfig(dtau=dtau, method=args.method, **({"n_nodes": nodes} if nodes else {}))
    if tau_end / config.dtau > MAX_STEPS:
        raise DrillSimError(f"--tau-end = {tau_end:g} (--t-end) at dtau = {config.dtau:g} is "
                            f"{tau_end / config.dtau:.3g} steps; at most {MAX_STEPS:.0e} (a "
                            "few minutes of the kernel): shorten the run or raise --dtau")
    return RunSpec(params, scales, physical, tau_end, config.dtau, average_from,
                   args.perturb_v, args.perturb_omega, args.method, config.n_nodes,
                   _top_drive(args, preset.drive if preset else paper_drive(scales), scales),
                   args.motor_torque, preset.bit_law if preset else RGD07_LAW)


def _top_drive(args: argparse.Namespace, base: TopDrivePhysical, scales: Scales) -> TopDrive:
    """The preset's drive (SI) with the command line's changes: its torque limit in N m
    (``limit_of_setting``: 0 is none) before the one scaling, the scaled flags after it."""
    limit_nm = args.drive_max_torque_nm
    if limit_nm is not None:
        if not limit_nm >= 0.0:
            raise DrillSimError(f"--drive-max-torque-nm = {limit_nm!r} must be >= 0 N m (0 or "
                                "inf: no limit)")
        base = replace(base, max_torque_nm=limit_of_setting(limit_nm))
    changes = {name: value for name, value in (
        ("mode", args.top_drive), ("inertia_ratio", args.drive_inertia_ratio),
        ("kp", args.drive_kp), ("ki", args.drive_ki)) if value is not None}
    drive = base.scaled(scales)
    return drive.with_(**changes) if changes else drive


def _tau_end(args: argparse.Namespace, scales: Scales, physical: bool) -> float:
    if args.t_end is not None:
        if not physical:
            raise DrillSimError("--t-end needs a physical preset (--params); use --tau-end")
        if not (math.isfinite(args.t_end) and args.t_end > 0.0):
            raise DrillSimError(f"--t-end = {args.t_end!r} must be a positive number of s")
        tau_end = args.t_end / scales.time_s
    else:
        tau_end = 600.0 if args.tau_end is None else args.tau_end
    if not (math.isfinite(tau_end) and tau_end > 0.0):
        raise DrillSimError(f"--tau-end = {tau_end!r} must be a positive number")
    return tau_end


# ---- running ------------------------------------------------------------------------------
class Progress:
    """A one-line progress bar on stderr (only when asked or on a terminal)."""

    def __init__(self, total: int, enabled: bool) -> None:
        self.total = total
        self.line = StatusLine(force=enabled) if enabled else StatusLine()
        self.start = time.perf_counter()

    def update(self, done: int) -> None:
        frac = done / self.total if self.total else 1.0
        elapsed = time.perf_counter() - self.start
        eta = elapsed * (1.0 - frac) / frac if frac > 0 else math.inf
        self.line.show(f"[{'#' * int(30 * frac):<30}] {100 * frac:5.1f}%  "
                       f"{done:,}/{self.total:,} steps  eta {eta:5.1f} s")

    def close(self) -> None:
        self.line.close()


def _chunks(total: int, size: int) -> Iterator[int]:
    while total > 0:
        step = min(size, total)
        total -= step
        yield step


def simulate(spec: RunSpec, trace: TextIO | None = None, trace_every: int = 100,
             progress: bool = False) -> dict[str, Any]:
    """Run ``spec`` and return the summary dictionary (the ``--json`` object)."""
    sim = Simulator(spec.params, SimConfig(dtau=spec.dtau, n_nodes=spec.n_nodes,
                                           method=spec.method, tau_avg=spec.average_from),
                    perturb_v=spec.perturb_v, perturb_omega=spec.perturb_omega,
                    top_drive=spec.top_drive, scales=spec.scales, bit_law=spec.bit_law)
    if spec.motor_torque is not None:
        sim.set_inputs(motor_torque=spec.motor_torque)
    root = analysis.rightmost_root(spec.params)     # before the run, so it cannot lose it
    sim.advance(0, every=1)               # compile (or load from cache) outside the timing
    total = sim.steps_for(spec.tau_end)
    writer = _trace_writer(trace, spec) if trace else None
    bar = Progress(total, progress)
    kernel_seconds = 0.0
    for n in _chunks(total, CHUNK_STEPS):
        t0 = time.perf_counter()
        samples = sim.advance(n, every=trace_every if writer else 0)
        kernel_seconds += time.perf_counter() - t0
        if writer:
            _write_trace(writer, samples, spec)
        bar.update(sim.steps)
    bar.close()
    return summarize(spec, sim, kernel_seconds, root)


def summarize(spec: RunSpec, sim: Simulator, kernel_seconds: float,
              root: complex) -> dict[str, Any]:
    """The run's figures: events, cycle averages (eqs. 42-48), stability (App. B: ``root``)."""
    p = spec.params
    acc = sim.accumulators
    avg = analysis.cycle_averages(p, acc)
    stick, bounce = analysis.first_event_tau(acc)
    triv = sim.trivial                   # eq. 34, its torque the bit law's
    sev = analysis.severity_of(avg.omega_min, avg.omega_max, avg.mean_omega, p.omega0)
    out: dict[str, Any] = {
        "params": {g: getattr(p, g) for g in GROUPS},
        "tau_end": spec.tau_end, "dtau": spec.dtau, "average_from": spec.average_from,
        "method": spec.method, "nodes": spec.n_nodes,
        "top_drive": {"mode": spec.top_drive.mode,
                      "inertia_ratio": spec.top_drive.inertia_ratio,
                      "kp": spec.top_drive.kp, "ki": spec.top_drive.ki,
                      "max_torque": spec.top_drive.max_torque},
        "first_stick_tau": stick, "bounce_tau": bounce,
        "stick_fraction": avg.stick_fraction, "kappa": avg.kappa,
        "kappa_from_depth": analysis.kappa_from_depth(avg.mean_depth_of_cut,
                                                      triv.depth_of_cut, p.lam),
        "eta": avg.eta,
        "mean_torque": avg.mean_torque, "mean_depth_of_cut": avg.mean_depth_of_cut,
        "mean_wob": avg.mean_wob, "mean_omega": avg.mean_omega,
        "mean_pipe_torque": avg.mean_pipe_torque, "mean_rop": avg.mean_rop,
        "specific_energy": avg.specific_energy, "drilling_strength": avg.drilling_strength,
        "omega_min": avg.omega_min, "omega_max": avg.omega_max, "ssi": sev.ssi, "utr": sev.utr,
        "trivial_torque": triv.torque, "trivial_depth_of_cut": triv.depth_of_cut,
        "trivial_rop": triv.v, "trivial_delay": analysis.trivial_delay(p),
        "critical_delay": analysis.critical_delay(p),
        "growth_rate": root.real, "growth_frequency": root.imag,
        "steps": sim.steps, "kernel_seconds": kernel_seconds,
        "ns_per_step": 1e9 * kernel_seconds / sim.steps if sim.steps else None,
    }
    if spec.physical:
        out["si"] = _si_summary(spec.scales, out)
    return {key: _clean(value) for key, value in out.items()}


def _si_summary(sc: Scales, d: dict[str, Any]) -> dict[str, Any]:
    def t(x: float | None) -> float | None:
        return None if x is None else x * sc.time_s
    return {
        "t_star_s": sc.time_s, "l_star_m": sc.length_m,
        "first_stick_s": t(d["first_stick_tau"]), "bounce_s": t(d["bounce_tau"]),
        "mean_tob_nm": sc.tob_nm(d["mean_torque"]), "mean_wob_n": sc.wob_n(d["mean_wob"]),
        "mean_rop_m_per_h": sc.rop_m_s(d["mean_rop"]) * 3600.0,
        "mean_depth_of_cut_mm": d["mean_depth_of_cut"] * sc.length_m * 1e3,
        "bit_rpm_min": sc.rpm(d["omega_min"]), "bit_rpm_max": sc.rpm(d["omega_max"]),
        "mean_bit_rpm": sc.rpm(d["mean_omega"]),
    }


def _clean(value: Any) -> Any:
    """JSON-safe: numpy scalars to float, NaN/inf to None."""
    if isinstance(value, dict):
        return {k_: _clean(v) for k_, v in value.items()}
    if hasattr(value, "item"):
        value = value.item()
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value


# ---- trace --------------------------------------------------------------------------------
def _trace_writer(stream: TextIO, spec: RunSpec) -> Any:
    writer = csv.writer(stream)
    writer.writerow(TRACE_COLUMNS + (TRACE_SI_COLUMNS if spec.physical else ()))
    return writer


def _write_trace(writer: Any, samples: Any, spec: RunSpec) -> None:
    cols = [samples.column(c) for c in (k.C_TAU, k.C_OMEGA, k.C_V, k.C_WOB, k.C_TOB,
                                        k.C_DOC, k.C_T_PIPE, k.C_MODE)]
    si = None
    if spec.physical:
        rows = telemetry.si_rows(samples.data, (samples.depth_offset, samples.angle_offset),
                                 telemetry.field_scales(spec.scales),
                                 cols[0] * spec.scales.time_s, 0.0)
        si = rows[:, [telemetry.TELEMETRY_INDEX[name] for name in TRACE_SI_FIELDS]]
    for i in range(len(samples)):
        row = [f"{c[i]:.10g}" for c in cols[:-1]] + [int(cols[-1][i])]
        if si is not None:
            row += [f"{x:.10g}" for x in si[i]]
        writer.writerow(row)


# ---- output -------------------------------------------------------------------------------
def format_summary(d: dict[str, Any]) -> str:
    """A readable multi-line summary of :func:`simulate`'s dictionary."""
    def f(x: Any, fmt: str = ".4g") -> str:
        return "none" if x is None else format(x, fmt)
    p = d["params"]
    lines = [
        "drill_sim run  (Richard, Germay & Detournay 2007)",
        "  groups      " + "  ".join(f"{g}={p[g]:g}" for g in GROUPS),
        f"  numerics    dtau={d['dtau']:g}  tau_end={d['tau_end']:g}  method={d['method']}  "
        f"steps={d['steps']:,}  kernel {f(d['kernel_seconds'], '.3f')} s "
        f"({f(d['ns_per_step'], '.1f')} ns/step)",
        f"  top drive   {d['top_drive']['mode']}  J/I={f(d['top_drive']['inertia_ratio'])}  "
        f"kp={f(d['top_drive']['kp'])}  ki={f(d['top_drive']['ki'])}  "
        f"max torque={f(d['top_drive']['max_torque'])}",
        f"  stability   tau_n0={f(d['trivial_delay'])}  critical={f(d['critical_delay'])}  "
        f"growth rate={f(d['growth_rate'])}  frequency={f(d['growth_frequency'])}",
        f"  events      first stick tau={f(d['first_stick_tau'])}  "
        f"first bounce tau={f(d['bounce_tau'])}",
        f"  averages    over tau in [{d['average_from']:g}, {d['tau_end']:g}]",
        f"    kappa={f(d['kappa'])} (from <delta>, eq. 45a: {f(d['kappa_from_depth'])})  "
        f"eta={f(d['eta'])}  stick fraction={f(d['stick_fraction'])}",
        f"    <T>={f(d['mean_torque'])} (trivial {f(d['trivial_torque'])})  "
        f"<delta>={f(d['mean_depth_of_cut'])} (trivial {f(d['trivial_depth_of_cut'])})  "
        f"<W>={f(d['mean_wob'])}",
        f"    omega in [{f(d['omega_min'])}, {f(d['omega_max'])}]  SSI={f(d['ssi'])}  "
        f"E={f(d['specific_energy'])}  S={f(d['drilling_strength'])}",
    ]
    if "si" in d:
        si = d["si"]
        lines += [
            f"  SI          t*={si['t_star_s']:.4g} s  L*={si['l_star_m'] * 1e3:.4g} mm  "
            f"first stick {f(si['first_stick_s'])} s",
            f"    bit rpm {f(si['bit_rpm_min'], '.1f')}..{f(si['bit_rpm_max'], '.1f')} "
            f"(mean {f(si['mean_bit_rpm'], '.1f')})  <TOB>={f(si['mean_tob_nm'], '.4g')} N m  "
            f"<WOB>={f(si['mean_wob_n'], '.4g')} N  ROP={f(si['mean_rop_m_per_h'], '.3g')} m/h",
        ]
    return "\n".join(lines)


def _sweep_values(text: str) -> list[float]:
    try:
        if ":" in text:
            start, stop, count = text.split(":")
            n = int(count)
            if not 1 <= n <= MAX_SWEEP_VALUES:
                raise DrillSimError(f"--values {text!r}: COUNT = {n} must be in "
                                    f"[1, {MAX_SWEEP_VALUES}]")
            return [float(start) + i * (float(stop) - float(start)) / max(n - 1, 1)
                    for i in range(n)]
        return [float(x) for x in text.split(",") if x.strip()]
    except ValueError:
        raise DrillSimError(f"--values {text!r}: expected V1,V2,... or START:STOP:COUNT "
                            "(numbers)") from None


def _cmd_run(args: argparse.Namespace) -> int:
    spec = _resolve(args)
    progress = args.progress or sys.stderr.isatty()
    if args.trace:
        trace = open_output(args.trace, args.overwrite)      # refused before the run
        with io.TextIOWrapper(trace, encoding="utf-8", newline="") as stream:
            result = simulate(spec, stream, args.trace_every, progress)
    else:
        result = simulate(spec, progress=progress)
    print(json.dumps(result) if args.json else format_summary(result))
    return 0


def _cmd_sweep(args: argparse.Namespace) -> int:
    values = _sweep_values(args.values)
    if args.vary == "n":
        check_blade_counts(values, f"--values {args.values!r}")
    progress = args.progress or sys.stderr.isatty()
    for value in values:
        setattr(args, args.vary, int(value) if args.vary == "n" else value)
        result = simulate(_resolve(args), progress=progress)
        print(json.dumps(result), flush=True)
    return 0


def _cmd_info(args: argparse.Namespace) -> int:
    preset = load_preset(args.preset)
    p = preset.params
    print(f"{preset.name}: {preset.description}")
    print("  groups  " + "  ".join(f"{g}={getattr(p, g):.4g}" for g in GROUPS))
    for fld in fields(preset.scales):
        print(f"  {fld.name:10s} {getattr(preset.scales, fld.name):.6g}")
    drive = preset.top_drive
    print(f"  top drive {drive.mode}: J/I={drive.inertia_ratio:.4g}  kp={drive.kp:.4g}  "
          f"ki={drive.ki:.4g}  max torque={drive.max_torque:.4g} (units of C, t*)")
    weakening = preset.friction_weakening
    print("  bit law rgd07" if weakening is None else
          f"  bit law {LAWS[preset.bit_law.law]}: floor ratio {weakening.floor_ratio:.4g}, "
          f"{weakening.speed_rad_s:.4g} rad/s, read through a {weakening.response_s:.4g} s lag")
    if preset.depth_of_cut_limit is not None:
        print(f"  depth-of-cut limit {1e3 * preset.depth_of_cut_limit.max_depth_m_per_rev:.4g} "
              f"mm per revolution, its contact's beta {preset.bit_law.beta_limit:.4g}")
    root = analysis.rightmost_root(p)
    print(f"  tau_n0={analysis.trivial_delay(p):.4g}  critical delay="
          f"{analysis.critical_delay(p):.4g}  rightmost root={root.real:.4g}+{root.imag:.4g}i")
    return 0


STOP_GRACE_S = 10.0    # after SIGTERM or SIGHUP, the longest a command may take to unwind


def main(argv: Sequence[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    # SIGTERM and SIGHUP stop a command as Ctrl-C does (every ``finally`` runs); the outputs
    # under way (--plot's temporary file, the directories made for it) go at once
    with stop_on_signals(remove_unfinished, STOP_GRACE_S):
        code = _main(args)
    if stop_requested():
        _end_now(code)
    return code


def _end_now(code: int) -> NoReturn:
    """End a command stopped by a signal without the interpreter's finalizers, once every
    ``finally`` has run and the outputs under way are removed: a stop that tore numba's
    compiler mid-work leaves LLVM objects that can crash in them (status -11 after
    "interrupted", seen 2026-12-07 in tests/robust/test_gateway_and_leftovers.py under
    `make test`'s two workers, a cold compile on a loaded machine)."""
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(code)


def _main(args: argparse.Namespace) -> int:
    try:
        if args.command == "presets":
            for name in available_presets():
                print(f"{name:22s} {load_preset(name).description.splitlines()[0]}")
            return 0
        if args.command == "params":             # imports rclpy: only when asked
            from drill_sim_ros.ros import parameter_list
            return parameter_list.run(args)
        if args.command == "map":
            return study_cli.cmd_map(args, _resolve)
        return {"run": _cmd_run, "sweep": _cmd_sweep, "info": _cmd_info,
                "closed-loop": closed_loop_cli.cmd_closed_loop,
                "suite": suite_cli.cmd_suite,
                "map-plot": study_cli.cmd_map_plot,
                "figures": study_cli.cmd_figures, "modes": string_cli.cmd_modes,
                "reflection": string_cli.cmd_reflection,
                "stability": stability_cli.cmd_stability,
                "startup": startup_cli.cmd_startup,
                "torque-drag": torque_drag_cli.cmd_torque_drag,
                "fit": fit_cli.cmd_fit}[args.command](args)
    except DrillSimError as exc:
        print(f"drill_sim: error: {' '.join(str(exc).splitlines())}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        return _interrupted(args.command)
    except BrokenPipeError:        # the reader went away (`drill_sim params | head`)
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())   # no flush error
        return 128 + signal.SIGPIPE
    except Exception:
        if stop_requested():      # numba's compiler, torn by the stop, re-raises it as an
            return _interrupted(args.command)   # error of its own (RuntimeError)
        raise


def _interrupted(command: str) -> int:
    print(f"drill_sim {command}: interrupted", file=sys.stderr)
    return 130


if __name__ == "__main__":
    sys.exit(main())
