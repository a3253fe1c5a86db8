"""``drill_sim map``, ``drill_sim map-plot`` and ``drill_sim figures`` (wired in by
:mod:`drill_sim_ros.cli`, which lends its model options and their resolution)."""

from __future__ import annotations

import argparse
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any

from drill_sim_ros.archive.output import check_output, commit, temporary_beside
from drill_sim_ros.model.errors import DrillSimError
from drill_sim_ros.study.progress import MapProgress

if TYPE_CHECKING:
    from drill_sim_ros.study.grid import MapSpec

def add_parsers(sub: Any, add_model_args: Callable[[argparse.ArgumentParser], None]) -> None:
    """The three sub-commands on the ``drill_sim`` sub-parser ``sub``."""
    _add_map_parser(sub, add_model_args)
    _add_map_plot_parser(sub)
    _add_figures_parser(sub)


def _add_map_parser(sub: Any,
                    add_model_args: Callable[[argparse.ArgumentParser], None]) -> None:
    """``drill_sim map``: the model's options, the grid, the Dask cluster, the closed loop."""
    m = sub.add_parser("map", help="regime map over a grid of parameters (Dask), to NetCDF")
    add_model_args(m)
    m.add_argument("--vary", action="append", required=True, metavar="NAME=START:STOP:COUNT",
                   help="a varied axis (repeat for a grid): n, psi, beta, lam, w0, omega0, "
                        "w0_ratio (= W0/lam, lam held); physical presets also surface_rpm "
                        "[rpm] and wob_n [N]. Values also as NAME=V1,V2,...")
    m.add_argument("--out", type=Path, default=Path("map.nc"),
                   help="NetCDF file (default map.nc); a re-run with the same file resumes")
    m.add_argument("--scheduler", help="address of an existing Dask scheduler "
                   "(tcp://HOST:PORT); default: a local cluster on 127.0.0.1")
    m.add_argument("--workers", type=int, default=None,
                   help="local worker processes (default: one per core)")
    m.add_argument("--batch", type=int, default=None, help="points per task (default: "
                   "about 8 tasks per worker, at most 64 points)")
    c = m.add_argument_group("closed loop (physical presets; axes surface_rpm and wob_n)")
    c.add_argument("--controller", default=None, help="run every point closed-loop with this "
                   "controller in process (none | stiff | soft_torque | z_torque | "
                   "package.module:Class); default: the open-loop model")
    c.add_argument("--mode", choices=("speed", "torque"), default="speed",
                   help="the controller sends the speed setpoint or the motor torque "
                        "(default speed)")
    c.add_argument("--enable-at", type=float, default=0.0, metavar="S",
                   help="switch-on time of the controller, s (default 0)")


def _add_map_plot_parser(sub: Any) -> None:
    """``drill_sim map-plot``: a map file drawn as a PNG."""
    p = sub.add_parser("map-plot", help="draw a map file (regime map or one variable)")
    p.add_argument("map", type=Path, help="NetCDF file written by drill_sim map")
    p.add_argument("-o", "--output", type=Path, default=None, help="PNG (default: MAP.png)")
    p.add_argument("--overwrite", action="store_true", help="replace an existing --output")
    p.add_argument("--var", default="regime", help="variable to draw (default regime)")
    p.add_argument("--at", action="append", default=[], metavar="NAME=VALUE",
                   help="for maps of more than two axes: the value of an extra axis "
                        "(nearest point)")


def _add_figures_parser(sub: Any) -> None:
    """``drill_sim figures``: the paper's figures regenerated."""
    f = sub.add_parser("figures", help="regenerate the paper's figures (PNG gallery)")
    f.add_argument("-o", "--output", type=Path, default=Path("docs/gallery"),
                   help="directory of the PNGs (default docs/gallery)")
    f.add_argument("--cache", type=Path, default=None, help="keep the figures' maps here "
                   "and resume them (default: compute afresh in a temporary directory)")
    f.add_argument("--only", action="append", default=None, help="only this figure "
                   "(repeatable; names as the PNG files without .png)")
    f.add_argument("--scheduler", help="existing Dask scheduler (tcp://HOST:PORT)")
    f.add_argument("--workers", type=int, default=None, help="local worker processes")


