"""The gateway's ROS side of one rig: the sim_node of one namespace (issue 33).

A :class:`SimLink` sends that sim_node's commands (``<ns>/drill/cmd/top_drive``), takes its
samples (``<ns>/drill/surface/measured``, latched), switches its drive mode (the runtime
parameter ``top_drive.mode``) and keeps its settings (:data:`SIM_PARAMETERS`) in view: it
reads them again whenever sim_node says one changed (``/parameter_events``) or sim_node
started again (its samples' time went back, or a new publisher of them appeared: a restarted
sim_node's parameter events can come before the gateway hears them), retrying until sim_node
answers. Everything but
:meth:`SimLink.send` and :meth:`SimLink.switch_mode` runs in the node's executor thread.
"""

from __future__ import annotations

import concurrent.futures
import contextlib
import time
from collections.abc import Callable
from typing import Any

from rclpy.node import Node
from rclpy.parameter import Parameter, parameter_value_to_python
from rclpy.parameter_client import AsyncParameterClient
from rclpy.task import Future
from sensor_msgs.msg import JointState

from drill_sim_ros import topics
from drill_sim_ros.control.command import Command
from drill_sim_ros.hil.address_space import SAMPLE_VARIABLES
from drill_sim_ros.ros.lockstep_driver import LOCKSTEP_QOS, top_drive_command
from drill_sim_ros.ros.messages import LATEST_SAMPLE_QOS, stamp_ns

SIM_PARAMETERS = ("limits.max_surface_rpm", "limits.max_wob_n", "top_drive.max_torque_nm",
                  "publish_rate_hz",
                  "model.surface_rpm", "model.applied_wob_n", "top_drive.mode", "lockstep",
                  "lockstep_trigger")
MODE_PARAMETER = "top_drive.mode"
READ_TIMEOUT_S = 5.0          # a read of sim_node's parameters unanswered this long is retried


def in_namespace(namespace: str, name: str) -> str:
    """The absolute name of ``name`` (a topic or node, relative) in ``namespace``."""
    return f"{namespace.rstrip('/')}/{name.lstrip('/')}"


def sample_values(msg: JointState) -> tuple[dict[str, float], int]:
    """The read-only values of a drill/surface/measured sample, and its stamp (ns)."""
    time_ns = stamp_ns(msg.header.stamp)
    arrays = {"position": msg.position, "velocity": msg.velocity, "effort": msg.effort}
    values = {v.name: time_ns / 1e9 if v.source[0] == "stamp"
              else float(arrays[v.source[0]][v.source[1]]) for v in SAMPLE_VARIABLES}
    return values, time_ns


def sim_values(response: Any) -> dict[str, Any] | None:
    """SIM_PARAMETERS' values of a GetParameters response (None: some are not declared)."""
    values = [parameter_value_to_python(value) for value in response.values]
    if len(values) != len(SIM_PARAMETERS) or any(v is None for v in values):
        return None
    return dict(zip(SIM_PARAMETERS, values, strict=True))


