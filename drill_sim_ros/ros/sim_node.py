"""sim_node: the real-time ROS 2 node around the RGD07 drill-bit simulator (node ``drill_sim``).

Publishes the bit and surface state at ``publish_rate_hz`` of simulated time (stamps in
simulated time, one stamp per sample on every topic), /diagnostics at 1 Hz wall and /clock;
takes surface-rpm and WOB setpoints; serves ~/reset, ~/pause and ~/step (lockstep).
Pacing follows the monotonic clock without drift (:mod:`drill_sim_ros.ros.pacing`).

Threads: a :class:`~drill_sim_ros.ros.ticker.Ticker` advances and publishes the samples
(starting with the first spin of the node); the executor's thread runs the commands,
services, parameter callbacks and 1 Hz timers. Both take the node's :class:`HandoffLock`
before touching the session, the schedule or the recorder. Lockstep uses no ticker.
"""

from __future__ import annotations

import gc
import math
import signal
import sys
import time
from collections.abc import Callable
from typing import Any

import numpy as np
import rclpy
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
from rcl_interfaces.msg import SetParametersResult
from rclpy.clock import Clock, ClockType
from rclpy.event_handler import PublisherEventCallbacks
from rclpy.executors import ExternalShutdownException
from rclpy.impl.implementation_singleton import rclpy_implementation
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.qos import HistoryPolicy, QoSProfile, ReliabilityPolicy
from rclpy.serialization import serialize_message
from rclpy.task import Future
from std_msgs.msg import Float64
from std_srvs.srv import SetBool, Trigger

from drill_sim_ros import topics
from drill_sim_ros.model.errors import DrillSimError, NumericalFault, ParameterError
from drill_sim_ros.model.presets import load_preset
from drill_sim_ros.ros import messages
from drill_sim_ros.ros.command_types import ForeignCommandTypes
from drill_sim_ros.ros.conversions import stamp
from drill_sim_ros.ros.engine import EXIT_WAIT, R_SAMPLES, TickLoop
from drill_sim_ros.ros.frame import SAMPLE_TOPICS, FramePublisher, SampleFrame
from drill_sim_ros.ros.pacing import Pacer, RateMeter, lateness_percentiles_ms
from drill_sim_ros.ros.parameters import (
    SPEC_BY_NAME,
    coerce,
    declare_all,
    init_ros,
    recording_options,
    validate,
)
from drill_sim_ros.ros.session import SessionConfig, SimSession
from drill_sim_ros.ros.status_line import StatusLine, format_status
from drill_sim_ros.ros.ticker import SHORT_WAIT_S, HandoffLock, Ticker

RCLError = rclpy_implementation.RCLError
DATA_QOS = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=100,
                      reliability=ReliabilityPolicy.RELIABLE)
CLOCK_QOS = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=10,
                       reliability=ReliabilityPolicy.RELIABLE)
COMMAND_QOS = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=10,
                         reliability=ReliabilityPolicy.RELIABLE)
# Reliable volatile publishers match every subscriber but transient-local ones; without the
# default QoS-event handlers the executor's wait set is 2 entities per publisher smaller.
QUIET_PUBLISHER = PublisherEventCallbacks(use_default_callbacks=False)
FREE_RUN_BATCH = 20          # periods per kernel call when running as fast as possible
MAX_CATCH_UP = 50            # periods per kernel call when catching up in real time
MAX_RUN = 1 << 30            # samples per compiled run (the severity window stops it sooner)
DIAGNOSTICS_PERIOD_S = 1.0
STATUS_PERIOD_S = 0.25
WARN_THROTTLE_S = 1.0
GIL_SWITCH_INTERVAL_S = 0.0005


def session_config(values: dict[str, Any], preset: Any) -> SessionConfig:
    """The session settings from the declared parameter values."""
    return SessionConfig(
        preset=preset, publish_rate_hz=values["publish_rate_hz"],
        dtau_max=values["model.dtau"], n_nodes=values["model.n_nodes"],
        perturb_v=values["model.perturb_v"], applied_wob_n=values["model.applied_wob_n"],
        surface_rpm=values["model.surface_rpm"],
        top_drive_accel_rpm_s=values["limits.top_drive_accel_rpm_s"],
        wob_rate_n_s=values["limits.wob_rate_n_s"], window_s=values["diagnostics.window_s"])


def command_problem(value: float, limit: float, unit: str) -> str | None:
    """Why a setpoint command is unacceptable (None if it is fine)."""
    if not math.isfinite(value):
        return f"{value!r} is not finite"
    if value < 0.0:
        return f"{value!r} {unit} is negative"
    if value > limit:
        return f"{value!r} {unit} exceeds the limit {limit!r} {unit}"
    return None


