"""opcua_gateway: sim_node's surface and commands as an OPC UA server (node ``opcua_gateway``).

A PLC's controller closes the loop through it (hardware in the loop, docs/hil.md). One
gateway serves one rig per sim_node namespace of its ``rigs`` parameter (default: its own
namespace). The ROS side of each is a :class:`~drill_sim_ros.ros.sim_link.SimLink`, a
lockstep driver of that sim_node (the handshake of docs/control-loop.md): it reads
``<ns>/drill/surface/measured`` (latched), and sends each command on ``<ns>/drill/cmd/top_drive``
stamped with the latest sample; the OPC UA side is a
:class:`~drill_sim_ros.hil.rig_server.Rig` of the one
:class:`~drill_sim_ros.hil.rig_server.RigServer`, which decides when a command goes (a
client's ``CommandCounter`` or ``Step``).

rclpy spins in a thread of its own; samples and settings cross into asyncua's event loop
through a queue, in order. The setpoints' EURanges, the setpoints in force, the drive mode and
``Lockstep`` come from each sim_node's parameters (one source: its ``limits.*``), read at
start and again whenever they change or sim_node starts again.

    sim_node --ros-args -p lockstep:=true -p lockstep_trigger:=command
    opcua_gateway --ros-args -p endpoint:=opc.tcp://127.0.0.1:4840/drill_sim/
    opcua_gateway --ros-args -p "rigs:=[/site/rig1, /site/rig2]"    # two sim_nodes, one server
"""

from __future__ import annotations

import asyncio
import contextlib
import functools
import logging
import signal
import sys
import time
from collections.abc import Awaitable, Callable
from dataclasses import dataclass
from typing import Any

import rclpy
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
from rcl_interfaces.msg import FloatingPointRange, ParameterDescriptor, ParameterEvent
from rclpy.exceptions import InvalidNamespaceException
from rclpy.executors import ExternalShutdownException, SingleThreadedExecutor
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.qos import qos_profile_parameter_events
from rclpy.validate_namespace import validate_namespace

from drill_sim_ros import topics
from drill_sim_ros.hil.address_space import DEFAULT_ENDPOINT, rig_name
from drill_sim_ros.hil.endpoint import check_endpoint
from drill_sim_ros.hil.rig_server import Rig, RigServer, RigSettings, RigTiming
from drill_sim_ros.hil.security import SETTINGS as SECURITY_SETTINGS
from drill_sim_ros.hil.security import load_security
from drill_sim_ros.model.errors import DrillSimError, ParameterError
from drill_sim_ros.ros.messages import status
from drill_sim_ros.ros.parameters import init_ros
from drill_sim_ros.ros.sim_link import SIM_PARAMETERS, SimLink, sim_values
from drill_sim_ros.ros.spinning import SpinThread

NODE_NAME = "opcua_gateway"
USAGE = """usage: opcua_gateway [--ros-args -p endpoint:=opc.tcp://127.0.0.1:4840/drill_sim/ ...]
       opcua_gateway --export-nodeset FILE [--ros-args ...]

sim_node's surface and commands as an OPC UA server, for a PLC's controller in the loop
(docs/hil.md). Its settings are ROS parameters (-p "rigs:=[/rig1, /rig2]" serves the
sim_nodes of two namespaces); start sim_node first. --export-nodeset FILE writes the address
space (with sim_node's ranges) as NodeSet2 XML for a PLC project, and exits."""
GIL_SWITCH_INTERVAL_S = 0.0005    # as sim_node's: a thread waiting for the GIL waits less
POLL_S = 0.2
STOP_SIGNALS = (signal.SIGINT, signal.SIGTERM)
DIAGNOSTICS_PERIOD_S = 1.0        # wall time, as sim_node's
SETTINGS_RETRY_S = 0.5            # how often stale sim_node settings are asked for again
PROGRESS_S = 5.0                  # a line while the gateway waits for sim_node at start


@dataclass(frozen=True)
class Setting:
    """One of the gateway's (read-only) ROS parameters; ``default`` None: an unset string
    array; ``bounded``: a value of 0.1 ... 3600 (a duration in s, or the safe ramp)."""

    name: str
    default: Any
    description: str
    bounded: bool = False

    def descriptor(self) -> ParameterDescriptor:
        desc = ParameterDescriptor(description=self.description, read_only=True)
        if self.bounded:
            desc.floating_point_range = [FloatingPointRange(from_value=MIN_SECONDS,
                                                            to_value=MAX_SECONDS, step=0.0)]
        return desc

    def declared(self, node: Node) -> Any:
        """Declare it on ``node``; its value (None: an unset array)."""
        default = Parameter.Type.STRING_ARRAY if self.default is None else self.default
        return node.declare_parameter(self.name, default, self.descriptor()).value


