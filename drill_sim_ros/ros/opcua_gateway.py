"""opcua_gateway: sim_node's surface and commands as an OPC UA server (node ``opcua_gateway``).

A PLC's controller closes the loop through it (hardware in the loop, docs/hil.md). The ROS
side is a lockstep driver of sim_node (the handshake of docs/control-loop.md): it reads
``drill/surface/measured`` (latched), and sends each command on ``drill/cmd/top_drive``
stamped with the latest sample; the OPC UA side is :class:`~drill_sim_ros.hil.rig_server.
RigServer`, which decides when a command goes (a client's ``CommandCounter`` or ``Step``).

rclpy spins in a thread of its own; a sample crosses into asyncua's event loop through a
queue, in order. The setpoints' EURanges, the setpoints in force and the drive mode are read
from the running sim_node's parameters at start (one source: its ``limits.*``).

    sim_node --ros-args -p lockstep:=true -p lockstep_trigger:=command
    opcua_gateway --ros-args -p endpoint:=opc.tcp://127.0.0.1:4840/drill_sim/
"""

from __future__ import annotations

import asyncio
import contextlib
import logging
import sys
import threading
from typing import Any

import rclpy
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
from rcl_interfaces.msg import FloatingPointRange, ParameterDescriptor
from rclpy.executors import ExternalShutdownException, SingleThreadedExecutor
from rclpy.node import Node
from rclpy.parameter import parameter_value_to_python
from rclpy.parameter_client import AsyncParameterClient
from sensor_msgs.msg import JointState

from drill_sim_ros import topics
from drill_sim_ros.control.command import Command
from drill_sim_ros.hil.address_space import DEFAULT_ENDPOINT, SAMPLE_VARIABLES, rig_name
from drill_sim_ros.hil.endpoint import check_endpoint
from drill_sim_ros.hil.rig_server import RigServer, RigSettings
from drill_sim_ros.hil.security import SETTINGS as SECURITY_SETTINGS
from drill_sim_ros.hil.security import load_security
from drill_sim_ros.model.errors import DrillSimError
from drill_sim_ros.model.params import RPM_PER_RAD_S
from drill_sim_ros.ros.lockstep_driver import LOCKSTEP_QOS, top_drive_command
from drill_sim_ros.ros.messages import LATEST_SAMPLE_QOS, stamp_ns, status
from drill_sim_ros.ros.parameters import init_ros

NODE_NAME = "opcua_gateway"
USAGE = """usage: opcua_gateway [--ros-args -p endpoint:=opc.tcp://127.0.0.1:4840/drill_sim/ ...]

sim_node's surface and commands as an OPC UA server, for a PLC's controller in the loop
(docs/hil.md). Its settings are ROS parameters; start sim_node first."""
SIM_PARAMETERS = ("limits.max_surface_rpm", "limits.max_wob_n", "top_drive.max_torque_nm",
                  "model.surface_rpm", "model.applied_wob_n", "top_drive.mode", "lockstep",
                  "lockstep_trigger")
GIL_SWITCH_INTERVAL_S = 0.0005    # as sim_node's: a thread waiting for the GIL waits less
POLL_S = 0.2
DIAGNOSTICS_PERIOD_S = 1.0        # wall time, as sim_node's


SECURITY_HELP = {
    "security.certificate": "the server's certificate, DER or PEM, with the URI "
                            "urn:drill_sim_ros:opcua_gateway ('' = not secured: loopback only)",
    "security.private_key": "the certificate's private key, PEM",
    "security.user": "the one user name a client must give",
    "security.password_file": "a file whose first line is that user's password"}


def _seconds(description: str, default: float) -> tuple[float, ParameterDescriptor]:
    return default, ParameterDescriptor(description=description, read_only=True,
                                        floating_point_range=[FloatingPointRange(
                                            from_value=0.1, to_value=3600.0, step=0.0)])


def sample_values(msg: JointState) -> tuple[dict[str, float], int]:
    """The read-only values of a drill/surface/measured sample, and its stamp (ns)."""
    time_ns = stamp_ns(msg.header.stamp)
    arrays = {"position": msg.position, "velocity": msg.velocity, "effort": msg.effort}
    values = {v.name: time_ns / 1e9 if v.source[0] == "stamp"
              else float(arrays[v.source[0]][v.source[1]]) for v in SAMPLE_VARIABLES}
    return values, time_ns


def rig_settings(sim: dict[str, Any]) -> RigSettings:
    """The rig object's settings from sim_node's parameters (``SIM_PARAMETERS``)."""
    torque_nm = sim["top_drive.max_torque_nm"] or sys.float_info.max     # 0: no limit
    return RigSettings(
        max_speed_rad_s=sim["limits.max_surface_rpm"] / RPM_PER_RAD_S, max_torque_nm=torque_nm,
        max_wob_n=sim["limits.max_wob_n"], speed_rad_s=sim["model.surface_rpm"] / RPM_PER_RAD_S,
        wob_n=sim["model.applied_wob_n"],
        drive_mode="torque" if sim["top_drive.mode"] == "torque" else "speed",
        lockstep=bool(sim["lockstep"]) and sim["lockstep_trigger"] == "command")