class SimNode(Node):
    """The ``drill_sim`` node; ``finished`` completes when ``run_seconds`` have passed."""

    def __init__(self, **node_kwargs: Any) -> None:
        super().__init__(topics.NODE_NAME, **node_kwargs)
        self._steady = Clock(clock_type=ClockType.STEADY_TIME)
        self._preset, self._values = declare_all(self, load_preset)
        self._session = SimSession(session_config(self._values, self._preset))
        self._lock = HandoffLock()
        self._pacer = Pacer(self._wall_period_ns(1.0))
        self._rate = RateMeter(time.monotonic_ns(), 0.0)
        self._status = StatusLine()
        self.finished = Future()
        self._paused = False
        self._closing = False
        self._fault: str | None = None
        self.recording_failed = False
        self._foreign_commands = ForeignCommandTypes(
            {t: topics.MSG_TYPES[t] for t in (topics.CMD_SURFACE_RPM, topics.CMD_WOB)})
        self.rejected_commands = 0
        self._last_row: np.ndarray | None = None     # SI, TELEMETRY_FIELDS; lock held
        self._pubs = {t: self.create_publisher(messages.type_of(t), t, self._qos(t),
                                               event_callbacks=QUIET_PUBLISHER)
                      for t in (*SAMPLE_TOPICS, topics.CLOCK, topics.DIAGNOSTICS)}
        self._frame_publishers = {with_clock: self._frame_publisher(with_clock)
                                  for with_clock in (False, True)}
        self._recorder = self._open_recorder(self._values["record.path"])
        self.create_subscription(Float64, topics.CMD_SURFACE_RPM, self._on_surface_rpm,
                                 COMMAND_QOS)
        self.create_subscription(Float64, topics.CMD_WOB, self._on_wob, COMMAND_QOS)
        self.create_service(Trigger, "~/reset", self._on_reset)
        self.create_service(SetBool, "~/pause", self._on_pause)
        self.create_service(Trigger, "~/step", self._on_step)
        self._ticker = Ticker(self._tick, self._on_tick_error, name="drill_sim_ticker")
        self._lock.on_request = self._ticker.wake     # the compiled loop waits on its eventfd
        self._loop = self._tick_loop()
        self._first_spin = self.create_timer(0.0, self._start_ticker, clock=self._steady)
        self.create_timer(DIAGNOSTICS_PERIOD_S, self._publish_diagnostics, clock=self._steady)
        if self._status.active:
            self.create_timer(STATUS_PERIOD_S, self._show_status, clock=self._steady)
        self._stop_timer = self._start_run_limit(self._values["run_seconds"])
        self.add_on_set_parameters_callback(self._validate_parameters)
        self.add_post_set_parameters_callback(self._apply_parameters)
        self._log_start()

    # ---- set-up ------------------------------------------------------------------------
    def _tick_loop(self) -> TickLoop | None:
        """The compiled tick loop, or None (then the ticker runs the Python path) where rcl's
        publish call or the C library's clocks cannot be bound."""
        if not all(p.compiled for p in self._frame_publishers.values()):
            return None
        try:
            loop = TickLoop(self._lock.requests, self._ticker.wake_fd, MAX_CATCH_UP,
                            FREE_RUN_BATCH, round(SHORT_WAIT_S * 1e9))
        except (OSError, AttributeError) as exc:
            self.get_logger().warning(f"ticking in Python: {exc}")
            return None
        # load the compiled loop now (a run of no samples), not on the first tick
        loop.run(self._session, self._frame_publishers[False], self._pacer, 0, 0.0)
        return loop

    def _frame_publisher(self, with_clock: bool) -> FramePublisher:
        frame = SampleFrame(self._preset.scales, with_clock)
        return FramePublisher(frame, [self._pubs[topic] for topic in frame.topics])

    @staticmethod
    def _qos(topic: str) -> QoSProfile:
        return CLOCK_QOS if topic in (topics.CLOCK, topics.DIAGNOSTICS) else DATA_QOS

    def _open_recorder(self, path: str) -> Any:
        """The in-process MCAP recorder of ``record.path`` (None when off). An existing or
        unwritable path raises one ArchiveError line: the node does not start."""
        if not path:
            return None
        from drill_sim_ros.archive.inprocess import InProcessRecorder
        recorder = InProcessRecorder(path, node_name=topics.NODE_NAME,
                                     metadata=self._run_metadata(),
                                     **recording_options(self._values))
        for topic in self._pubs:
            recorder.add_topic(topic, topics.MSG_TYPES[topic], self._qos(topic))
        self.get_logger().info(f"recording to {path}")
        return recorder

    def _run_metadata(self) -> dict[str, str]:
        """What a recording needs to be read back alone (mcap_to_rerun takes the preset)."""
        sc = self._preset.scales
        return {"preset": self._preset.name, "publish_rate_hz": str(self._values[
            "publish_rate_hz"]), "dtau": repr(self._session.dtau),
            "t_star_s": repr(sc.time_s), "l_star_m": repr(sc.length_m),
            "force_unit_n": repr(sc.force_n), "torque_unit_nm": repr(sc.torque_nm)}

    def _start_run_limit(self, run_seconds: float) -> Any:
        if run_seconds <= 0:
            return None
        return self.create_timer(run_seconds, self._on_run_limit, clock=self._steady)

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
        return SetParametersResult(successful=True)

    def _apply_parameters(self, params: list[Parameter]) -> None:
        with self._lock.urgent():
            for param in params:
                if param.name in SPEC_BY_NAME:
                    self._values[param.name] = coerce(SPEC_BY_NAME[param.name], param.value)
            if any(p.name in ("real_time_factor", "lockstep") for p in params):
                self._restart_ticks()

    # ---- pacing ------------------------------------------------------------------------
    def _wall_period_ns(self, rtf: float) -> int:
        return max(1, round(self._session.period_ns / rtf)) if rtf > 0 else 1

    def _start_ticker(self) -> None:
        """First spin: anchor the schedule and start the ticker thread."""
        self.destroy_timer(self._first_spin)
        with self._lock.urgent():
            self._restart_ticks()
        self._ticker.start()

    def _restart_ticks(self) -> None:
        """New schedule for the current factor, anchored now (call with the lock held)."""
        self._pacer = Pacer(self._wall_period_ns(self._rtf))
        self._anchor()

    def _anchor(self) -> None:
        """The next tick is due now; wake the ticker (call with the lock held)."""
        self._pacer.anchor(time.monotonic_ns())
        self._ticker.wake()

    def _tick(self) -> float | None:
        """One turn of the ticker thread; the seconds to wait before the next (None: idle)."""
        self._lock.acquire_background()
        try:
            if self._closing or self._lockstep or self._paused or self._fault is not None:
                return None
            if self._loop is not None:
                return self._run_loop()
            if self._rtf <= 0:
                self._advance(FREE_RUN_BATCH)
                return 0.0
            pacer = self._pacer
            count = pacer.due(time.monotonic_ns(), MAX_CATCH_UP)
            if count > 0 and self._advance(count):
                pacer.complete(count, time.monotonic_ns())
            return max(0.0, (pacer.deadline_ns() - time.monotonic_ns()) * 1e-9)
        finally:
            self._lock.release()

    def _run_loop(self) -> float | None:
        """Hand the ticker to the compiled loop until Python has work (lock held)."""
        publisher = self._frame_publishers[self._values["publish_clock"]]
        time_ns = self._session.sim_time_ns
        try:
            reason = self._loop.run(
                self._session, publisher, None if self._rtf <= 0 else self._pacer,
                MAX_RUN if self._recorder is None else 1,
                self._values["model.submerged_string_weight_n"])
        except NumericalFault as exc:
            self._on_fault(exc)
            return None
        if self._loop.result[R_SAMPLES] > 0:
            self._last_row = publisher.frame.row
            if self._recorder is not None:
                self._record(publisher.frame, time_ns)
        if reason == EXIT_WAIT:
            return max(0.0, (self._pacer.deadline_ns() - time.monotonic_ns()) * 1e-9)
        return 0.0

    def _on_tick_error(self, exc: Exception) -> bool:
        """An unexpected error on the ticker: quiet at shutdown, else a fault until reset."""
        if not self.context.ok():
            return False             # SIGINT/SIGTERM shut the context down mid-publish
        with self._lock.urgent():
            self._fault = f"internal error: {exc!r}"
        self.get_logger().error(f"ticker: {exc!r}; call ~/reset to resume")
        return True

    def _advance(self, periods: int) -> bool:
        """Simulate and publish ``periods`` samples; False on a numerical fault."""
        session = self._session
        try:
            time_ns, count = session.run(periods)
        except NumericalFault as exc:
            self._on_fault(exc)
            return False
        # One compiled call fills and publishes the samples through rcl (FramePublisher);
        # sim_node destroys no publisher while it ticks. (Lockstep, and the Python ticker.)
        publisher = self._frame_publishers[self._values["publish_clock"]]
        weight_n = self._values["model.submerged_string_weight_n"]
        offsets, period_ns = session.sim.offsets, session.period_ns
        if self._recorder is None:
            publisher.publish(session.samples, 0, count, offsets, time_ns, period_ns, weight_n)
        else:
            for index in range(count):
                publisher.publish(session.samples, index, 1, offsets, time_ns, period_ns,
                                  weight_n)
                self._record(publisher.frame, time_ns)
                time_ns += period_ns
        if count:
            self._last_row = publisher.frame.row
        return True

    def _record(self, frame: SampleFrame, time_ns: int) -> None:
        """The very bytes just published, unchanged (recorder on, lock held)."""
        for topic, payload in zip(frame.topics, frame.payloads(), strict=True):
            self._recorder.write_serialized(topic, payload, time_ns)

    def _on_fault(self, exc: NumericalFault) -> None:
        self._fault = str(exc)
        self.get_logger().error(f"numerical fault: {exc}; call ~/reset to recover")

    # ---- commands ----------------------------------------------------------------------
    def _on_surface_rpm(self, msg: Float64) -> None:
        self._command(topics.CMD_SURFACE_RPM, msg.data, "limits.max_surface_rpm", "rev/min",
                      self._session.set_surface_rpm)

    def _on_wob(self, msg: Float64) -> None:
        self._command(topics.CMD_WOB, msg.data, "limits.max_wob_n", "N", self._session.set_wob_n)

    def _command(self, topic: str, value: float, limit: str, unit: str,
                 apply: Callable[[float], None]) -> None:
        """Apply a setpoint at the next step, or reject it (counted) and keep the last one."""
        problem = command_problem(value, self._values[limit], unit)
        if problem is not None:
            self._reject(topic, problem)
            return
        # No lock: a setpoint is one float64 store into the kernel's targets, which the
        # ticker's next step reads (the compiled loop holds the lock through its sleeps).
        apply(value)

    def _reject(self, topic: str, problem: str) -> None:
        self.rejected_commands += 1
        self.get_logger().warning(
            f"rejected {topic}: {problem}; the last valid setpoint stays "
            f"({self.rejected_commands} rejected so far)", throttle_duration_sec=WARN_THROTTLE_S)

    # ---- services ----------------------------------------------------------------------
    def _on_reset(self, _request: Trigger.Request, response: Trigger.Response
                  ) -> Trigger.Response:
        with self._lock.urgent():
            self._session.reset()
            if self._fault is not None:
                self._fault = None
                self._anchor()       # no catching up on the time spent in the fault
            time_s = self._session.sim_time_ns * 1e-9
        response.success = True
        response.message = (f"model reset to its initial state at t = {time_s:.3f} s "
                            f"(sim time runs on)")
        self.get_logger().info(response.message)
        return response

    def _on_pause(self, request: SetBool.Request, response: SetBool.Response
                  ) -> SetBool.Response:
        with self._lock.urgent():
            was_paused, self._paused = self._paused, bool(request.data)
            if was_paused and not self._paused:
                self._anchor()
        response.success = True
        response.message = "paused" if self._paused else "running"
        return response

    def _on_step(self, _request: Trigger.Request, response: Trigger.Response
                 ) -> Trigger.Response:
        if not (self._lockstep or self._paused):
            response.message = "~/step needs lockstep:=true or a paused simulation"
        elif self._fault is not None:
            response.message = f"numerical fault ({self._fault}); call ~/reset"
        else:
            with self._lock.urgent():
                time_ns = self._session.sim_time_ns
                response.success = self._advance(1)
            response.message = f"published t = {time_ns * 1e-9:.6f} s"
        return response

    # ---- diagnostics, status, shutdown -------------------------------------------------
    def _publish_diagnostics(self) -> None:
        """/diagnostics: the figures are read under the lock, the message is built and
        serialized outside it, so the ticker waits for a copy, not for the formatting."""
        for reason in self._foreign_commands.new_reasons(self):
            self.get_logger().warning(reason)
        with self._lock.urgent():
            time_ns = max(0, self._session.sim_time_ns - self._session.period_ns)
            figures = self._figures(time_ns)
        msg = DiagnosticArray(status=[self._node_status(figures),
                                      self._dynamics_status(figures)])
        msg.header.stamp = stamp(time_ns)
        payload = serialize_message(msg)
        self._pubs[topics.DIAGNOSTICS].publish(payload)
        if self._recorder is not None:   # its queue takes producers on any thread, no lock
            self._recorder.write_serialized(topics.DIAGNOSTICS, payload, time_ns)

    def _figures(self, time_ns: int) -> dict[str, Any]:
        """What /diagnostics reports, copied (call with the lock held)."""
        sev, stick_fraction = self._session.severity()
        row = self._last_row
        return {
            "state": self._state_text(), "fault": self._fault,
            "sim_time_s": self._session.sim_time_ns * 1e-9, "rtf": self._rtf,
            "achieved": self._rate.update(time.monotonic_ns(), time_ns * 1e-9),
            "overruns": self._pacer.overruns, "lateness_ns": self._pacer.lateness_ns(),
            "rejected": self.rejected_commands, "dropped": self._recorder_count("dropped"),
            "written": self._recorder_count("written"), "severity": sev,
            "record_error": None if self._recorder is None else self._recorder.error,
            "stick_fraction": stick_fraction,
            "mode": "none" if row is None else topics.MODE_NAMES[
                int(row[topics.TELEMETRY_INDEX["mode"]])],
            "window_s": self._values["diagnostics.window_s"],
        }

    @staticmethod
    def _node_status(f: dict[str, Any]) -> DiagnosticStatus:
        p50, p99 = lateness_percentiles_ms(f["lateness_ns"], 50, 99)
        values = {
            "state": f["state"],
            "sim_time_s": f"{f['sim_time_s']:.3f}",
            "real_time_factor_target": f"{f['rtf']:g}",
            "real_time_factor_achieved": f"{f['achieved']:.4g}",
            "overruns": str(f["overruns"]),
            "tick_lateness_p50_ms": f"{p50:.4g}",
            "tick_lateness_p99_ms": f"{p99:.4g}",
            "rejected_commands": str(f["rejected"]),
            "recorder_dropped": str(f["dropped"]),
            "recorder_written": str(f["written"]),
            "fault": f["fault"] or "",
            "recorder_error": f["record_error"] or "",
        }
        if f["fault"] is not None:
            level, message = DiagnosticStatus.ERROR, f"numerical fault: {f['fault']}"
        elif f["record_error"] is not None:
            level, message = DiagnosticStatus.ERROR, f"recording stopped: {f['record_error']}"
        elif f["overruns"] or f["dropped"]:
            level, message = DiagnosticStatus.WARN, "overruns or recorder drops"
        else:
            level, message = DiagnosticStatus.OK, f["state"]
        return messages.status(f"{topics.NODE_NAME}: simulation", level, message, values)

    @staticmethod
    def _dynamics_status(f: dict[str, Any]) -> DiagnosticStatus:
        sev, stick_fraction = f["severity"], f["stick_fraction"]
        values = {"mode": f["mode"], "stick_slip_severity": f"{sev.ssi:.4g}",
                  "under_torque_ratio": f"{sev.utr:.4g}",
                  "stick_fraction": f"{stick_fraction:.4g}",
                  "window_s": f"{f['window_s']:g}"}
        stick_slip = stick_fraction > 0 or sev.ssi > 0.5
        level = DiagnosticStatus.WARN if stick_slip else DiagnosticStatus.OK
        message = "stick-slip" if stick_slip else "smooth drilling"
        return messages.status(f"{topics.NODE_NAME}: bit dynamics", level, message, values)

    def _recorder_count(self, name: str) -> int:
        return 0 if self._recorder is None else int(getattr(self._recorder, name))

    def _state_text(self) -> str:
        if self._fault is not None:
            return "fault"
        if self._paused:
            return "paused"
        return "lockstep" if self._lockstep else "running"

    def _show_status(self) -> None:
        with self._lock.urgent():
            row = None if self._last_row is None else self._last_row.tolist()
            state = self._state_text()
        if self._values["status_line"] and row is not None:
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
            if self._recorder is not None:
                recorder, self._recorder = self._recorder, None
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
    try:
        init_ros(args)
    except ParameterError as exc:
        rclpy.logging.get_logger(topics.NODE_NAME).fatal(str(exc))
        return 1
    # A closed terminal (SIGHUP) stops the node like Ctrl-C or SIGTERM, so the recording is
    # finished instead of cut off without its summary.
    signal.signal(signal.SIGHUP, lambda *_: rclpy.try_shutdown())
    node = None
    try:
        node = SimNode()
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
    except (DrillSimError, ValueError) as exc:
        rclpy.logging.get_logger(topics.NODE_NAME).fatal(str(exc))
        return 1
    finally:
        if node is not None:
            node.destroy_node()
        rclpy.try_shutdown()
    return 1 if node is not None and node.recording_failed else 0


if __name__ == "__main__":
    raise SystemExit(main())
