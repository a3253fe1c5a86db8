"""``rerun_bridge [--save FILE.rrd] [--connect URL] [--serve]``: the live drilling dashboard.

A ROS 2 node that subscribes to ``drill/telemetry`` of its namespace (``-r __ns:=/rig1``:
``/rig1/drill/telemetry``; one atomic sample per message, SI) and
logs it on the ``sim_time`` timeline taken from the record's ``sim_time_s``. Queued samples
are taken and sent with ``send_columns`` ``flush_hz`` times a second. ``--serve`` hosts a
gRPC server bound to 127.0.0.1 only. ``--connect`` streams to a viewer through a
:class:`~drill_sim_ros.viz.viewer_link.ViewerLink`: cut while no viewer listens there, re-made
when one does. Turns rerun's analytics off first.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import signal
import sys
import time
import uuid
from dataclasses import dataclass
from typing import Any

import numpy as np
import rclpy
import rerun as rr
from rclpy.clock import Clock, ClockType
from rclpy.context import Context
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.qos import HistoryPolicy, QoSProfile, ReliabilityPolicy
from rclpy.signals import SignalHandlerOptions
from rclpy.utilities import remove_ros_args
from sensor_msgs.msg import JointState
from std_msgs.msg import Float64MultiArray, String

from drill_sim_ros import topics
from drill_sim_ros.archive.output import OutputError, check_output
from drill_sim_ros.model.presets import DEFAULT_PRESET, load_preset
from drill_sim_ros.ros import typed
from drill_sim_ros.ros.messages import RUN_INFO_QOS
from drill_sim_ros.viz.analytics_off import disable_analytics
from drill_sim_ros.viz.blueprint import build_blueprint, has_string_views
from drill_sim_ros.viz.dashboard import Dashboard
from drill_sim_ros.viz.frames import Extents, view_frames
from drill_sim_ros.viz.paper_units import PaperUnits
from drill_sim_ros.viz.recording import (
    DEFAULT_SERVE_MEMORY_MIB,
    DEFAULT_SERVE_PORT,
    DEFAULT_VIEWER_URL,
    SERVE_MEMORY_MIB_RANGE,
    Recordings,
    close_recording,
    open_recording,
    port_free,
    viewer_listening,
)
from drill_sim_ros.viz.running_stats import default_window_s
from drill_sim_ros.viz.string_views import string_batch
from drill_sim_ros.viz.telemetry import N_FIELDS, TelemetryBatch, field_order
from drill_sim_ros.viz.viewer_link import Progress, ViewerLink

NODE_NAME = "rerun_bridge"
QUEUE_DEPTH = 1000          # 10 s of telemetry at the sim's default 100 Hz
# The bridge's inner nodes, which nobody configures or asks: no parameter services, no
# type description service, no /rosout.
HELPER_NODE = {"start_parameter_services": False, "enable_rosout": False,
               "parameter_overrides": [Parameter("start_type_description_service", value=False)]}


def telemetry_qos(best_effort: bool = False) -> QoSProfile:
    reliability = ReliabilityPolicy.BEST_EFFORT if best_effort else ReliabilityPolicy.RELIABLE
    return QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=QUEUE_DEPTH,
                      reliability=reliability)


class TelemetryQueue:
    """A /drill/telemetry subscription on a node that no executor spins.

    DDS queues up to QUEUE_DEPTH samples; :meth:`take_all` drains them in one go, so the
    bridge wakes ``flush_hz`` times a second instead of once per message (rclpy's executor
    costs far more per message than the logging does).
    """

    def __init__(self, context: Context | None = None, best_effort: bool = False,
                 topic: str = topics.TELEMETRY, msg_type: Any = Float64MultiArray) -> None:
        name = "_".join(topic.split("/")[2:])       # /drill/typed/x -> typed_x
        self.node = Node(f"{NODE_NAME}_{name}", context=context, **HELPER_NODE)
        self._sub = self.node.create_subscription(msg_type, topics.node_relative(topic),
                                                  lambda _msg: None, telemetry_qos(best_effort))

    @property
    def topic_name(self) -> str:
        """The resolved telemetry topic (under the bridge's namespace)."""
        return self._sub.topic_name

    def take_all(self, limit: int = 10 * QUEUE_DEPTH) -> list[Float64MultiArray]:
        """Every message queued so far (at most ``limit``), oldest first."""
        messages = []
        handle = self._sub.handle
        with handle:
            while len(messages) < limit:
                taken = handle.take_message(self._sub.msg_type, self._sub.raw)
                if taken is None:
                    break
                messages.append(taken[0])
        return messages

    def destroy(self) -> None:
        self.node.destroy_node()


def string_profile_types() -> list[tuple[str, Any]]:
    """The string profile topics and their message classes: drill/string/torsion
    (JointState), and drill/typed/string/torsion (StringProfile) with drill_sim_msgs."""
    out: list[tuple[str, Any]] = [(topics.STRING_TORSION, JointState)]
    if typed.PROFILE_AVAILABLE:
        out.append((topics.TYPED_STRING_TORSION, typed.StringProfile))
    return out


RUN_INFO_WAIT_S = 3.0        # how long to wait for the sim's /drill/run_info at start


class RerunBridge(Node):
    """Drains the telemetry queue ``flush_hz`` times a second into a :class:`Dashboard`, and
    lets the ``viewer`` link check its viewer when a check is due."""

    def __init__(self, dashboard: Dashboard, flush_hz: float = 4.0,
                 status_period_s: float = 2.0, best_effort: bool = False,
                 viewer: ViewerLink | None = None) -> None:
        super().__init__(NODE_NAME)
        self._dashboard = dashboard
        self._viewer = viewer
        self._queue = TelemetryQueue(self.context, best_effort)
        # the string profiles, as the sim's string.message sends them
        self._strings = [TelemetryQueue(self.context, best_effort, topic, msg_type)
                         for topic, msg_type in string_profile_types()]
        self.telemetry_topic = self._queue.topic_name
        self._order: np.ndarray | None = None
        self.dropped = 0
        self._status_period_s = status_period_s
        self._last_status = (time.monotonic(), 0)
        # steady: the dashboard flushes while the sim's /clock (use_sim_time) stands still
        self.create_timer(1.0 / flush_hz, self.flush,
                          clock=Clock(clock_type=ClockType.STEADY_TIME))

    def _rows(self, messages: list[Float64MultiArray]) -> list[np.ndarray]:
        if self._order is None and messages:
            self._order = field_order([d.label for d in messages[0].layout.dim])
        rows = [np.frombuffer(m.data, dtype=np.float64) for m in messages
                if len(m.data) >= N_FIELDS]
        self.dropped += len(messages) - len(rows)
        return rows

    def flush(self) -> None:
        """Log the buffered samples in one batch, then maybe print the status line."""
        rows = self._rows(self._queue.take_all())
        if rows:
            self._dashboard.log_batch(TelemetryBatch.from_rows(np.stack(rows), self._order))
        for queue in self._strings:
            strings = string_batch(queue.take_all())
            if strings is not None:
                self._dashboard.log_strings(strings)
        if self._viewer is not None:
            self._viewer.poll(time.monotonic(), progress(self._dashboard))
        self._status(force=False)

    def _status(self, force: bool) -> None:
        now, count = time.monotonic(), self._dashboard.samples
        if count == self._last_status[1] or (
                not force and now - self._last_status[0] < self._status_period_s):
            return
        self._last_status = (now, count)
        sim_time = self._dashboard.last_time_s or 0.0
        self.get_logger().info(f"{count} telemetry samples logged, sim_time {sim_time:.3f} s, "
                               f"{self.dropped} malformed")

    def finish(self) -> None:
        """Log what is queued, report the final count, destroy the queue's node."""
        if self.context.ok():
            self.flush()
        self._status(force=True)
        self._queue.destroy()
        for queue in self._strings:
            queue.destroy()


def parse_args(argv: list[str]) -> argparse.Namespace:
    parser = argparse.ArgumentParser(prog="rerun_bridge", description=__doc__.splitlines()[0])
    parser.add_argument("--save", metavar="FILE.rrd", help="write the recording to this file")
    parser.add_argument("--overwrite", action="store_true",
                        help="replace an existing --save file (default: refuse)")
    parser.add_argument("--connect", metavar="URL", nargs="?", const=DEFAULT_VIEWER_URL,
                        help=f"stream to a viewer (default URL {DEFAULT_VIEWER_URL})")
    parser.add_argument("--serve", action="store_true",
                        help="host a gRPC server on 127.0.0.1 for viewers to connect to")
    parser.add_argument("--serve-port", type=int, default=DEFAULT_SERVE_PORT)
    parser.add_argument("--serve-memory-limit", metavar="MiB", type=int,
                        default=DEFAULT_SERVE_MEMORY_MIB,
                        help="data --serve keeps for viewers, MiB; beyond it the oldest is "
                             f"dropped (default {DEFAULT_SERVE_MEMORY_MIB})")
    parser.add_argument("--preset", default=None,
                        help="model preset for the scales of the 2D views (default: what "
                             f"the sim publishes on {topics.RUN_INFO}, else {DEFAULT_PRESET})")
    parser.add_argument("--window-s", type=float, default=None,
                        help="sliding window for E-S and severity, s (default 20 t*)")
    parser.add_argument("--flush-hz", type=float, default=4.0)
    parser.add_argument("--best-effort", action="store_true",
                        help="subscribe best-effort (default: reliable)")
    args = parser.parse_args(argv)
    if not 1 <= args.serve_port <= 65535:
        parser.error(f"--serve-port = {args.serve_port} must lie in [1, 65535]")
    low, high = SERVE_MEMORY_MIB_RANGE
    if not low <= args.serve_memory_limit <= high:
        parser.error(f"--serve-memory-limit = {args.serve_memory_limit} MiB must lie in "
                     f"[{low}, {high}]")
    if not (math.isfinite(args.flush_hz) and 0 < args.flush_hz <= 1000):
        parser.error(f"--flush-hz = {args.flush_hz!r} must lie in (0, 1000]")
    if args.window_s is not None and not (math.isfinite(args.window_s) and args.window_s > 0):
        parser.error(f"--window-s = {args.window_s!r} must be a positive number of seconds")
    if not (args.save or args.connect or args.serve):
        args.connect = DEFAULT_VIEWER_URL
    return args


def run_units(preset: str | None, info: dict[str, Any] | None,
              timeout_s: float = RUN_INFO_WAIT_S) -> PaperUnits:
    """``preset``'s units if given; else those of the running sim's run ``info``; else the
    default preset's, with a warning naming it."""
    if preset:
        return PaperUnits.load(preset)
    if info is not None:
        return PaperUnits.from_run_info(info)
    rclpy.logging.get_logger(f"{NODE_NAME}_run_info").warning(
        f"no {topics.RUN_INFO} within {timeout_s:g} s: the 2D views use the scales of preset "
        f"{DEFAULT_PRESET!r} (override with --preset)")
    return PaperUnits.load(DEFAULT_PRESET)


def wait_run_info(timeout_s: float = RUN_INFO_WAIT_S) -> dict[str, Any] | None:
    """The running sim's /drill/run_info (JSON), waited for up to ``timeout_s``; None if it
    did not come."""
    node = Node(f"{NODE_NAME}_run_info", **HELPER_NODE)
    received: list[String] = []
    node.create_subscription(String, topics.node_relative(topics.RUN_INFO), received.append,
                             RUN_INFO_QOS)
    deadline = time.monotonic() + timeout_s
    try:
        while not received and time.monotonic() < deadline:
            rclpy.spin_once(node, timeout_sec=0.1)
    finally:
        node.destroy_node()
    return json.loads(received[0].data) if received else None


def string_shown(info: dict[str, Any] | None, preset: str | None) -> bool:
    """Whether the dashboard has the string views: the run info's string is distributed;
    without run info (the sim not started yet), ``preset``'s (default: the default
    preset's)."""
    if info is not None:
        return has_string_views(info)
    return load_preset(preset or DEFAULT_PRESET).string.distributed


class StartError(Exception):
    """The bridge cannot start as asked (one line)."""


def check_sinks(args: argparse.Namespace) -> None:
    """Refuse an existing --save file (unless --overwrite), a busy --serve port, and a
    --connect with no viewer listening when it is the only sink.

    rerun buffers everything for a viewer that is not there yet (about 21 MB a minute at the
    sim's rate), so the bridge never streams to an address where nothing listens: beside
    another sink, the ViewerLink waits for a viewer instead.
    """
    if args.save:
        try:
            check_output(args.save, args.overwrite)
        except OutputError as exc:
            raise StartError(f"--save: {exc}") from None
    if args.serve and (busy := port_free(args.serve_port)) is not None:
        raise StartError(f"--serve-port {args.serve_port}: cannot listen on 127.0.0.1 "
                         f"({busy})")
    if args.connect and not (args.save or args.serve) and not viewer_listening(args.connect):
        raise StartError(f"no viewer listening at {args.connect}: start one first "
                         "(`rerun`), or use --save FILE.rrd or --serve")


def progress(dashboard: Dashboard) -> Progress:
    return Progress(dashboard.samples, dashboard.last_time_s)


def kept_elsewhere(args: argparse.Namespace) -> str:
    """What keeps the telemetry while no viewer listens (for the ViewerLink's warning)."""
    if args.save and args.serve:
        return f"{args.save} and --serve continue"
    if args.save or args.serve:
        return f"{args.save or '--serve'} continues"
    return "nothing else records it meanwhile"


FILE_CLOSE_TIMEOUT_S = 10.0     # a .rrd gets everything queued, and its footer
VIEWER_CLOSE_TIMEOUT_S = 1.5    # stop within 2 s even when a viewer stopped reading


@dataclass
class Outputs:
    """The dashboard, the stream of --save/--serve (if any) and the --connect viewer link."""

    dashboard: Dashboard
    stored: rr.RecordingStream | None
    viewer: ViewerLink | None

    def close(self) -> list[str]:
        """Finish the .rrd (and --serve), then the viewer's stream (bounded); return what
        could not be flushed, one line per sink."""
        problems = []
        if self.stored is not None and (
                problem := close_recording(self.stored, FILE_CLOSE_TIMEOUT_S)) is not None:
            problems.append(f"not everything reached --save/--serve: {problem}")
        if self.viewer is not None and (
                problem := self.viewer.close(VIEWER_CLOSE_TIMEOUT_S)) is not None:
            problems.append(f"not everything reached the viewer: {problem}")
        return problems


def open_outputs(args: argparse.Namespace, logger: Any) -> Outputs:
    """The dashboard logging to --save/--serve, and to --connect while a viewer listens."""
    info = wait_run_info()       # also with --preset: it says whether the string is shown
    units = run_units(args.preset, info)
    window = default_window_s(units) if args.window_s is None else args.window_s
    frames = view_frames(units, Extents.typical())     # live: the data is not known yet
    blueprint = build_blueprint(window, frames, string_shown(info, args.preset))
    recording_id = str(uuid.uuid4())                    # one recording on every sink
    stored = None
    if args.save or args.serve:
        stored = open_recording(blueprint, save=args.save,
                                serve_port=args.serve_port if args.serve else None,
                                serve_memory_mib=args.serve_memory_limit,
                                recording_id=recording_id)
    recordings = Recordings(*([stored] if stored is not None else []))
    dashboard = Dashboard(recordings, units, window, frames)
    viewer = None
    if args.connect:
        def open_stream() -> rr.RecordingStream:
            stream = open_recording(blueprint, connect=args.connect, recording_id=recording_id)
            dashboard.log_static(stream)
            return stream

        viewer = ViewerLink(args.connect, recordings, open_stream, logger, kept_elsewhere(args))
        viewer.poll(time.monotonic(), progress(dashboard))
    return Outputs(dashboard, stored, viewer)


def _interrupt(signum: int, frame: object) -> None:
    raise KeyboardInterrupt(f"signal {signum}")


def _spin_bridge(args: argparse.Namespace, logger: Any) -> tuple[Outputs | None, list[str]]:
    """Open the outputs and spin the bridge until a signal or a shutdown; the outputs (None if
    they did not open) and what could not be flushed to them."""
    outputs: Outputs | None = None
    node: RerunBridge | None = None
    try:
        outputs = open_outputs(args, logger)
        node = RerunBridge(outputs.dashboard, args.flush_hz, best_effort=args.best_effort,
                           viewer=outputs.viewer)
        node.get_logger().info(f"ready: {node.telemetry_topic} -> rerun "
                               f"(scales of {outputs.dashboard.units.preset or 'the run info'})")
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        if node is not None:
            node.finish()
            node.destroy_node()
        rclpy.try_shutdown()
        problems = [] if outputs is None else outputs.close()
    return outputs, problems


def _exit_code(outputs: Outputs | None, problems: list[str], logger: Any) -> int:
    """Log what was lost; 1 if anything was, else 0 (leaving at once past a stuck viewer)."""
    for problem in problems:
        logger.error(problem)
    code = 1 if problems else 0
    if outputs is not None and outputs.viewer is not None and outputs.viewer.closing():
        # rerun's exit hook would wait for as long as a stuck viewer holds data unread; the
        # .rrd and --serve are closed by now, so leave without it.
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(code)
    return code


def main(argv: list[str] | None = None) -> int:
    disable_analytics()
    argv = sys.argv if argv is None else argv
    args = parse_args(remove_ros_args(argv)[1:])
    logger = rclpy.logging.get_logger(NODE_NAME)
    try:
        check_sinks(args)
    except StartError as exc:
        logger.fatal(str(exc))
        return 2
    # Own signal handling: the context stays up on SIGINT/SIGTERM/SIGHUP so the queue is
    # drained and the .rrd finished.
    rclpy.init(args=argv, signal_handler_options=SignalHandlerOptions.NO)
    signal.signal(signal.SIGTERM, _interrupt)
    signal.signal(signal.SIGHUP, _interrupt)
    outputs, problems = _spin_bridge(args, logger)
    return _exit_code(outputs, problems, logger)


if __name__ == "__main__":
    sys.exit(main())
