"""``drill_sim suite``: every controller x scenario of config/scenarios on Dask, the league
table printed and written (wired in by :mod:`drill_sim_ros.cli`)."""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path
from typing import Any

from drill_sim_ros.control.controllers import CONTROL_MODES
from drill_sim_ros.control.scenario import ensemble_caption
from drill_sim_ros.terminal import StatusLine


def add_parser(sub: Any) -> None:
    p = sub.add_parser("suite", help="a league table: controllers x scenarios (Dask)")
    p.add_argument("--controller", action="append", default=None, metavar="NAME",
                   help="none | stiff | soft_torque | z_torque | package.module:Class "
                        "(repeatable; default: none, stiff, soft_torque, z_torque)")
    p.add_argument("--mode", choices=CONTROL_MODES, default="speed",
                   help="speed: the controllers send the speed setpoint; torque: the motor "
                        "torque ('none' always runs the drive's own speed loop; default "
                        "speed)")
    p.add_argument("--scenario", action="append", default=None, metavar="NAME|FILE",
                   help="only this scenario (a name of config/scenarios or a YAML file; "
                        "repeatable; default: all of config/scenarios)")
    p.add_argument("--out", type=Path, required=True,
                   help="results directory; a re-run with the same one resumes")
    p.add_argument("--scheduler", help="address of an existing Dask scheduler "
                   "(tcp://HOST:PORT); default: a local cluster on 127.0.0.1")
    p.add_argument("--workers", type=int, default=None,
                   help="local worker processes (default: one per core)")
    p.add_argument("--ensemble", type=int, default=1, metavar="N",
                   help="run every controller x scenario N times (1-64), member k with the "
                        "bit's sigma l x (1 + k 1e-12): the spread of a chaotic case; "
                        "member 0 is the plain run (default 1)")
    p.add_argument("--no-pictures", action="store_true",
                   help="skip the report's pictures (matplotlib)")


def cmd_suite(args: argparse.Namespace) -> int:
    from drill_sim_ros.control.registry import controller_class
    from drill_sim_ros.study import engine, suite, suite_report
    controllers = args.controller or list(suite.DEFAULT_CONTROLLERS)
    for name in controllers:
        controller_class(name)                     # a bad name fails here, in one line
    entries = suite.ensemble(suite.entries(suite.scenario_files(args.scenario or ()),
                                           controllers, args.mode), args.ensemble)
    line = StatusLine()
    def progress(done: int, total: int) -> None:
        line.show(f"drill_sim suite: {done}/{total} runs")
    start = time.perf_counter()
    try:
        with engine.connect(args.scheduler, args.workers) as client:
            result = suite.run_suite(entries, args.out, client, suite.code_fingerprint(),
                                     progress)
    except KeyboardInterrupt:
        result = None
    finally:
        line.close()
    if result is None or result.interrupted:
        print(f"drill_sim suite: interrupted; the runs done are kept in {args.out}; re-run "
              "the same command to resume")
        return 130
    wall_s = time.perf_counter() - start
    print(suite_report.format_table(suite_report.plain(entries), result.results))
    if args.ensemble > 1:
        print("\n" + ensemble_caption(args.ensemble))
        print(suite_report.format_ensemble_table(entries, result.results))
    written = suite_report.write_outputs(args.out, entries, result.results, wall_s,
                                         pictures=not args.no_pictures)
    print(f"drill_sim suite: {len(entries)} runs ({result.computed} computed now) in "
          f"{wall_s:.1f} s; wrote {', '.join(str(p) for p in written[:2])} and "
          f"{args.out / 'report.md'}", file=sys.stdout)
    return 0

