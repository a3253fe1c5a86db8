"""``mcap_to_rerun FILE.mcap -o FILE.rrd``: a recorded run as the drilling dashboard.

The same views as the live bridge (:class:`~drill_sim_ros.viz.dashboard.Dashboard`), from the
``/drill/telemetry`` messages of the file, on the ``sim_time`` timeline of their own
``sim_time_s`` field: the MCAP log time (simulated time from a wall-clock start in an in-process
recording, receipt time in an ``mcap_recorder`` file) is not used, so both files of one run
give the same dashboard. The file is read twice: first to frame the 2D views by the data.
Turns rerun's analytics off first.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from drill_sim_ros.model.errors import ParameterError
from drill_sim_ros.model.presets import DEFAULT_PRESET
from drill_sim_ros.viz.analytics_off import disable_analytics
from drill_sim_ros.viz.blueprint import build_blueprint
from drill_sim_ros.viz.dashboard import Dashboard, data_extents
from drill_sim_ros.viz.frames import view_frames
from drill_sim_ros.viz.mcap_telemetry import NoTelemetryError, read_telemetry, recorded_preset
from drill_sim_ros.viz.paper_units import PaperUnits
from drill_sim_ros.viz.recording import close_recording, open_recording
from drill_sim_ros.viz.running_stats import default_window_s


def parse_args(argv: list[str] | None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(prog="mcap_to_rerun", description=__doc__.splitlines()[0])
    parser.add_argument("mcap", type=Path, help="recorded run (ROS 2 MCAP)")
    parser.add_argument("-o", "--output", type=Path, required=True, help="the .rrd to write")
    parser.add_argument("--preset", default=None,
                        help="model preset for the 2D views' scales (default: the file's "
                             f"'preset' metadata, else {DEFAULT_PRESET})")
    parser.add_argument("--window-s", type=float, default=None,
                        help="sliding window for E-S and severity, s (default 20 t*)")
    return parser.parse_args(argv)


def convert(mcap: Path, output: Path, preset: str | None = None,
            window_s: float | None = None) -> int:
    """Write ``output`` from ``mcap``; return the number of telemetry samples logged."""
    units = PaperUnits.load(preset or recorded_preset(mcap) or DEFAULT_PRESET)
    window = default_window_s(units) if window_s is None else window_s
    frames = view_frames(units, data_extents(read_telemetry(mcap), units, window))
    rec = open_recording(build_blueprint(window, frames), save=output)
    try:
        dashboard = Dashboard(rec, units, window, frames)
        for batch in read_telemetry(mcap):
            dashboard.log_batch(batch)
    finally:
        close_recording(rec)
    return dashboard.samples


def main(argv: list[str] | None = None) -> int:
    disable_analytics()
    args = parse_args(argv)
    try:
        count = convert(args.mcap, args.output, args.preset, args.window_s)
    except (OSError, NoTelemetryError, ParameterError) as exc:
        print(f"mcap_to_rerun: {exc}", file=sys.stderr)
        return 1
    print(f"mcap_to_rerun: {count} telemetry samples -> {args.output}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