MIN_SECONDS, MAX_SECONDS = 0.1, 3600.0
SETTINGS = (
    Setting("endpoint", DEFAULT_ENDPOINT, "opc.tcp://HOST:PORT/PATH the OPC UA server listens "
            "on (loopback unless secured)"),
    Setting("rigs", None, "the sim_node namespaces served, one rig object each, named after "
            "the namespace's last part (a relative one is in this node's namespace); unset: "
            "this node's namespace"),
    Setting("rig", "", "BrowseName of a lone rig's object; '' = the namespace's last part, "
            "or Rig in /"),
    Setting("sim_node", topics.NODE_NAME, "sim_node's node name, in each rig's namespace"),
    Setting("sim_wait_s", 120.0, "how long to wait at start for each sim_node's parameters, "
            "asking again until all are declared (a line every 5 s) [s]", bounded=True),
    Setting("step_timeout_s", 0.5, "Step returns BadTimeout after this many wall seconds "
            "without the sample; the session's other requests wait behind it, so keep it below "
            "the client's own timeouts (asyncua's watchdog: 1 s) [s]", bounded=True),
    Setting("heartbeat_timeout_s", 2.0, "the owner of the setpoints that writes nothing (nor "
            "calls Step) for this long loses them; in free run the drive then stops safely "
            "(HeartbeatLost, Reset to go on) [s]", bounded=True),
    Setting("sim_timeout_s", 2.0, "a command unanswered (in free run: no sample) for this "
            "long makes Status SimLost [s]", bounded=True),
    Setting("safe_ramp_rad_s2", 2.0, "the safe stop's ramp of the speed setpoint to 0 "
            "[rad/s per s of simulated time]", bounded=True),
    Setting("security.certificate", "", "the server's certificate, DER or PEM, with the URI "
            "urn:drill_sim_ros:opcua_gateway ('' = not secured: loopback only)"),
    Setting("security.private_key", "", "the certificate's private key, PEM"),
    Setting("security.user", "", "the one user name a client must give"),
    Setting("security.password_file", "", "a file whose first line is that user's password"),
)


def _default_text(default: Any) -> str:
    if default is None:
        return "unset"
    if isinstance(default, float):
        return f"`{default:g}`"
    return f"`{default}`" if default else "`''`"


def settings_table() -> str:
    """The gateway's parameters as the Markdown table of docs/hil.md."""
    rows = ["| parameter | default | meaning |", "| --- | --- | --- |"]
    for s in SETTINGS:
        rows.append(f"| `{s.name}` | {_default_text(s.default)} | {s.description} |")
    return "\n".join(rows)


def rig_namespaces(listed: list[str] | None, own: str) -> list[str]:
    """The absolute sim_node namespaces of the ``rigs`` parameter (relative ones are in the
    gateway's namespace ``own``; none listed: ``own``); ParameterError for a bad one."""
    namespaces = []
    for name in listed or [own]:
        absolute = name if name.startswith("/") else f"{own.rstrip('/')}/{name}"
        absolute = absolute.rstrip("/") or "/"
        try:
            validate_namespace(absolute)
        except InvalidNamespaceException:
            raise ParameterError(f"rigs: {name!r} is not a ROS namespace") from None
        namespaces.append(absolute)
    return namespaces


def rig_names(namespaces: list[str], rig: str) -> list[str]:
    """The rig objects' BrowseNames: each namespace's last part (``rig`` names a lone rig);
    ParameterError when two are the same."""
    if rig and len(namespaces) > 1:
        raise ParameterError(f"rig {rig!r} names one rig; rigs lists {len(namespaces)} (their "
                             "objects take their namespaces' last parts)")
    names = [rig] if rig else [rig_name(ns) for ns in namespaces]
    twice = sorted({n for n in names if names.count(n) > 1})
    if twice:
        raise ParameterError(f"rigs: two rigs would both be called {twice[0]!r} (the "
                             "namespaces' last parts must differ)")
    return names


