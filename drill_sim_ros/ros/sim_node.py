"""sim_node: the real-time ROS 2 node around the RGD07 drill-bit simulator (node ``drill_sim``).

Publishes the bit and surface state at ``publish_rate_hz`` of simulated time (stamps in
simulated time, one stamp per sample on every topic), /diagnostics at 1 Hz wall and /clock;
takes surface-rpm and WOB setpoints; serves ~/reset, ~/pause and ~/step (lockstep). With
drill_sim_msgs installed, drill/typed/* carry the same samples, run info and command typed
(:mod:`drill_sim_ros.ros.typed`).
Pacing follows the monotonic clock without drift (:mod:`drill_sim_ros.realtime.pacing`).

One tick path: the ticker thread (real time, free run) or the ``~/step`` callback (lockstep,
paused) asks the session for the periods that are due and hands the block to the sinks
(:mod:`drill_sim_ros.ros.sinks`: publishers and recorder, the same bytes). The executor's
thread runs the commands, services, parameter callbacks and 1 Hz timers. Both take the
node's :class:`HandoffLock` before touching the session, the schedule or the recorder.
"""

from __future__ import annotations

import faulthandler
import gc
import json
import math
import signal
import sys
import time
from typing import Any

import numpy as np
import rclpy
from rcl_interfaces.msg import SetParametersResult
from rclpy.clock import Clock, ClockType
from rclpy.event_handler import PublisherEventCallbacks, SubscriptionEventCallbacks
from rclpy.executors import ExternalShutdownException
from rclpy.impl.implementation_singleton import rclpy_implementation
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.qos import HistoryPolicy, QoSProfile, ReliabilityPolicy
from rclpy.serialization import deserialize_message, serialize_message
from rclpy.task import Future
from sensor_msgs.msg import JointState
from std_msgs.msg import Float64, String
from std_srvs.srv import SetBool, Trigger

from drill_sim_ros import topics
from drill_sim_ros.control.command import Command, CommandLimits, apply_command
from drill_sim_ros.model.errors import DrillSimError, NumericalFault, ParameterError
from drill_sim_ros.model.measurement import SIGNALS, RigSensors, SignalSpec
from drill_sim_ros.model.params import RPM_PER_RAD_S
from drill_sim_ros.model.presets import load_preset
from drill_sim_ros.model.session import Block, SessionConfig, SimSession
from drill_sim_ros.model.telemetry import MODE_NAMES, NS_PER_S, TELEMETRY_INDEX
from drill_sim_ros.realtime.pacing import Pacer, RateMeter
from drill_sim_ros.realtime.ticker import HandoffLock, Ticker
from drill_sim_ros.ros import messages, typed
from drill_sim_ros.ros.command_types import ForeignCommandTypes
from drill_sim_ros.ros.diagnostics import Diagnostics, Figures, source_of
from drill_sim_ros.ros.frame import SAMPLE_TOPICS
from drill_sim_ros.ros.handshake import COMMAND_MODE, SERVICE_MODE, Handshake
from drill_sim_ros.ros.messages import LATEST_SAMPLE_QOS, RUN_INFO_QOS, TELEMETRY_QOS, stamp_ns
from drill_sim_ros.ros.parameters import (
    RUNTIME_DRIVE_PARAMETERS,
    SPEC_BY_NAME,
    coerce,
    declare_all,
    init_ros,
    recording_options,
    top_drive_of,
    validate,
)
from drill_sim_ros.ros.sinks import SampleSinks, TypedTelemetry
from drill_sim_ros.ros.string_sink import (
    StringProfileSink,
    profile_packer,
    string_message,
    string_topics,
)
from drill_sim_ros.terminal import StatusLine, format_status

RCLError = rclpy_implementation.RCLError
DATA_QOS = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=100,
                      reliability=ReliabilityPolicy.RELIABLE)
CLOCK_QOS = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=10,
                       reliability=ReliabilityPolicy.RELIABLE)
# The node's queue never drops a command (a flood is held back by DDS flow control, and what
# a publisher's own history overwrites is reported lost): in command-triggered lockstep a
# controller's answer is never lost behind other commands.
COMMAND_QOS = QoSProfile(history=HistoryPolicy.KEEP_ALL, reliability=ReliabilityPolicy.RELIABLE)
# The services (~/reset, ~/pause, ~/off_bottom, ~/step) keep every request and every reply
# (the default keeps the last 10: a burst of 1000 calls got 31 replies); a client that sends
# bursts needs a queue as deep on its side (its requests and the replies it has not taken).
SERVICE_QOS = QoSProfile(history=HistoryPolicy.KEEP_ALL, reliability=ReliabilityPolicy.RELIABLE)
# Reliable volatile publishers match every subscriber but transient-local ones; without the
# default QoS-event handlers the executor's wait set is 2 entities per publisher smaller.
QUIET_PUBLISHER = PublisherEventCallbacks(use_default_callbacks=False)
FREE_RUN_BATCH = 20          # periods per turn when running as fast as possible
MAX_CATCH_UP = 50            # periods per turn when catching up in real time
BACKLOG_WAIT_S = 0.005       # wait this long while the recorder catches up
DIAGNOSTICS_PERIOD_S = 1.0
STATUS_PERIOD_S = 0.25
WARN_THROTTLE_S = 1.0
GIL_SWITCH_INTERVAL_S = 0.0005
WAIT_CHECK_PERIOD_S = 0.1    # how often lockstep's wait is compared with lockstep.warn_after_s
PAUSED_COMMAND_LOCKSTEP = ("paused (command lockstep: a command answering the latest sample "
                           "is applied, and its period runs on resume)")


