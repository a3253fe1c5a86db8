"""``mcap_to_rerun FILE.mcap -o FILE.rrd``: a recorded run as the drilling dashboard.

The same views as the live bridge (:class:`~drill_sim_ros.viz.dashboard.Dashboard`), from the
``/drill/telemetry`` messages of the file, on the ``sim_time`` timeline of their own
``sim_time_s`` field: the MCAP log time (simulated time from a wall-clock start in an in-process
recording, receipt time in an ``mcap_recorder`` file) is not used, so both files of one run
give the same dashboard. The file is read twice: first to frame the 2D views by the data.

A damaged or cut recording gives what ``mcap_reindex`` would keep (every intact chunk), with
one warning naming what was skipped, and exit code 1. The .rrd is written beside its target
and moved in place only when complete: an error or SIGINT/SIGTERM/SIGHUP leaves no partial
file. An existing .rrd is refused unless ``--overwrite``. Turns rerun's analytics off first.
"""

from __future__ import annotations

import argparse
import logging
import math
import sys
from pathlib import Path

from drill_sim_ros import topics
from drill_sim_ros.archive.errors import ArchiveError
from drill_sim_ros.archive.output import commit, temporary_beside
from drill_sim_ros.archive.reader import ArchiveReader
from drill_sim_ros.archive.signals import stop_on_signals
from drill_sim_ros.model.errors import ParameterError
from drill_sim_ros.model.presets import DEFAULT_PRESET
from drill_sim_ros.viz.analytics_off import disable_analytics
from drill_sim_ros.viz.blueprint import build_blueprint, has_string_views
from drill_sim_ros.viz.dashboard import Dashboard, data_extents
from drill_sim_ros.viz.frames import view_frames
from drill_sim_ros.viz.mcap_telemetry import (
    NoTelemetryError,
    read_string_profiles,
    read_telemetry,
    recorded_preset,
    recorded_run_info,
)
from drill_sim_ros.viz.paper_units import PaperUnits
from drill_sim_ros.viz.recording import close_recording, open_recording
from drill_sim_ros.viz.running_stats import default_window_s


def parse_args(argv: list[str] | None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(prog="mcap_to_rerun", description=__doc__.splitlines()[0])
    parser.add_argument("mcap", type=Path, help="recorded run (ROS 2 MCAP)")
    parser.add_argument("-o", "--output", type=Path, required=True, help="the .rrd to write")
    parser.add_argument("--preset", default=None,
                        help="model preset for the 2D views' scales (default: the "
                             "recorded /drill/run_info, else the file's 'preset' metadata, "
                             f"else {DEFAULT_PRESET})")
    parser.add_argument("--window-s", type=float, default=None,
                        help="sliding window for E-S and severity, s (default 20 t*)")
    parser.add_argument("--overwrite", action="store_true",
                        help="replace an existing output (default: refuse)")
    args = parser.parse_args(argv)
    if args.window_s is not None and not (math.isfinite(args.window_s) and args.window_s > 0):
        parser.error(f"--window-s = {args.window_s!r} must be a positive number of seconds")
    return args


def convert(mcap: Path, output: Path, preset: str | None = None,
            window_s: float | None = None, overwrite: bool = False,
            reader: ArchiveReader | None = None) -> int:
    """Write ``output`` from ``mcap``; return the number of telemetry samples logged.

    Nothing is left at ``output`` unless it succeeds. Pass ``reader`` to learn afterwards what
    a damaged file lost (its ``problem`` and ``lost_data``).
    """
    reader = reader or ArchiveReader(mcap)
    batches = read_telemetry(reader)
    first = next(batches)                # NoTelemetryError before anything else is said
    units = recorded_units(mcap, preset)
    string = has_string_views(recorded_run_info(mcap))
    window = default_window_s(units) if window_s is None else window_s
    frames = view_frames(units, data_extents(read_telemetry(mcap), units, window))
    temporary = temporary_beside(output, overwrite)
    try:
        rec = open_recording(build_blueprint(window, frames, string), save=temporary)
        try:
            dashboard = Dashboard(rec, units, window, frames)
            dashboard.log_batch(first)
            for batch in batches:
                dashboard.log_batch(batch)
            for profiles in read_string_profiles(reader):
                dashboard.log_strings(profiles)
        finally:
            close_recording(rec)
        commit(temporary, output, overwrite)
    finally:
        temporary.unlink(missing_ok=True)
    return dashboard.samples


def recorded_units(mcap: Path, preset: str | None) -> PaperUnits:
    """The scales of the 2D views: ``preset`` if given, else the recorded run info, else
    the preset named in the file's metadata (recordings made before the run info existed),
    else the default preset, with a warning naming it."""
    if preset:
        return PaperUnits.load(preset)
    info = recorded_run_info(mcap)
    if info is not None:
        return PaperUnits.from_run_info(info)
    recorded = recorded_preset(mcap)
    if recorded:
        return PaperUnits.load(recorded)
    print(f"mcap_to_rerun: warning: {mcap} has no {topics.RUN_INFO} and names no preset; the "
          f"2D views use the scales of preset {DEFAULT_PRESET!r} (override with --preset)",
          file=sys.stderr)
    return PaperUnits.load(DEFAULT_PRESET)


def main(argv: list[str] | None = None) -> int:
    disable_analytics()
    args = parse_args(argv)
    logging.basicConfig(level=logging.ERROR, format="mcap_to_rerun: %(message)s")
    try:
        with stop_on_signals():
            reader = ArchiveReader(args.mcap)
            count = convert(args.mcap, args.output, args.preset, args.window_s,
                            args.overwrite, reader)
    except (OSError, NoTelemetryError, ParameterError, ArchiveError) as exc:
        print(f"mcap_to_rerun: {exc}", file=sys.stderr)
        return 2 if isinstance(exc, (ArchiveError, ParameterError, OSError)) else 1
    except KeyboardInterrupt as exc:
        print(f"mcap_to_rerun: interrupted ({exc or 'SIGINT'}); no {args.output} written",
              file=sys.stderr)
        return 130
    if reader.problem is not None:
        print(f"mcap_to_rerun: warning: {reader.problem}", file=sys.stderr)
    print(f"mcap_to_rerun: {count} telemetry samples -> {args.output}")
    return 1 if reader.lost_data else 0


if __name__ == "__main__":
    sys.exit(main())