class SimLink:
    """The sim_node ``sim_node`` in ``namespace``, served as the rig object ``rig``.
    ``on_sample(values, stamp_ns)`` and ``on_settings(sim)`` are called in the executor
    thread."""

    def __init__(self, node: Node, namespace: str, sim_node: str, rig: str) -> None:
        self.namespace, self.rig = namespace, rig
        self.sim_node = in_namespace(namespace, sim_node)
        self._pub = node.create_publisher(JointState, in_namespace(
            namespace, topics.CMD_TOP_DRIVE), LOCKSTEP_QOS)
        self._node = node
        self._samples_topic = in_namespace(namespace, topics.SURFACE_MEASURED)
        node.create_subscription(JointState, self._samples_topic, self._on_sample,
                                 LATEST_SAMPLE_QOS)
        self._publishers: frozenset[bytes] = frozenset()    # of the samples, last seen
        self.on_restart: Callable[[], None] | None = None
        self.parameters = AsyncParameterClient(node, self.sim_node)
        self.on_sample: Callable[[dict[str, float], int], None] | None = None
        self.on_settings: Callable[[dict[str, Any]], None] | None = None
        self.latest_sample: tuple[dict[str, float], int] | None = None   # (before on_sample)
        self.figures: Callable[[], dict[str, str]] | None = None         # once served
        self.rejected_before = "0"                                       # (diagnostics)
        self.stale = False                   # sim_node's settings are to be read again
        self._read: Future | None = None
        self._read_since_s = 0.0

    # -- samples and commands -------------------------------------------------------------
    def _on_sample(self, msg: JointState) -> None:
        values, time_ns = sample_values(msg)
        if self.latest_sample is not None and time_ns < self.latest_sample[1]:
            self.want_settings()               # sim_node started again: its settings too
        self.latest_sample = (values, time_ns)
        if self.on_sample is not None:
            self.on_sample(values, time_ns)

    def send(self, command: Command, stamp_ns: int) -> None:
        """The command answering the sample stamped ``stamp_ns`` (from any thread)."""
        self._pub.publish(top_drive_command(command, stamp_ns))

    # -- sim_node's settings --------------------------------------------------------------
    def on_parameter_event(self, msg: Any) -> None:
        """A ``/parameter_events`` message: read the settings again if it touches them."""
        if msg.node != self.sim_node:
            return
        names = {p.name for p in (*msg.new_parameters, *msg.changed_parameters)}
        if names & set(SIM_PARAMETERS):
            self.want_settings()

    def want_settings(self) -> None:
        self.stale = True
        self.poll()

    def watch_publishers(self) -> None:
        """A new publisher of the samples (a sim_node started again, whatever its time): its
        settings are read again and ``on_restart`` is called."""
        gids = frozenset(bytes(info.endpoint_gid) for info in
                         self._node.get_publishers_info_by_topic(self._samples_topic))
        if not gids:
            return                             # gone: wait for the next one
        new = self._publishers and not gids <= self._publishers
        self._publishers = gids
        if new:
            self.stale = True
            if self.on_restart is not None:
                self.on_restart()

    def poll(self) -> None:
        """Read the settings if they are stale, sim_node answers and no read is under way
        (one unanswered for READ_TIMEOUT_S is given up and made again)."""
        if self._read is not None:
            if time.monotonic() - self._read_since_s < READ_TIMEOUT_S:
                return
            given_up, self._read = self._read, None
            given_up.cancel()
            self.stale = True
        if not self.stale or not self.parameters.services_are_ready():
            return
        self.stale = False
        self._read_since_s = time.monotonic()
        self._read = self.parameters.get_parameters(list(SIM_PARAMETERS))
        self._read.add_done_callback(self._on_read)

    def _on_read(self, future: Future) -> None:
        if future is not self._read:
            return                             # given up already
        self._read = None
        sim = sim_values(future.result())
        if sim is None:
            self.stale = True                  # declared soon (sim_node is starting): retry
        elif self.on_settings is not None:
            self.on_settings(sim)
        if self.stale:
            self.poll()

    # -- the drive mode -------------------------------------------------------------------
    def switch_mode(self, mode: str) -> concurrent.futures.Future[str | None]:
        """Set sim_node's ``top_drive.mode`` (from any thread): None once it drives in
        ``mode``, or its reason for refusing; TimeoutError if it is not there."""
        result: concurrent.futures.Future[str | None] = concurrent.futures.Future()
        if not self.parameters.services_are_ready():
            result.set_exception(TimeoutError(f"{self.sim_node} does not answer"))
            return result

        def done(future: Future) -> None:
            outcome = future.result().results[0]
            with contextlib.suppress(concurrent.futures.InvalidStateError):   # given up
                result.set_result(None if outcome.successful else outcome.reason or "refused")

        self.parameters.set_parameters([Parameter(MODE_PARAMETER, value=mode)], done)
        return result
