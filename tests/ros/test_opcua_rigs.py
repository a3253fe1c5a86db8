"""The OPC UA gateway with several rigs, DriveMode and sim_node's settings followed: sim_node
and opcua_gateway as processes over loopback, a real asyncua client (issue 33).

- One gateway serves the sim_nodes of two namespaces as the objects ``rig1`` and ``rig2``:
  a PI law closes the loop on both at once (one through the counters, one through ``Step``,
  for different numbers of periods), and each recording equals the in-process bench of its
  length, bit for bit.
- A DriveMode write (DriveModeEnum: 0 speed, 1 torque) switches sim_node's
  ``top_drive.mode`` (read back over ROS): in torque mode the commanded torque is the motor
  torque; values outside the enumeration are refused and counted.
- sim_node's limits, lockstep and drive mode, changed at runtime or by a restart with other
  values, show in the EURanges, ``Lockstep`` and ``DriveMode`` (kinematic as speed, 0); after
  the restart the handshake goes on.
"""

from __future__ import annotations

import asyncio
import math
import signal
from collections.abc import Iterator
from contextlib import ExitStack, contextmanager
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from asyncua import ua
from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory
from rclpy.node import Node
from rclpy.parameter import Parameter, parameter_value_to_python
from rclpy.parameter_client import AsyncParameterClient

from drill_sim_ros import topics
from drill_sim_ros.control.bench import run_in_process
from drill_sim_ros.model.errors import ParameterError
from drill_sim_ros.ros.opcua_gateway import rig_names, rig_namespaces
from tests.archive.helpers import running, stop
from tests.ros.harness import Ros, ros_context
from tests.ros.test_opcua_gateway import (
    DOUBLE,
    HEARTBEAT_LOST,
    SCENARIO,
    START_TIMEOUT_S,
    UINT32,
    Rig,
    connect,
    free_port,
    law_through_counters,
    law_through_step,
    run,
    sim_command,
    wait_sample,
    wait_until,
)

pytestmark = pytest.mark.ros
STRING, INT32 = ua.VariantType.String, ua.VariantType.Int32
SPEED, TORQUE = 0, 1                     # DriveModeEnum's values (docs/hil.md)
RUNNING = 1                              # RigStatus.Running (docs/hil.md)
ROS_TIMEOUT_S = 10.0


def rad_s(rpm: float) -> float:
    """rev/min in rad/s as a PLC writes it (docs/hil.md: the EURange is rpm*pi/30)."""
    return rpm * math.pi / 30.0


@contextmanager
def sims_and_gateway(tmp_path: Path, namespaces: tuple[str, ...], record: bool = False,
                     sim_options: tuple[str, ...] = ()) -> Iterator[tuple[dict[str, Any], Any,
                                                                         str]]:
    """sim_nodes in ``namespaces`` (recording to <last part>.mcap) and one gateway of them."""
    url = f"opc.tcp://127.0.0.1:{free_port()}/drill_sim/"
    with ExitStack() as stack:
        sims = {}
        for ns in namespaces:
            name = ns.rpartition("/")[2] or "root"
            command = sim_command(tmp_path / f"{name}.mcap" if record else None, namespace=ns)
            sims[ns] = stack.enter_context(running([*command, *sim_options],
                                                   tmp_path / f"sim_{name}.log"))
        rigs = f"rigs:=[{', '.join(namespaces)}]"
        gateway = stack.enter_context(running(
            ["opcua_gateway", "--ros-args", "-p", f"endpoint:={url}", "-p", rigs],
            tmp_path / "gateway.log"))
        yield sims, gateway, url


def telemetry_in(path: Path, namespace: str) -> np.ndarray:
    """The rows of ``<namespace>/drill/telemetry`` in a recording, in order."""
    with open(path, "rb") as stream:
        reader = make_reader(stream, decoder_factories=[DecoderFactory()])
        rows = [list(msg.data) for *_, msg in reader.iter_decoded_messages(
            topics=[namespace + topics.TELEMETRY])]
    return np.array(rows, dtype=np.float64)


# ---- several rigs, one server ---------------------------------------------------------------

def test_rig_namespaces_and_names() -> None:
    assert rig_namespaces([], "/") == ["/"]
    assert rig_namespaces(None, "/site") == ["/site"]
    assert rig_namespaces(["/a/rig1", "rig2", "/b/"], "/site") == ["/a/rig1", "/site/rig2",
                                                                   "/b"]
    assert rig_names(["/a/rig1", "/site/rig2"], "") == ["rig1", "rig2"]
    assert rig_names(["/"], "") == ["Rig"]
    assert rig_names(["/a"], "north") == ["north"]
    with pytest.raises(ParameterError, match="both be called 'rig'"):
        rig_names(["/a/rig", "/b/rig"], "")
    with pytest.raises(ParameterError, match="names one rig"):
        rig_names(["/a", "/b"], "north")
    with pytest.raises(ParameterError, match="not a ROS namespace"):
        rig_namespaces(["/a b"], "/")