def session_config(values: dict[str, Any], preset: Any) -> SessionConfig:
    """The session settings from the declared parameter values."""
    return SessionConfig(
        preset=preset, publish_rate_hz=values["publish_rate_hz"],
        dtau_max=values["model.dtau"], n_nodes=values["model.n_nodes"],
        perturb_v=values["model.perturb_v"], applied_wob_n=values["model.applied_wob_n"],
        surface_rpm=values["model.surface_rpm"],
        top_drive_accel_rpm_s=values["limits.top_drive_accel_rpm_s"],
        wob_rate_n_s=values["limits.wob_rate_n_s"], window_s=values["diagnostics.window_s"],
        submerged_weight_n=values["model.submerged_string_weight_n"],
        top_drive=top_drive_of(values), sensors=rig_sensors(values),
        command_delay_s=values["commands.delay_s"],
        string_rate_hz=values["string.rate_hz"], string_depths=values["string.depths"],
        formation=tuple(formation_layers(values["formation.layers"])))


def formation_layers(text: str) -> list[dict[str, Any]]:
    """The ``formation.layers`` parameter: a JSON list of layer mappings ('' = none)."""
    if not text.strip():
        return []
    try:
        layers = json.loads(text)
    except json.JSONDecodeError as exc:
        raise ParameterError(f"parameter 'formation.layers' is not JSON: {exc}") from exc
    if not isinstance(layers, list):
        raise ParameterError("parameter 'formation.layers' must be a JSON list of layers")
    return layers


def rig_sensors(values: dict[str, Any]) -> RigSensors:
    """The surface sensors of the ``sensors.*`` parameters."""
    specs = {signal: SignalSpec(noise_std=values[f"sensors.{signal}.noise_std"],
                                quantum=values[f"sensors.{signal}.quantum"],
                                delay_periods=values[f"sensors.{signal}.delay_periods"])
             for signal in SIGNALS}
    return RigSensors(specs, seed=values["sensors.seed"])


# (joint, interface) of drill/cmd/top_drive -> the Command field it sets
COMMAND_INTERFACES = {("top_drive", "velocity"): "speed_rad_s",
                      ("top_drive", "effort"): "motor_torque_nm", ("hook", "effort"): "wob_n"}


def malformed_joint_state(msg: JointState) -> str | None:
    """Why a drill/cmd/top_drive message cannot be read joint by joint (None: it can): each
    of position, velocity and effort must be empty or as long as ``name``."""
    lengths = {"position": len(msg.position), "velocity": len(msg.velocity),
               "effort": len(msg.effort)}
    wrong = [f"{array} has {n}" for array, n in lengths.items() if n not in (0, len(msg.name))]
    if not wrong:
        return None
    return (f"{len(msg.name)} names but {', '.join(wrong)} values (each array is empty or "
            "one value per name)")


def joint_commands(msg: JointState) -> dict[tuple[str, str], float]:
    """``{(joint, 'velocity' | 'effort'): value}`` of a drill/cmd/top_drive message; NaN and
    missing entries are no command."""
    out: dict[tuple[str, str], float] = {}
    for i, joint in enumerate(msg.name):
        for interface, values in (("velocity", msg.velocity), ("effort", msg.effort)):
            if i < len(values) and not math.isnan(values[i]):
                out[(joint, interface)] = float(values[i])
    return out


def topic_qos(topic: str) -> QoSProfile:
    """The QoS sim_node publishes ``topic`` with (its recording stores the same)."""
    if topic in (topics.RUN_INFO, topics.TYPED_RUN_INFO):
        return RUN_INFO_QOS
    if topic == topics.SURFACE_MEASURED:
        return LATEST_SAMPLE_QOS
    if topic == topics.TELEMETRY:
        return TELEMETRY_QOS
    return CLOCK_QOS if topic in (topics.CLOCK, topics.DIAGNOSTICS) else DATA_QOS