def map_spec_from(args: argparse.Namespace,
                  resolve: Callable[[argparse.Namespace], Any]) -> MapSpec:
    """A :class:`MapSpec` from the ``map`` options; ``resolve`` is ``drill_sim run``'s."""
    from drill_sim_ros.model.presets import load_preset
    from drill_sim_ros.study.grid import Control, MapSpec, Numerics, parse_vary
    control = None
    if args.controller is not None:
        from drill_sim_ros.control.registry import controller_class
        controller_class(args.controller)            # a bad name fails here, in one line
        control = Control(args.controller, args.mode, args.enable_at)
    run = resolve(args)
    num = Numerics(tau_end=run.tau_end, average_from=run.average_from, dtau=run.dtau,
                   n_nodes=run.n_nodes, method=run.method, perturb_v=run.perturb_v,
                   perturb_omega=run.perturb_omega)
    name = load_preset(args.params).name if args.params else ""
    return MapSpec(run.params, tuple(parse_vary(v) for v in args.vary), num,
                   scales=run.scales if run.physical else None, preset=name,
                   control=control)


def cmd_map(args: argparse.Namespace, resolve: Callable[[argparse.Namespace], Any]) -> int:
    if args.batch is not None and not 1 <= args.batch <= 100_000:
        raise DrillSimError(f"--batch = {args.batch} must be in [1, 100000]")
    from drill_sim_ros.study import engine, store
    spec = map_spec_from(args, resolve)
    bar = MapProgress(args.progress or _isatty())
    try:
        with store.map_lock(args.out), engine.connect(args.scheduler, args.workers) as client:
            result = engine.run_map(spec, args.out, client, progress=bar, batch=args.batch,
                                    log=bar.say)
    except KeyboardInterrupt:
        result = None
    finally:
        bar.close()
    if result is None or result.interrupted:
        kept = f"the points done are kept in {args.out}" if args.out.exists() else \
            "no point was done"
        print(f"drill_sim map: interrupted; {kept}; re-run the same command to resume",
              file=sys.stderr)
        return 130
    done = int(result.dataset["done"].sum())
    rate = result.computed / result.seconds if result.seconds > 0 else 0.0
    print(f"drill_sim map: {done}/{result.total} points in {args.out} "
          f"({result.computed} computed now in {result.seconds:.1f} s, {rate:.2f} points/s)")
    return 0


def cmd_map_plot(args: argparse.Namespace) -> int:
    from drill_sim_ros.study import plot, store
    ds = store.load(args.map)
    out = check_output(args.output or args.map.with_suffix(".png"), args.overwrite)
    at = dict(_parse_at(text) for text in args.at)
    temporary = temporary_beside(out, args.overwrite, keep_suffix=True)
    try:
        plot.plot_file(ds, args.var, temporary, at)
        commit(temporary, out, args.overwrite)
    finally:
        temporary.unlink(missing_ok=True)
    print(f"drill_sim map-plot: wrote {out}")
    return 0


def cmd_figures(args: argparse.Namespace) -> int:
    from drill_sim_ros.study import figures
    t0 = time.perf_counter()
    try:
        written = figures.make_all(args.output, cache=args.cache, only=args.only,
                                   scheduler=args.scheduler, workers=args.workers,
                                   progress=_isatty(), log=print)
    except KeyboardInterrupt:
        kept = f"; the maps done are kept in {args.cache}" if args.cache else ""
        print(f"drill_sim figures: interrupted{kept}")
        return 130
    for path in written:
        print(f"wrote {path}")
    print(f"drill_sim figures: {len(written)} figures in {time.perf_counter() - t0:.0f} s")
    return 0


def _parse_at(text: str) -> tuple[str, float]:
    name, sep, value = text.partition("=")
    try:
        if not sep:
            raise ValueError(text)
        return name.strip(), float(value)
    except ValueError as exc:
        raise DrillSimError(f"--at {text!r}: expected NAME=VALUE") from exc


def _isatty() -> bool:
    import sys
    return sys.stderr.isatty()