class GatewayNode(Node):
    """The ROS side: one :class:`SimLink` per rig, the parameters, the diagnostics."""

    def __init__(self, **node_kwargs: Any) -> None:
        super().__init__(NODE_NAME, **node_kwargs)
        values = {s.name: s.declared(self) for s in SETTINGS}
        self.endpoint = values["endpoint"]
        self.sim_wait_s = values["sim_wait_s"]
        self.timing = RigTiming(**{name: values[name] for name in (
            "step_timeout_s", "heartbeat_timeout_s", "sim_timeout_s", "safe_ramp_rad_s2")})
        self.security = load_security({name: values[name] for name in SECURITY_SETTINGS})
        listed, rig, sim_node = values["rigs"], values["rig"], values["sim_node"]
        namespaces = rig_namespaces(list(listed or []), self.get_namespace())
        self.links = [SimLink(self, ns, sim_node, name) for ns, name in
                      zip(namespaces, rig_names(namespaces, rig), strict=True)]
        self._diagnostics = self.create_publisher(DiagnosticArray, topics.DIAGNOSTICS, 10)
        self.create_timer(DIAGNOSTICS_PERIOD_S, self._publish_diagnostics)
        self.create_subscription(ParameterEvent, "/parameter_events", self._on_parameter_event,
                                 qos_profile_parameter_events)
        self.create_timer(SETTINGS_RETRY_S, self._poll_settings)

    def _on_parameter_event(self, msg: ParameterEvent) -> None:
        for link in self.links:
            link.on_parameter_event(msg)

    def _poll_settings(self) -> None:
        for link in self.links:
            link.watch_publishers()
            link.poll()

    def _publish_diagnostics(self) -> None:
        """``opcua_gateway: <rig>`` per rig: WARN when writes were refused since the last."""
        statuses = [self._rig_status(link) for link in self.links if link.figures is not None]
        if not statuses:
            return
        msg = DiagnosticArray(status=statuses)
        msg.header.stamp = self.get_clock().now().to_msg()
        self._diagnostics.publish(msg)

    def _rig_status(self, link: SimLink) -> DiagnosticStatus:
        values = {"endpoint": self.endpoint, "namespace": link.namespace, **link.figures()}
        refused = values["rejected_writes"] != link.rejected_before
        link.rejected_before = values["rejected_writes"]
        level = DiagnosticStatus.WARN if refused else DiagnosticStatus.OK
        message = "writes refused (see the log)" if refused else values["status"]
        return status(f"{NODE_NAME}: {link.rig}", level, message, values)

    def sim_parameters(self, link: SimLink) -> dict[str, Any]:
        """The SIM_PARAMETERS of ``link``'s sim_node, asked for again until it answers with all
        of them declared (a first start loads the kernel for a while), with a progress line
        every PROGRESS_S; DrillSimError (one line) after ``sim_wait_s``."""
        start_s = time.monotonic()
        next_line_s = start_s + PROGRESS_S
        answered = False
        while (left_s := start_s + self.sim_wait_s - time.monotonic()) > 0:
            if link.parameters.wait_for_services(timeout_sec=min(left_s, PROGRESS_S)):
                answered = True
                future = link.parameters.get_parameters(list(SIM_PARAMETERS))
                rclpy.spin_until_future_complete(self, future, timeout_sec=min(
                    left_s, PROGRESS_S))
                sim = sim_values(future.result()) if future.done() else None
                if sim is not None:
                    return sim
                time.sleep(min(SETTINGS_RETRY_S, max(0.0, left_s)))
            if time.monotonic() >= next_line_s:
                next_line_s += PROGRESS_S
                self.get_logger().info(
                    f"waiting for {link.sim_node}'s parameters: "
                    f"{time.monotonic() - start_s:.0f} s of sim_wait_s {self.sim_wait_s:g} "
                    f"({'it answers, not all declared yet' if answered else 'not there yet'})")
        if not answered:
            raise DrillSimError(f"no sim_node {link.sim_node} answered in {self.sim_wait_s:g} "
                                "s (start sim_node first, in the rig's namespace and domain)")
        raise DrillSimError(f"{link.sim_node} did not return all its parameters in "
                            f"{self.sim_wait_s:g} s")


Event = Callable[[], Awaitable[None]]


def _switcher(link: SimLink) -> Callable[[str], Awaitable[str | None]]:
    return lambda mode: asyncio.wrap_future(link.switch_mode(mode))


def _connect(link: SimLink, rig: Rig, loop: asyncio.AbstractEventLoop,
             events: asyncio.Queue[Event]) -> None:
    """Hand ``link``'s samples and settings to ``rig`` through ``events`` (in order)."""
    def put(event: Event) -> None:
        # a sample that arrives while the gateway stops (the loop closed after the executor's
        # shutdown waited out its timeout) has nowhere to go: drop it, it is not an error
        with contextlib.suppress(RuntimeError):
            loop.call_soon_threadsafe(events.put_nowait, event)

    link.on_sample = lambda values, time_ns: put(functools.partial(rig.sample_in, values,
                                                                   time_ns))
    link.on_settings = lambda sim: put(functools.partial(rig.follow, RigSettings.of_sim(sim)))
    link.on_restart = lambda: put(rig.sim_replaced)
    link.figures = rig.figures
    if link.latest_sample is not None:      # received while sim_node's parameters came
        events.put_nowait(functools.partial(rig.sample_in, *link.latest_sample))