class GatewayNode(Node):
    """The ROS side: the command publisher, the sample subscription, the parameters."""

    def __init__(self, **node_kwargs: Any) -> None:
        super().__init__(NODE_NAME, **node_kwargs)
        self.endpoint = self.declare_parameter("endpoint", DEFAULT_ENDPOINT, ParameterDescriptor(
            description="opc.tcp://HOST:PORT/PATH the OPC UA server listens on (loopback "
                        "only)", read_only=True)).value
        self.rig = self.declare_parameter("rig", "", ParameterDescriptor(
            description="BrowseName of the rig object; '' = the namespace's last part, or "
                        "Rig", read_only=True)).value or rig_name(self.get_namespace())
        self.sim_node = self.declare_parameter("sim_node", topics.NODE_NAME, ParameterDescriptor(
            description="sim_node's node name, in this node's namespace",
            read_only=True)).value
        self.sim_wait_s = self.declare_parameter("sim_wait_s", *_seconds(
            "how long to wait at start for sim_node's parameters [s]", 30.0)).value
        self.step_timeout_s = self.declare_parameter("step_timeout_s", *_seconds(
            "Step returns BadTimeout after this many wall seconds without the sample [s]",
            10.0)).value
        self.security = load_security({name: self.declare_parameter(
            name, "", ParameterDescriptor(description=SECURITY_HELP[name], read_only=True)
        ).value for name in SECURITY_SETTINGS})
        self.on_sample = None
        self.figures: Any = None            # () -> the diagnostics' values, once serving
        self._rejected_before = "0"
        self._diagnostics = self.create_publisher(DiagnosticArray, topics.DIAGNOSTICS, 10)
        self.create_timer(DIAGNOSTICS_PERIOD_S, self._publish_diagnostics)
        self.latest_sample: tuple[dict[str, float], int] | None = None   # (before on_sample)
        self._pub = self.create_publisher(JointState, topics.node_relative(
            topics.CMD_TOP_DRIVE), LOCKSTEP_QOS)
        self.create_subscription(JointState, topics.node_relative(topics.SURFACE_MEASURED),
                                 self._on_sample, LATEST_SAMPLE_QOS)

    def _on_sample(self, msg: JointState) -> None:
        values, time_ns = sample_values(msg)
        self.latest_sample = (values, time_ns)
        if self.on_sample is not None:
            self.on_sample(values, time_ns)

    def _publish_diagnostics(self) -> None:
        """``opcua_gateway: <rig>``: WARN when writes were refused since the last one."""
        if self.figures is None:
            return
        values = self.figures()
        refused = values["rejected_writes"] != self._rejected_before
        self._rejected_before = values["rejected_writes"]
        level = DiagnosticStatus.WARN if refused else DiagnosticStatus.OK
        message = "writes refused (see the log)" if refused else values["status"]
        msg = DiagnosticArray(status=[status(f"{NODE_NAME}: {self.rig}", level, message,
                                             values)])
        msg.header.stamp = self.get_clock().now().to_msg()
        self._diagnostics.publish(msg)

    def send(self, command: Command, stamp_ns: int) -> None:
        """The command answering the sample stamped ``stamp_ns`` (from any thread)."""
        self._pub.publish(top_drive_command(command, stamp_ns))

    def sim_parameters(self) -> dict[str, Any]:
        """sim_node's SIM_PARAMETERS (DrillSimError, one line, if it does not answer)."""
        client = AsyncParameterClient(self, self.sim_node)
        where = f"{self.get_namespace().rstrip('/')}/{self.sim_node}"
        if not client.wait_for_services(timeout_sec=self.sim_wait_s):
            raise DrillSimError(f"no sim_node {where} answered in {self.sim_wait_s:g} s "
                                "(start sim_node first, in the same namespace and domain)")
        future = client.get_parameters(list(SIM_PARAMETERS))
        rclpy.spin_until_future_complete(self, future, timeout_sec=self.sim_wait_s)
        if not future.done():
            raise DrillSimError(f"{where} did not return its parameters")
        values = future.result().values
        return {name: parameter_value_to_python(value)
                for name, value in zip(SIM_PARAMETERS, values, strict=True)}


def _spin(executor: SingleThreadedExecutor) -> None:
    with contextlib.suppress(ExternalShutdownException):
        executor.spin()


async def serve(node: GatewayNode, settings: RigSettings) -> None:
    """Run the OPC UA server until ROS shuts down (SIGINT, SIGTERM)."""
    loop = asyncio.get_running_loop()
    samples: asyncio.Queue[tuple[dict[str, float], int]] = asyncio.Queue()
    rig = RigServer(node.endpoint, node.rig, settings, node.send, node.step_timeout_s,
                    node.security)
    await rig.start()
    node.figures = rig.figures
    node.on_sample = lambda values, time_ns: loop.call_soon_threadsafe(
        samples.put_nowait, (values, time_ns))
    if node.latest_sample is not None:      # received while sim_node's parameters came
        samples.put_nowait(node.latest_sample)
    executor = SingleThreadedExecutor()
    executor.add_node(node)
    threading.Thread(target=_spin, args=(executor,), daemon=True).start()
    node.get_logger().info(f"serving {node.rig} at {node.endpoint} (lockstep "
                           f"{settings.lockstep}, drive mode {settings.drive_mode})")
    try:
        while rclpy.ok():
            try:
                values, time_ns = await asyncio.wait_for(samples.get(), POLL_S)
            except TimeoutError:
                continue
            await rig.sample_in(values, time_ns)
    finally:
        executor.shutdown(timeout_sec=1.0)
        await rig.stop()


def main(args: list[str] | None = None) -> int:
    """Console script ``opcua_gateway``; a user's mistake (a bad argument, an off-loopback
    endpoint, no sim_node) is one line, exit 2."""
    try:
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
        asyncio.run(serve(node, rig_settings(node.sim_parameters())))
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