async def close_both_loops(url: str, periods: dict[str, int]) -> None:
    (client1, rig1), (client2, rig2) = [await connect(url, rig_name=name) for name in periods]
    try:
        objects = {(await n.read_browse_name()).Name
                   for n in await client1.nodes.objects.get_children()}
        assert {"rig1", "rig2"} <= objects and "Rig" not in objects
        await asyncio.gather(law_through_counters(rig1, 1, periods["rig1"], 0.0),
                             law_through_step(rig2, 1, periods["rig2"], 0.0))
        assert await rig1.value("SampleCounter") == periods["rig1"]
        assert await rig2.value("SimTime") == pytest.approx(periods["rig2"] * 0.01, abs=1e-9)
    finally:
        await client1.disconnect()
        await client2.disconnect()


def test_two_sim_nodes_behind_one_gateway_each_close_their_loop_bit_for_bit(
        tmp_path: Path) -> None:
    periods = {"rig1": 200, "rig2": 120}
    with sims_and_gateway(tmp_path, ("/site/rig1", "/site/rig2"), record=True) as (
            sims, gateway, url):
        run(close_both_loops(url, periods))
        assert stop(gateway, signal.SIGINT) == 0, (tmp_path / "gateway.log").read_text()
        for sim in sims.values():
            assert stop(sim, signal.SIGINT) == 0
    local = run_in_process(SCENARIO).rows
    for name, count in periods.items():
        remote = telemetry_in(tmp_path / f"{name}.mcap", f"/site/{name}")
        assert remote.shape == (count + 1, local.shape[1])
        assert remote.tobytes() == local[:count + 1].tobytes(), name


def test_two_rigs_with_one_last_part_are_refused_in_one_line(tmp_path: Path) -> None:
    with running(["opcua_gateway", "--ros-args", "-p", "rigs:=[/a/rig, /b/rig]"],
                 tmp_path / "gateway.log") as gateway:
        assert gateway.wait(60) == 2
    lines = (tmp_path / "gateway.log").read_text().strip().splitlines()
    assert len(lines) == 1 and "both be called 'rig'" in lines[0], lines


# ---- sim_node over ROS, from the test -------------------------------------------------------

class SimParameters:
    """sim_node's parameters over ROS (each call bounded; from any one thread at a time)."""

    def __init__(self, ros: Ros, sim_node: str = "/drill_sim") -> None:
        self.ros = ros
        self.client = AsyncParameterClient(ros.add(Node("sim_parameters",
                                                        context=ros.context)), sim_node)

    def _result(self, future: Any) -> Any:
        assert self.ros.spin_until(future.done, ROS_TIMEOUT_S), "sim_node did not answer"
        return future.result()

    def get(self, name: str) -> Any:
        assert self.client.wait_for_services(timeout_sec=ROS_TIMEOUT_S), "no sim_node"
        result = self._result(self.client.get_parameters([name]))
        return parameter_value_to_python(result.values[0])

    def set(self, **values: Any) -> None:
        """``max_surface_rpm=`` ... sets ``limits.max_surface_rpm`` (``__`` is ``.``)."""
        assert self.client.wait_for_services(timeout_sec=ROS_TIMEOUT_S), "no sim_node"
        result = self._result(self.client.set_parameters(
            [Parameter(name.replace("__", "."), value=v) for name, v in values.items()]))
        assert all(r.successful for r in result.results), result


# ---- DriveMode ------------------------------------------------------------------------------

async def switch_modes(url: str, sim: SimParameters) -> None:
    client, rig = await connect(url)
    try:
        assert await asyncio.to_thread(sim.get, "top_drive.mode") == "speed"
        # the switch and a torque command in one request: the command carries the torque
        await rig.write(DriveMode=ua.Variant(TORQUE, INT32),
                        TorqueCommand=ua.Variant(12345.0, DOUBLE),
                        CommandCounter=ua.Variant(1, UINT32))
        await wait_sample(rig, 1)
        assert await asyncio.to_thread(sim.get, "top_drive.mode") == "torque"
        assert await rig.value("MotorTorque") == 12345.0     # no lag, no rate limit
        await check_wrong_modes(rig)
        assert await asyncio.to_thread(sim.get, "top_drive.mode") == "torque"
        await rig.write(DriveMode=ua.Variant(SPEED, INT32),
                        SpeedSetpoint=ua.Variant(8.0, DOUBLE),
                        TorqueCommand=ua.Variant(777.0, DOUBLE))
        assert await asyncio.to_thread(sim.get, "top_drive.mode") == "speed"
        for counter in range(2, 152):                       # 1.5 s of the speed loop
            await rig.write(CommandCounter=ua.Variant(counter, UINT32))
            await wait_sample(rig, counter)
        assert await rig.value("DriveSpeed") == pytest.approx(8.0, abs=0.5)
        assert await rig.value("MotorTorque") != 777.0
    finally:
        await client.disconnect()


async def check_wrong_modes(rig: Rig) -> None:
    for wrong in (2, -1):
        with pytest.raises(ua.uaerrors.BadOutOfRange):
            await rig.write(DriveMode=ua.Variant(wrong, INT32))
    with pytest.raises(ua.uaerrors.BadTypeMismatch):
        await rig.write(DriveMode=ua.Variant("torque", STRING))
    assert await rig.value("RejectedWrites") == 3
    assert await rig.value("DriveMode") == TORQUE