async def serve(node: GatewayNode, settings: list[RigSettings]) -> None:
    """Run the OPC UA server until SIGINT or SIGTERM (or ROS shuts down otherwise).

    The signals set a flag the loop reads: asyncio.run's own SIGINT handler (which replaces
    rclpy's) only cancels the task, and Python 3.11's ``wait_for`` drops that cancellation
    when its queue delivers an event at the same moment, which left the gateway serving."""
    loop = asyncio.get_running_loop()
    stopping = asyncio.Event()
    for signum in STOP_SIGNALS:
        loop.add_signal_handler(signum, stopping.set)
    events: asyncio.Queue[Event] = asyncio.Queue()
    rigs = [Rig(link.rig, start_settings, link.send, _switcher(link), node.timing)
            for link, start_settings in zip(node.links, settings, strict=True)]
    server = RigServer(node.endpoint, rigs, node.security)
    await server.start()
    for link, rig in zip(node.links, rigs, strict=True):
        _connect(link, rig, loop, events)
    executor = SingleThreadedExecutor(context=node.context)
    executor.add_node(node)
    spinning = SpinThread(executor, node.context, "gateway-ros")
    for link, rig in zip(node.links, rigs, strict=True):
        node.get_logger().info(f"serving {rig.name} ({link.sim_node}) at {node.endpoint} "
                               f"(lockstep {rig.settings.lockstep}, drive mode "
                               f"{rig.settings.drive_mode.name})")
    try:
        while rclpy.ok() and not stopping.is_set():
            try:
                event = await asyncio.wait_for(events.get(), POLL_S)
            except TimeoutError:
                continue
            await event()
    finally:
        for signum in STOP_SIGNALS:
            loop.remove_signal_handler(signum)
        await asyncio.to_thread(spinning.stop)
        await server.stop()


EXPORT_OPTION = "--export-nodeset"


def export_option(args: list[str]) -> tuple[list[str], str | None]:
    """``args`` without ``--export-nodeset FILE``, and FILE (None: not asked for)."""
    if EXPORT_OPTION not in args:
        return args, None
    at = args.index(EXPORT_OPTION)
    if at + 1 >= len(args) or args[at + 1].startswith("-"):
        raise ParameterError(f"{EXPORT_OPTION} needs a FILE (the NodeSet2 XML to write)")
    return args[:at] + args[at + 2:], args[at + 1]


async def export(node: GatewayNode, settings: list[RigSettings], path: str) -> None:
    """Write the rigs' address space (with these sim_nodes' ranges) as NodeSet2 XML."""
    rigs = [Rig(link.rig, start_settings, link.send, None, node.timing)
            for link, start_settings in zip(node.links, settings, strict=True)]
    server = RigServer(node.endpoint, rigs, node.security)
    await server.build()
    await server.export_nodeset(path)
    node.get_logger().info(f"wrote the address space of {', '.join(r.name for r in rigs)} "
                           f"to {path} (NodeSet2 XML)")


def main(args: list[str] | None = None) -> int:
    """Console script ``opcua_gateway``; a user's mistake (a bad argument, an off-loopback
    endpoint, no sim_node) is one line, exit 2."""
    try:
        args, export_path = export_option(list(sys.argv if args is None else args))
        init_ros(args, USAGE)
    except DrillSimError as exc:
        rclpy.logging.get_logger(NODE_NAME).fatal(str(exc))
        return 2
    logging.basicConfig(level=logging.WARNING, format="[%(levelname)s] [opcua] %(message)s")
    sys.setswitchinterval(GIL_SWITCH_INTERVAL_S)
    node = None
    try:
        node = GatewayNode()
        check_endpoint(node.endpoint, secured=node.security is not None)
        settings = [RigSettings.of_sim(node.sim_parameters(link)) for link in node.links]
        asyncio.run(serve(node, settings) if export_path is None
                    else export(node, settings, export_path))
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    except (DrillSimError, ValueError, OSError) as exc:     # refused at start: one line
        rclpy.logging.get_logger(NODE_NAME).fatal(str(exc))
        return 2
    finally:
        if node is not None:
            node.destroy_node()
        rclpy.try_shutdown()
    return 0


if __name__ == "__main__":
    sys.exit(main())