class SimNode(Node):
    """The ``drill_sim`` node; call :meth:`start` before spinning it. ``finished`` completes
    when ``run_seconds`` have passed."""

    def __init__(self, **node_kwargs: Any) -> None:
        super().__init__(topics.NODE_NAME, **node_kwargs)
        self._steady = Clock(clock_type=ClockType.STEADY_TIME)
        self._preset, self._values = declare_all(self, load_preset)
        self._init_run_state()
        self._pubs = {t: self.create_publisher(messages.type_of(t), topics.node_relative(t),
                                               topic_qos(t), event_callbacks=QUIET_PUBLISHER)
                      for t in (*SAMPLE_TOPICS, topics.CLOCK, topics.DIAGNOSTICS,
                                topics.RUN_INFO, *self._string_topics())}
        self._sinks = SampleSinks(self._pubs)
        self._string_sink: StringProfileSink | None = None     # made by start()
        self._add_command_topics()
        self._typed_pubs = self._add_typed_topics()
        self._add_services()
        self._add_timers()
        self.add_on_set_parameters_callback(self._validate_parameters)
        self.add_post_set_parameters_callback(self._apply_parameters)

    def _init_run_state(self) -> None:
        """The run's plain state before :meth:`start`: no session, not paused, no counts."""
        self.finished = Future()
        self._lock = HandoffLock()
        self._status = StatusLine()
        self._session: SimSession | None = None       # made by start()
        self._initial_pending = False
        self._pacer = Pacer(1)
        self._rate = RateMeter(time.monotonic_ns(), 0.0)
        self._paused = False
        self._held_step = False      # paused in command lockstep: a command's period waits
        self._closing = False
        self._fault: str | None = None
        self.recording_failed = False
        self.rejected_commands = 0
        self.saturated_commands = 0
        self._last_command_ns: int | None = None     # sim time of the last top_drive command
        self._diagnostics = Diagnostics(source_of(self.get_fully_qualified_name(),
                                                  self.get_namespace()))
        self._last_row: np.ndarray | None = None     # SI, TELEMETRY_FIELDS; lock held

    def _add_command_topics(self) -> None:
        """The subscriptions of the three command topics, each counting its DDS losses."""
        self._command_names: dict[str, str] = {}      # command topic -> its resolved name
        self._command_subs = {}
        for topic, callback in ((topics.CMD_SURFACE_RPM, self._on_surface_rpm),
                                (topics.CMD_WOB, self._on_wob),
                                (topics.CMD_TOP_DRIVE, self._on_top_drive)):
            sub = self.create_subscription(
                messages.type_of(topic), topics.node_relative(topic), callback, COMMAND_QOS,
                raw=True, event_callbacks=SubscriptionEventCallbacks(
                    message_lost=self._on_commands_lost(topic)))
            self._command_names[topic] = sub.topic_name
            self._command_subs[topic] = sub
        self._foreign_commands = ForeignCommandTypes(
            {name: topics.MSG_TYPES[topic] for topic, name in self._command_names.items()})

    def _add_services(self) -> None:
        """``~/reset``, ``~/pause`` and ``~/step``, and the lockstep handshake of ``~/step``."""
        self.create_service(Trigger, "~/reset", self._on_reset, qos_profile=SERVICE_QOS)
        self.create_service(SetBool, "~/pause", self._on_pause, qos_profile=SERVICE_QOS)
        self.create_service(SetBool, "~/off_bottom", self._on_off_bottom,
                            qos_profile=SERVICE_QOS)
        step = self.create_service(Trigger, "~/step", self._on_step, qos_profile=SERVICE_QOS)
        self._handshake = Handshake(self.get_logger(), self._command_names[topics.CMD_TOP_DRIVE],
                                    self.resolve_service_name(step.srv_name),
                                    time.monotonic())

    def _add_timers(self) -> None:
        """The steady-clock timers (lockstep waits, diagnostics, the status line, the first
        spin and ``run_seconds``, the last two armed by :meth:`start`) and the ticker."""
        # armed only in lockstep (_restart_ticks): each wake of the executor costs about
        # half a millisecond of CPU, which at 10 Hz was a sixth of the node's at real time
        self._wait_timer = self.create_timer(WAIT_CHECK_PERIOD_S, self._check_waiting,
                                             clock=self._steady)
        self._wait_timer.cancel()
        self._ticker = Ticker(self._tick, self._on_tick_error, name="drill_sim_ticker")
        self._first_spin = self.create_timer(0.0, self._start_ticker, clock=self._steady)
        self._first_spin.cancel()                      # start() arms it
        self.create_timer(DIAGNOSTICS_PERIOD_S, self._publish_diagnostics, clock=self._steady)
        if self._status.active:        # a terminal: no executor wake-ups for nobody
            self.create_timer(STATUS_PERIOD_S, self._show_status, clock=self._steady)
        self._stop_timer = self.create_timer(max(self._values["run_seconds"], 1e-3),
                                             self._on_run_limit, clock=self._steady)
        self._stop_timer.cancel()                      # start() arms it when run_seconds > 0

    def _add_typed_topics(self) -> dict[str, Any]:
        """The drill_sim_msgs twins of the telemetry, run info and command, when that package
        is installed; returns the typed publishers by topic."""
        if not typed.AVAILABLE:
            return {}
        pubs = {topic: self.create_publisher(msg_type, topics.node_relative(topic), qos,
                                             event_callbacks=QUIET_PUBLISHER)
                for topic, msg_type, qos in (
                    (topics.TYPED_TELEMETRY, typed.Telemetry, DATA_QOS),
                    (topics.TYPED_RUN_INFO, typed.RunInfo, RUN_INFO_QOS))}
        rig = self._diagnostics.source.hardware_id
        self._sinks.typed = TypedTelemetry(pubs[topics.TYPED_TELEMETRY],
                                           typed.TelemetryPacker(rig))
        topic = topics.TYPED_CMD_TOP_DRIVE
        sub = self.create_subscription(
            typed.TopDriveCommand, topics.node_relative(topic), self._on_typed_top_drive,
            COMMAND_QOS, raw=True, event_callbacks=SubscriptionEventCallbacks(
                message_lost=self._on_commands_lost(topic)))
        self._command_names[topic] = sub.topic_name
        self._command_subs[topic] = sub
        return pubs

    # ---- start -------------------------------------------------------------------------
    def start(self) -> None:
        """Build (compile, warm up) the session, open the recording, publish what runs; the
        ticker starts on the first spin. Raises DrillSimError or ValueError on bad settings."""
        with self._lock.urgent():
            session = SimSession(session_config(self._values, self._preset))
            self._session = session
            self._string_sink = self._profile_sink(session)
            self._sinks.warm_up()
            self._sinks.clock_period_ns = round(NS_PER_S / self._values["clock_rate_hz"])
            self._pacer = Pacer(self._wall_period_ns(self._rtf))
            self._sinks.recorder = self._open_recorder(self._values["record.path"])
            self._publish_run_info()
            self._initial_pending = True       # t = 0 goes out before the first period
        self._handshake.restart(time.monotonic())     # a wait counts from here
        self._first_spin.reset()
        if self._values["run_seconds"] > 0:
            self._stop_timer.reset()
        self._log_start()

    def _string_topics(self) -> tuple[str, ...]:
        """The topic of the string profiles (none: a lumped string or string.rate_hz 0)."""
        return string_topics(self._preset, self._values, typed.PROFILE_AVAILABLE)

    def _profile_sink(self, session: SimSession) -> StringProfileSink | None:
        """The sink of the string profiles in the message ``string.message`` chooses."""
        chosen = self._string_topics()
        if not chosen:
            return None
        message = string_message(self._values, typed.PROFILE_AVAILABLE)
        if message != self._values["string.message"]:
            self.get_logger().warning("string.message typed: drill_sim_msgs/StringProfile "
                                      f"is not installed, the profiles go out on "
                                      f"{topics.STRING_TORSION} as JointState")
        packer = profile_packer(message, session.string_depths_m, session.string_names,
                                self._diagnostics.source.hardware_id)
        return StringProfileSink(self._sinks, chosen[0], self._pubs, packer)

    def _open_recorder(self, path: str) -> Any:
        """The in-process MCAP recorder of ``record.path`` (None when off). An existing or
        unwritable path raises one ArchiveError line: the node does not start."""
        if not path:
            return None
        from drill_sim_ros.archive.inprocess import InProcessRecorder
        recorder = InProcessRecorder(path, node_name=topics.NODE_NAME,
                                     metadata=self._run_metadata(),
                                     **recording_options(self._values))
        types = {**topics.MSG_TYPES, **topics.TYPED_MSG_TYPES}
        for topic, publisher in {**self._pubs, **self._typed_pubs}.items():
            recorder.add_topic(publisher.topic_name, types[topic], topic_qos(topic))
        for topic, name in self._command_names.items():
            recorder.add_topic(name, types[topic], COMMAND_QOS)
        self.get_logger().info(f"recording to {path}")
        return recorder

    def _run_metadata(self) -> dict[str, str]:
        """The MCAP metadata record of a recording: the run info, flat, as strings."""
        info = self._session.run_info()
        flat = {key: value for key, value in info.items() if key != "groups"}
        return {key: value if isinstance(value, str) else repr(value)
                for key, value in flat.items()}

    def _publish_run_info(self) -> None:
        """/drill/run_info, latched: what this node runs, as JSON (lock held)."""
        payload = serialize_message(String(data=json.dumps(self._session.run_info())))
        self._sinks.emit_one(topics.RUN_INFO, payload, self._session.sim_time_ns)
        if topics.TYPED_RUN_INFO in self._typed_pubs:
            msg = typed.run_info_message(self._session.run_info(), self._values,
                                         self._session.sim_time_ns,
                                         self._diagnostics.source.hardware_id)
            self._sinks.emit_one(topics.TYPED_RUN_INFO, serialize_message(msg),
                                 self._session.sim_time_ns, self._typed_pubs)

    def _log_start(self) -> None:
        s = self._session
        self.get_logger().info(
            f"preset {self._preset.name}: {s.steps} steps of dtau {s.dtau:.4g} per "
            f"{s.period_ns * 1e-6:g} ms period; real_time_factor {self._rtf:g}, "
            f"lockstep {self._lockstep}")

    # ---- parameters --------------------------------------------------------------------
    @property
    def _rtf(self) -> float:
        return self._values["real_time_factor"]

    @property
    def _lockstep(self) -> bool:
        return self._values["lockstep"]

    def _validate_parameters(self, params: list[Parameter]) -> SetParametersResult:
        for param in params:
            spec = SPEC_BY_NAME.get(param.name)
            reason = None if spec is None else validate(spec, param.value)
            if reason is not None:
                return SetParametersResult(successful=False, reason=reason)
        drive = {p.name for p in params} & RUNTIME_DRIVE_PARAMETERS
        if drive and self._session is not None:   # the new drive must be stable at the step
            values = {**self._values, **{p.name: coerce(SPEC_BY_NAME[p.name], p.value)
                                         for p in params if p.name in drive}}
            try:
                self._session.check_top_drive(top_drive_of(values))
            except ParameterError as exc:
                return SetParametersResult(successful=False, reason=str(exc))
        for p in params:
            if p.name == "formation.layers" and self._session is not None:
                try:
                    self._session.check_formation(formation_layers(p.value))
                except ParameterError as exc:
                    return SetParametersResult(successful=False, reason=str(exc))
        return SetParametersResult(successful=True)

    def _apply_parameters(self, params: list[Parameter]) -> None:
        with self._lock.urgent():
            for param in params:
                if param.name in SPEC_BY_NAME:
                    self._values[param.name] = coerce(SPEC_BY_NAME[param.name], param.value)
            if self._session is None:
                return
            self._session.submerged_weight_n = self._values["model.submerged_string_weight_n"]
            names = {p.name for p in params}
            if names & RUNTIME_DRIVE_PARAMETERS:      # between runs: no bump
                self._session.set_top_drive(top_drive_of(self._values))
            if "formation.layers" in names:
                self._session.set_formation(formation_layers(self._values["formation.layers"]))
            if names & {"real_time_factor", "lockstep", "lockstep_trigger"}:
                self._restart_ticks()

    # ---- pacing and the one tick path --------------------------------------------------
    def _wall_period_ns(self, rtf: float) -> int:
        return max(1, round(self._session.period_ns / rtf)) if rtf > 0 else 1

    def _start_ticker(self) -> None:
        """First spin: anchor the schedule and start the ticker thread."""
        self.destroy_timer(self._first_spin)
        with self._lock.urgent():
            self._restart_ticks()
        self._ticker.start()

    def _restart_ticks(self) -> None:
        """New schedule for the current factor, anchored now; in command-triggered lockstep
        the latest sample (at start: t = 0) is out for a controller to answer (call with the
        lock held)."""
        self._pacer = Pacer(self._wall_period_ns(self._rtf))
        self._anchor()
        self._handshake.restart(time.monotonic())
        if self._lockstep:
            self._wait_timer.reset()
        else:
            self._wait_timer.cancel()
        if self._command_steps():
            self._emit_initial()

    def _anchor(self) -> None:
        """The next tick is due now; wake the ticker (call with the lock held)."""
        self._pacer.anchor(time.monotonic_ns())
        self._ticker.wake()

    def _tick(self) -> float | None:
        """One turn of the ticker thread: advance the periods that are due and hand their
        block to the sinks. Returns the seconds to wait before the next turn (None: idle)."""
        self._lock.acquire_background()
        try:
            if self._closing or self._lockstep or self._paused or self._fault is not None:
                return None
            # the recorder's loss bound, counting the free run's next block (20 periods,
            # 0.2 s at 100 Hz: without it the queue reached 0.7 s and a kill lost 1.07 s)
            block_s = FREE_RUN_BATCH * self._session.period_ns * 1e-9 if self._rtf <= 0 else 0.0
            if self._sinks.backlogged(block_s):
                return BACKLOG_WAIT_S
            if self._rtf <= 0:                        # free run
                self._advance(FREE_RUN_BATCH)
                return 0.0
            pacer = self._pacer
            count = pacer.due(time.monotonic_ns(), MAX_CATCH_UP)
            if count > 0 and self._advance(count):
                pacer.complete(count, time.monotonic_ns())
            return max(0.0, (pacer.deadline_ns() - time.monotonic_ns()) * 1e-9)
        finally:
            self._lock.release()

    def _advance(self, periods: int) -> bool:
        """Simulate ``periods`` and hand the block to the sinks; False on a numerical fault
        (call with the lock held)."""
        try:
            self._emit_initial(then_advance=True)
            block = self._session.run(periods)
        except NumericalFault as exc:
            self._on_fault(exc)
            return False
        self._emit(block)
        return True

    def _emit_initial(self, then_advance: bool = False) -> None:
        """The state at t = 0, what a controller first reacts to, once: just before the first
        period or the first command, whichever comes first; ``then_advance``: periods follow
        at once, so the sim has not advanced yet (lock held)."""
        if self._initial_pending:
            self._initial_pending = False
            self._emit(self._session.current(), advanced=not then_advance)

    def _emit(self, block: Block, advanced: bool = True) -> None:
        """Hand ``block`` to the sinks; ``advanced``: the sim advanced to its last sample
        (call with the lock held)."""
        self._sinks.emit(block, self._values["publish_clock"])
        if block.strings:
            self._string_sink.emit(block.strings)
        if len(block):
            self._last_row = block.rows[-1]
            self._handshake.published(int(block.stamps_ns[-1]), time.monotonic(), advanced)

    def _on_tick_error(self, exc: Exception) -> bool:
        """An unexpected error on the ticker: quiet at shutdown, else a fault until reset."""
        if not self.context.ok():
            return False             # SIGINT/SIGTERM shut the context down mid-publish
        with self._lock.urgent():
            self._fault = f"internal error: {exc!r}"
        self.get_logger().error(f"ticker: {exc!r}; call ~/reset to resume")
        return True

    def _on_fault(self, exc: NumericalFault) -> None:
        self._fault = str(exc)
        self.get_logger().error(f"numerical fault: {exc}; call ~/reset to recover")

    # ---- commands ----------------------------------------------------------------------
    def _on_surface_rpm(self, raw: bytes) -> None:
        rpm = deserialize_message(raw, Float64).data
        with self._lock.urgent():
            self._apply(topics.CMD_SURFACE_RPM, Command(speed_rad_s=rpm / RPM_PER_RAD_S))
            self._record_command(topics.CMD_SURFACE_RPM, raw)

    def _on_wob(self, raw: bytes) -> None:
        wob_n = deserialize_message(raw, Float64).data
        with self._lock.urgent():
            self._apply(topics.CMD_WOB, Command(wob_n=wob_n))
            self._record_command(topics.CMD_WOB, raw)

    def _on_top_drive(self, raw: bytes) -> None:
        """drill/cmd/top_drive: apply what it commands and, in command-triggered lockstep,
        advance exactly one period under it if it answers the latest sample (else it is
        stale: not applied, counted)."""
        msg = deserialize_message(raw, JointState)
        topic = topics.CMD_TOP_DRIVE
        if (problem := malformed_joint_state(msg)) is not None:
            with self._lock.urgent():
                self._reject(topic, problem)
            return
        self._take_top_drive(topic, self._top_drive_command(msg), stamp_ns(msg.header.stamp),
                             raw)

    def _on_typed_top_drive(self, raw: bytes) -> None:
        """drill/typed/cmd/top_drive: the same command as drill/cmd/top_drive, typed."""
        msg = deserialize_message(raw, typed.TopDriveCommand)
        self._take_top_drive(topics.TYPED_CMD_TOP_DRIVE, typed.command_of(msg),
                             stamp_ns(msg.header.stamp), raw)

    def _take_top_drive(self, topic: str, command: Command, reacts_to_ns: int,
                        raw: bytes) -> None:
        """Record a top-drive command; apply it and, in command-triggered lockstep, advance
        one period, unless it does not answer the latest sample there (stale: counted)."""
        with self._lock.urgent():
            self._record_command(topic, raw)
            steps = self._command_steps()
            if steps and not self._handshake.admit(topic, reacts_to_ns):
                return
            self._apply(topic, command)
            self._last_command_ns = self._session.sim_time_ns     # the controller is alive
            self._session.command_stamp_ns = reacts_to_ns
            if steps:
                self._step_on_command()

    def _step_on_command(self) -> None:
        """The period an admitted command advances: now, or on resume if paused (the
        command is applied already, so the period is the one it would have run; lock
        held)."""
        if self._paused:
            self._held_step = True
        else:
            self._advance(1)

    def _top_drive_command(self, msg: JointState) -> Command:
        """The Command of a drill/cmd/top_drive message; a joint/interface it does not know
        is rejected (counted)."""
        values = joint_commands(msg)
        for joint, interface in set(values) - set(COMMAND_INTERFACES):
            self._reject(topics.CMD_TOP_DRIVE, f"joint {joint!r} takes no {interface} command "
                                               "(top_drive: velocity, effort; hook: effort)")
        return Command(**{name: values[key] for key, name in COMMAND_INTERFACES.items()
                          if key in values})

    def _on_commands_lost(self, topic: str) -> Any:
        """The message_lost event handler of the ``topic`` subscription."""
        return lambda info: self._handshake.lost(topic, info.total_count_change)

    def _command_steps(self) -> bool:
        """Each drill/cmd/top_drive message advances one period (lock held)."""
        return (self._lockstep and self._values["lockstep_trigger"] == "command"
                and self._fault is None and not self._closing)

    def _apply(self, topic: str, command: Command) -> None:
        """``command`` from the next period, clamped to the limits (counted as saturated);
        a non-finite value is rejected and the last setpoint stays (lock held)."""
        self._emit_initial()                 # t = 0 is the state before any command
        limits = CommandLimits(self._values["limits.max_surface_rpm"],
                               self._values["limits.max_wob_n"])
        for applied, why in apply_command(self._session, command, limits):
            if not applied:
                self._reject(topic, why)
                continue
            self.saturated_commands += 1
            self.get_logger().warning(
                f"saturated {topic}: {why}; applying the limit "
                f"({self.saturated_commands} saturated so far)",
                throttle_duration_sec=WARN_THROTTLE_S)

    def _reject(self, topic: str, problem: str) -> None:
        self.rejected_commands += 1
        self.get_logger().warning(
            f"rejected {topic}: {problem}; the last valid setpoint stays "
            f"({self.rejected_commands} rejected so far)", throttle_duration_sec=WARN_THROTTLE_S)

    def _record_command(self, topic: str, raw: bytes) -> None:
        """The command as received, logged at the sim time it takes effect (lock held)."""
        if self._sinks.recorder is not None:
            self._sinks.recorder.write_serialized(self._command_names[topic], raw,
                                                  self._session.sim_time_ns)

    # ---- services ----------------------------------------------------------------------
    def _on_reset(self, _request: Trigger.Request, response: Trigger.Response
                  ) -> Trigger.Response:
        with self._lock.urgent():
            self._session.reset()
            self._held_step = False          # it answered a sample the reset replaced
            if self._fault is not None:
                self._fault = None
                self._anchor()       # no catching up on the time spent in the fault
            if self._command_steps():        # the reset state is the sample to answer now
                self._initial_pending = False
                self._emit(self._session.current())
            time_s = self._session.sim_time_ns * 1e-9
        response.success = True
        response.message = (f"model reset to its initial state at t = {time_s:.3f} s "
                            f"(sim time runs on)")
        self.get_logger().info(response.message)
        return response

    def _on_off_bottom(self, request: SetBool.Request, response: SetBool.Response
                       ) -> SetBool.Response:
        """The driller's pick-up (true) and tag (false): from the next period, through the
        command delay (SimSession.set_off_bottom); refused on the lumped string."""
        with self._lock.urgent():
            if self._session is None:
                response.success, response.message = False, "not started"
                return response
            try:
                self._session.set_off_bottom(bool(request.data))
            except ParameterError as exc:
                response.success, response.message = False, str(exc)
                return response
        response.success = True
        response.message = "picking up off bottom" if request.data else "tagging bottom"
        return response

    def _on_pause(self, request: SetBool.Request, response: SetBool.Response
                  ) -> SetBool.Response:
        """Pause or resume, in every mode; in command-triggered lockstep a command that
        answers the latest sample while paused is applied, and its period runs on resume."""
        with self._lock.urgent():
            was_paused, self._paused = self._paused, bool(request.data)
            if was_paused and not self._paused:
                self._resume()
            commanded = self._command_steps()
        response.success = True
        response.message = "running"
        if self._paused:
            response.message = PAUSED_COMMAND_LOCKSTEP if commanded else "paused"
        return response

    def _resume(self) -> None:
        """The pause ends: no catching up on it, a lockstep wait counts from now, and the
        period of a command held while paused runs (lock held)."""
        self._anchor()
        self._handshake.restart(time.monotonic())
        held, self._held_step = self._held_step, False
        if held and self._command_steps():
            self._advance(1)

    def _on_step(self, _request: Trigger.Request, response: Trigger.Response
                 ) -> Trigger.Response:
        if not (self._lockstep or self._paused):
            response.message = "~/step needs lockstep:=true or a paused simulation"
        elif self._lockstep and self._values["lockstep_trigger"] == "command":
            response.message = "lockstep_trigger is 'command': each drill/cmd/top_drive " \
                               "message advances one period"
        elif self._fault is not None:
            response.message = f"numerical fault ({self._fault}); call ~/reset"
        else:
            with self._lock.urgent():
                response.success = self._advance(1)
                time_ns = self._session.sim_time_ns
            response.message = f"published t = {time_ns * 1e-9:.6f} s"
        return response

    # ---- diagnostics, status, shutdown -------------------------------------------------
    def _lockstep_mode(self) -> str | None:
        """What advances the sim now: COMMAND_MODE, SERVICE_MODE, or None (it runs by itself,
        or cannot run: a fault, closing, paused) (lock held)."""
        if not self._lockstep or self._fault is not None or self._closing or self._paused:
            return None
        return COMMAND_MODE if self._values["lockstep_trigger"] == "command" else SERVICE_MODE

    def _check_waiting(self) -> None:
        """One warning when lockstep has waited longer than lockstep.warn_after_s."""
        if self._session is None:
            return
        publishers = self._top_drive_publishers()
        with self._lock.urgent():
            self._handshake.check(self._lockstep_mode(), time.monotonic(),
                                  self._values["lockstep.warn_after_s"], publishers)

    def _top_drive_publishers(self) -> int:
        """Publishers matched on drill/cmd/top_drive and on its typed twin."""
        return sum(self._command_subs[topic].get_publisher_count()
                   for topic in (topics.CMD_TOP_DRIVE, topics.TYPED_CMD_TOP_DRIVE)
                   if topic in self._command_subs)

    def _publish_diagnostics(self) -> None:
        """/diagnostics: the figures are copied under the lock, the message is built and
        serialized outside it, so the ticker waits for a copy, not for the formatting."""
        if self._session is None:
            return
        for reason in self._foreign_commands.new_reasons(self):
            self.get_logger().warning(reason)
        with self._lock.urgent():
            time_ns = self._session.sim_time_ns
            figures = self._figures(time_ns)
        payload = serialize_message(self._diagnostics.message(figures, time_ns))
        self._sinks.emit_one(topics.DIAGNOSTICS, payload, time_ns)

    def _figures(self, time_ns: int) -> Figures:
        """What /diagnostics reports, copied (call with the lock held)."""
        sev, stick_fraction = self._session.severity()
        row = self._last_row
        return Figures(
            state=self._state_text(), fault=self._fault,
            sim_time_s=self._session.sim_time_ns * 1e-9, rtf=self._rtf,
            achieved=self._rate.update(time.monotonic_ns(), time_ns * 1e-9),
            overruns=self._pacer.overruns, lateness_ns=self._pacer.lateness_ns(),
            rejected=self.rejected_commands, saturated=self.saturated_commands,
            dropped=self._recorder_count("dropped"),
            record_error=None if self._sinks.recorder is None else self._sinks.recorder.error,
            written=self._recorder_count("written"), severity=sev,
            stick_fraction=stick_fraction,
            mode="none" if row is None else MODE_NAMES[int(row[TELEMETRY_INDEX["mode"]])],
            window_s=self._values["diagnostics.window_s"],
            command_silence_s=None if self._last_command_ns is None else
            (time_ns - self._last_command_ns) * 1e-9,
            command_timeout_s=self._values["diagnostics.command_timeout_s"],
            **self._handshake_figures())

    def _handshake_figures(self) -> dict[str, Any]:
        """The lockstep handshake's part of the figures, and who hears the telemetry (lock
        held)."""
        waiting = self._handshake.waiting(self._lockstep_mode(), time.monotonic())
        return {"stale": self._handshake.gate.stale,
                "lost_commands": self._handshake.lost_commands,
                "command_publishers": self._top_drive_publishers(),
                "telemetry_subscribers": self._pubs[topics.TELEMETRY].get_subscription_count(),
                "waiting": None if waiting is None else waiting.text,
                "waits": self._handshake.watch.waits}

    def _recorder_count(self, name: str) -> int:
        recorder = self._sinks.recorder
        return 0 if recorder is None else int(getattr(recorder, name))

    def _state_text(self) -> str:
        if self._fault is not None:
            return "fault"
        if self._paused:
            return "paused"
        return "lockstep" if self._lockstep else "running"

    def _show_status(self) -> None:
        if not (self._status.active and self._values["status_line"]):
            return
        with self._lock.urgent():
            row = None if self._last_row is None else self._last_row.tolist()
            state = self._state_text()
        if row is not None:
            self._status.show(format_status(row, self._rate.last, state))

    def _on_run_limit(self) -> None:
        self._stop_timer.cancel()
        self._status.close()
        self.get_logger().info(f"run_seconds = {self._values['run_seconds']:g} reached")
        if not self.finished.done():
            self.finished.set_result(True)

    def close(self) -> None:
        """Stop the ticker, then finish the recording and the status line (idempotent)."""
        try:
            with self._lock.urgent():
                self._closing = True
            self._ticker.stop()
            self._status.close()
        finally:                            # whatever failed above, finish the recording
            recorder, self._sinks.recorder = self._sinks.recorder, None
            if recorder is not None:
                self.recording_failed = not recorder.close()
                # after Ctrl-C the context may be gone: a logger of no node has no /rosout
                # publisher
                logger = rclpy.logging.get_logger("drill_sim_ros")
                (logger.error if self.recording_failed else logger.info)(recorder.summary())

    def destroy_node(self) -> None:
        self.close()
        super().destroy_node()