def test_drive_mode_switches_sim_nodes_drive(tmp_path: Path) -> None:
    motorless = ("-p", "top_drive.motor_lag_s:=0.0", "-p", "top_drive.max_torque_rate_nm_s:=0.0")
    with sims_and_gateway(tmp_path, ("/",), sim_options=motorless) as (sims, gateway, url), \
            ros_context() as ros:
        run(switch_modes(url, SimParameters(ros)))
        assert stop(gateway, signal.SIGINT) == 0, (tmp_path / "gateway.log").read_text()
        assert stop(sims["/"], signal.SIGINT) == 0


# ---- sim_node's settings followed -----------------------------------------------------------

async def eu_high(rig: Rig, name: str) -> float:
    return (await (await rig.nodes[name].get_child("0:EURange")).read_value()).High


async def wait_eu_high(rig: Rig, name: str, high: float, timeout_s: float = 20.0) -> None:
    end = asyncio.get_running_loop().time() + timeout_s
    while (value := await eu_high(rig, name)) != high:
        assert asyncio.get_running_loop().time() < end, f"{name}'s EURange stayed at {value}"
        await asyncio.sleep(0.05)


async def follow_at_runtime(url: str, sim: SimParameters) -> None:
    client, rig = await connect(url)
    try:
        assert await eu_high(rig, "SpeedSetpoint") == rad_s(300.0)
        await rig.write(SpeedSetpoint=ua.Variant(25.0, DOUBLE))
        await asyncio.to_thread(sim.set, limits__max_surface_rpm=120.0,
                                top_drive__max_torque_nm=9000.0)
        await wait_eu_high(rig, "SpeedSetpoint", rad_s(120.0))
        await wait_eu_high(rig, "TorqueCommand", 9000.0)
        with pytest.raises(ua.uaerrors.BadOutOfRange):
            await rig.write(SpeedSetpoint=ua.Variant(25.0, DOUBLE))
        await asyncio.to_thread(sim.set, top_drive__mode="torque")     # sim_node's own switch
        await wait_until(rig, "DriveMode", lambda mode: mode == TORQUE)
        await asyncio.to_thread(sim.set, top_drive__mode="kinematic")  # takes speed setpoints
        await wait_until(rig, "DriveMode", lambda mode: mode == SPEED)
        await asyncio.to_thread(sim.set, lockstep=False)
        await wait_until(rig, "Lockstep", lambda on: on is False)
        # a heartbeat in free run: the settings above may outlast heartbeat_timeout_s (2 s),
        # and an owner silent that long in lockstep just lets go (no safe stop to latch)
        await rig.write(SpeedSetpoint=ua.Variant(5.0, DOUBLE))
        await wait_until(rig, "Status", lambda status: status == RUNNING)
    finally:
        await client.disconnect()


async def wait_status(url: str, status: int) -> None:
    """A second client (it only reads) waits for the rig's ``status``."""
    client, rig = await connect(url)
    try:
        await wait_until(rig, "Status", lambda now: now == status)
    finally:
        await client.disconnect()


async def follow_a_restart(url: str) -> None:
    client, rig = await connect(url)
    try:
        await wait_eu_high(rig, "SpeedSetpoint", rad_s(200.0), START_TIMEOUT_S)
        await wait_until(rig, "Lockstep", lambda on: on is True)
        await wait_until(rig, "SimTime", lambda t: t == 0.0)
        # the client that wrote SpeedSetpoint closed in free run: the watchdog's safe stop
        assert await rig.value("Status") == HEARTBEAT_LOST
        await rig.obj.call_method(f"{rig.index}:Reset")
        counter = await rig.value("SampleCounter")
        assert await rig.value("CommandCounter") == counter
        await rig.write(SpeedSetpoint=ua.Variant(15.0, DOUBLE),
                        CommandCounter=ua.Variant(counter + 1, UINT32))
        await wait_sample(rig, counter + 1)
        assert await rig.value("SimTime") == pytest.approx(0.01, abs=1e-12)
    finally:
        await client.disconnect()


def test_the_ranges_and_lockstep_follow_sim_node_at_runtime_and_across_a_restart(
        tmp_path: Path) -> None:
    with sims_and_gateway(tmp_path, ("/",)) as (sims, gateway, url), ros_context() as ros:
        run(follow_at_runtime(url, SimParameters(ros)))
        run(wait_status(url, HEARTBEAT_LOST))        # the owner closed in free run
        assert stop(sims["/"], signal.SIGINT) == 0
        with running([*sim_command(None), "-p", "limits.max_surface_rpm:=200.0"],
                     tmp_path / "sim_again.log") as sim:
            run(follow_a_restart(url))
            assert stop(gateway, signal.SIGINT) == 0, (tmp_path / "gateway.log").read_text()
            assert stop(sim, signal.SIGINT) == 0
    log = (tmp_path / "gateway.log").read_text()
    assert "Traceback" not in log and "sim_node started again" in log