def main(args: list[str] | None = None) -> int:
    """Console script ``sim_node`` (``ros2 run drill_sim_ros sim_node``)."""
    # Ctrl-C stops the node through rclpy alone: its handler (installed by rclpy.init, which
    # calls the one it found) shuts the context down and wakes the executor. Python's own
    # would also raise KeyboardInterrupt at whatever bytecode the main thread is at, even
    # between a lock's acquire and its try, and a HandoffLock lost so leaves close() waiting
    # for ever (seen once in tests/ros/test_colcon.py: the executor's thread in urgent(), the
    # ticker at the gate).
    signal.signal(signal.SIGINT, lambda *_: None)
    try:
        return _run(args)
    finally:
        signal.signal(signal.SIGINT, signal.default_int_handler)


def _run(args: list[str] | None) -> int:
    """:func:`main` with Ctrl-C handled by rclpy alone."""
    try:
        init_ros(args)
    except ParameterError as exc:               # a user's mistake: one line, exit 2
        rclpy.logging.get_logger(topics.NODE_NAME).fatal(str(exc))
        return 2
    # A closed terminal (SIGHUP) stops the node like Ctrl-C or SIGTERM, so the recording is
    # finished instead of cut off without its summary.
    signal.signal(signal.SIGHUP, lambda *_: rclpy.try_shutdown())
    # `kill -USR1 <pid>` prints every thread's stack to stderr: where a node that does not
    # stop is waiting (tests/ros/test_colcon.py asks for it before it gives up on a node)
    faulthandler.register(signal.SIGUSR1, all_threads=True)
    node = None
    try:
        node = SimNode()
        node.start()
        # Everything allocated so far lives for the whole run: keep it out of the cyclic
        # collector, whose full passes over the imported modules stall the ticker ~10-40 ms.
        gc.collect()
        gc.freeze()
        # A ticker waking while the executor's thread runs Python waits for the GIL until that
        # thread blocks or the switch interval (5 ms by default) forces a hand-over.
        sys.setswitchinterval(GIL_SWITCH_INTERVAL_S)
        rclpy.spin_until_future_complete(node, node.finished)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    except RCLError:
        if rclpy.ok():
            raise
        # SIGTERM shut the context down while the executor built its wait set: a clean stop.
    except (DrillSimError, ValueError) as exc:  # refused at start (record.path, preset, ...)
        rclpy.logging.get_logger(topics.NODE_NAME).fatal(str(exc))
        return 2
    finally:
        if node is not None:
            node.destroy_node()
        rclpy.try_shutdown()
    return 1 if node is not None and node.recording_failed else 0


if __name__ == "__main__":
    raise SystemExit(main())
