"""The gateway's OPC UA server without ROS: a real asyncua server on loopback with two rig
objects whose simulators are stand-ins, and a real asyncua client (issue 33).

- Two rigs share one server: each has its own object, NodeIds, counters and commands; a
  request spanning both is refused whole when one value is bad, counted by that rig alone.
- A new DriveMode switches the stand-in's drive before the request's command goes; a switch
  it refuses is BadInvalidState, one it never answers BadTimeout, both counted.
- The EURanges, Lockstep and DriveMode follow the stand-in's settings; a sample older than the
  latest (a restarted simulator) starts the handshake over from CommandCounter.
- Issue 53: 300 rev/min as a PLC computes it is in range; an array to a scalar is a counted
  BadTypeMismatch with no ERROR logged; a second session is refused BadUserAccessDenied and a
  stale setpoint BadInvalidState; Step's wait is bounded and Status honest (SimLost), a
  restart at t = 0 resyncs; a silent or closed owner in free run ramps the drive to rest
  (torque mode: switched to speed first, Faulted if refused) until Reset, in lockstep only
  loses the setpoints; the server's names and timestamps; the NodeSet2 export round-trips.
"""

from __future__ import annotations

import asyncio
import logging
import math
import socket
from collections.abc import AsyncIterator
from contextlib import asynccontextmanager
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import pytest
from asyncua import Client, Server, ua

from drill_sim_ros.control.command import Command
from drill_sim_ros.hil.address_space import VARIABLE_BY_NAME, VARIABLES, DriveModeEnum, RigStatus
from drill_sim_ros.hil.rig_server import Rig, RigServer, RigSettings, RigTiming
from drill_sim_ros.hil.security import APPLICATION_URI

DOUBLE, UINT32, STRING = ua.VariantType.Double, ua.VariantType.UInt32, ua.VariantType.String
INT32 = ua.VariantType.Int32
SPEED, TORQUE = 0, 1                     # DriveModeEnum's values (docs/hil.md)
SETTINGS = RigSettings(max_speed_rad_s=30.0, max_torque_nm=50_000.0, max_wob_n=1e6,
                       speed_rad_s=4.0, wob_n=60_000.0, drive_mode=DriveModeEnum.speed,
                       lockstep=True,
                       control_period_s=0.01)
SAMPLE = {"DriveSpeed": 4.0, "MotorTorque": 1.0, "QuillTorque": 2.0, "HookLoad": 3.0,
          "WobEstimate": 5.0, "BitDepth": 0.0, "Rop": 0.0, "SimTime": 0.0}
PERIOD_NS = 10_000_000
TIMEOUT_S = 30.0


@dataclass
class StandIn:
    """A simulator: the commands it was sent (with their stamps) and its drive switches."""

    commands: list[tuple[Command, int]] = field(default_factory=list)
    switches: list[str] = field(default_factory=list)
    refuse_with: str | None = None       # the reason it gives for refusing a switch
    silent: bool = False                 # it never answers a switch

    def send(self, command: Command, stamp_ns: int) -> None:
        self.commands.append((command, stamp_ns))

    async def switch_mode(self, mode: str) -> str | None:
        self.switches.append(mode)
        if self.silent:
            await asyncio.Event().wait()
        return self.refuse_with


def free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


class View:
    """The client's view of one rig object: its variables by BrowseName."""

    def __init__(self, client: Client, nodes: dict[str, Any]) -> None:
        self.client, self.nodes = client, nodes

    async def value(self, name: str) -> Any:
        return await self.nodes[name].read_value()

    async def eu_range(self, name: str) -> tuple[float, float]:
        value = await (await self.nodes[name].get_child("0:EURange")).read_value()
        return value.Low, value.High


async def view(client: Client, rig: str) -> View:
    index = await client.get_namespace_index("urn:drill_sim_ros")
    obj = await client.nodes.objects.get_child(f"{index}:{rig}")
    return View(client, {(await n.read_browse_name()).Name: n for n in await obj.get_children()})


@asynccontextmanager
async def serving(**rig_options: Any) -> AsyncIterator[tuple[dict[str, Rig],
                                                             dict[str, StandIn], Client]]:
    """Rigs ``north`` and ``south`` in one server, their stand-ins, a connected client."""
    stand_ins = {name: StandIn() for name in ("north", "south")}
    rigs = {name: Rig(name, SETTINGS, s.send, s.switch_mode, RigTiming(**rig_options))
            for name, s in stand_ins.items()}
    url = f"opc.tcp://127.0.0.1:{free_port()}/drill_sim/"
    server = RigServer(url, list(rigs.values()))
    await server.start()
    client = Client(url, timeout=5)
    try:
        await client.connect()
        try:
            yield rigs, stand_ins, client
        finally:
            await client.disconnect()
    finally:
        await server.stop()


def run(coroutine: Any) -> Any:
    return asyncio.run(asyncio.wait_for(coroutine, TIMEOUT_S))


async def first_samples(rigs: dict[str, Rig]) -> None:
    for rig in rigs.values():
        await rig.sample_in(SAMPLE, 0)


# ---- two rigs, one server -------------------------------------------------------------------

async def two_rigs_apart() -> None:
    async with serving() as (rigs, stand_ins, client):
        await first_samples(rigs)
        north, south = await view(client, "north"), await view(client, "south")
        assert north.nodes["CommandCounter"].nodeid.Identifier == "north.CommandCounter"
        await client.write_values([north.nodes["SpeedSetpoint"], north.nodes["CommandCounter"]],
                                  [ua.Variant(6.0, DOUBLE), ua.Variant(1, UINT32)])
        assert [c.speed_rad_s for c, _ in stand_ins["north"].commands] == [6.0]
        assert stand_ins["south"].commands == []
        await rigs["north"].sample_in(SAMPLE | {"SimTime": 0.01}, PERIOD_NS)
        assert (await north.value("SampleCounter"), await south.value("SampleCounter")) == (1, 0)
        assert await south.value("SimTime") == 0.0
        # one request over both rigs, the south one's value bad: refused whole
        with pytest.raises(ua.uaerrors.BadOutOfRange):
            await client.write_values(
                [north.nodes["CommandCounter"], south.nodes["WobSetpoint"]],
                [ua.Variant(2, UINT32), ua.Variant(math.inf, DOUBLE)])
        assert len(stand_ins["north"].commands) == 1
        assert await north.value("CommandCounter") == 1
        assert (await north.value("RejectedWrites"), await south.value("RejectedWrites")) == (
            0, 1)


def test_two_rigs_share_a_server_with_a_handshake_each() -> None:
    run(two_rigs_apart())


# ---- DriveMode ------------------------------------------------------------------------------

async def switch_the_drive() -> None:
    async with serving() as (rigs, stand_ins, client):
        await first_samples(rigs)
        north, stand_in = await view(client, "north"), stand_ins["north"]
        await client.write_values(
            [north.nodes["DriveMode"], north.nodes["TorqueCommand"],
             north.nodes["CommandCounter"]],
            [ua.Variant(TORQUE, INT32), ua.Variant(-1234.5, DOUBLE), ua.Variant(1, UINT32)])
        assert stand_in.switches == ["torque"]
        (command, _), = stand_in.commands
        assert (command.motor_torque_nm, command.speed_rad_s) == (-1234.5, None)
        assert command.wob_n == SETTINGS.wob_n      # nothing known in force after a switch
        await north.nodes["DriveMode"].write_value(ua.Variant(TORQUE, INT32))
        assert stand_in.switches == ["torque"]      # the mode it has: no switch
        for wrong in (2, -1, 2**31 - 1):
            with pytest.raises(ua.uaerrors.BadOutOfRange):
                await north.nodes["DriveMode"].write_value(ua.Variant(wrong, INT32))
        for wrong_type in (ua.Variant("torque", STRING), ua.Variant(1, UINT32)):
            with pytest.raises(ua.uaerrors.BadTypeMismatch):
                await north.nodes["DriveMode"].write_value(wrong_type)
        assert stand_in.switches == ["torque"]
        assert await north.value("RejectedWrites") == 5
        stand_in.refuse_with = "the drive would be unstable"
        with pytest.raises(ua.uaerrors.BadInvalidState):
            await north.nodes["DriveMode"].write_value(ua.Variant(SPEED, INT32))
        assert (await north.value("DriveMode"), await north.value("RejectedWrites")) == (
            TORQUE, 6)


def test_drive_mode_switches_the_simulators_drive_and_wrong_modes_are_refused() -> None:
    run(switch_the_drive())


async def drive_mode_enumeration() -> None:
    async with serving() as (rigs, stand_ins, client):
        await first_samples(rigs)
        north, stand_in = await view(client, "north"), stand_ins["north"]
        mode = north.nodes["DriveMode"]
        type_node = client.get_node(await mode.read_data_type())
        assert (await type_node.read_browse_name()).Name == "DriveModeEnum"
        supertype = await type_node.get_parent()       # by HasSubtype: a DataType's parent
        assert supertype.nodeid == ua.NodeId(ua.ObjectIds.Enumeration)
        names = await (await type_node.get_child("0:EnumStrings")).read_value()
        assert [n.Text for n in names] == ["speed", "torque"]
        description = (await type_node.read_description()).Text
        assert description not in ("", "DriveModeEnum")
        assert await mode.read_value() == SPEED
        await mode.write_value(ua.Variant(TORQUE, INT32))       # 1: torque, by EnumStrings
        assert stand_in.switches == ["torque"]
        assert await mode.read_value() == TORQUE


def test_drive_mode_is_an_enumeration_and_writing_1_switches_to_torque() -> None:
    run(drive_mode_enumeration())


async def an_unanswered_switch() -> None:
    async with serving(mode_switch_timeout_s=0.2) as (_, stand_ins, client):
        north = await view(client, "north")
        stand_ins["north"].silent = True
        with pytest.raises(ua.uaerrors.BadTimeout):
            await north.nodes["DriveMode"].write_value(ua.Variant(TORQUE, INT32))
        assert (await north.value("DriveMode"), await north.value("RejectedWrites")) == (
            SPEED, 1)


def test_a_switch_the_simulator_does_not_answer_is_bad_timeout() -> None:
    run(an_unanswered_switch())


# ---- following the simulator ----------------------------------------------------------------

async def follow_the_settings() -> None:
    async with serving() as (rigs, stand_ins, client):
        await first_samples(rigs)
        north = await view(client, "north")
        await north.nodes["SpeedSetpoint"].write_value(ua.Variant(20.0, DOUBLE))   # allowed
        await rigs["north"].follow(replace(SETTINGS, max_speed_rad_s=10.0, max_torque_nm=7.0,
                                           lockstep=False, drive_mode=DriveModeEnum.torque))
        assert await north.eu_range("SpeedSetpoint") == (0.0, 10.0)
        assert await north.eu_range("TorqueCommand") == (-7.0, 7.0)
        assert await north.eu_range("WobSetpoint") == (0.0, SETTINGS.max_wob_n)
        assert (await north.value("Lockstep"), await north.value("DriveMode")) == (
            False, TORQUE)
        with pytest.raises(ua.uaerrors.BadOutOfRange):
            await north.nodes["SpeedSetpoint"].write_value(ua.Variant(20.0, DOUBLE))
        await north.nodes["SpeedSetpoint"].write_value(ua.Variant(10.0, DOUBLE))
        south = await view(client, "south")
        assert await south.eu_range("SpeedSetpoint") == (0.0, SETTINGS.max_speed_rad_s)
        assert stand_ins["north"].switches == []      # sim_node's own change: nothing to do


def test_the_ranges_lockstep_and_drive_mode_follow_the_simulator() -> None:
    run(follow_the_settings())


async def start_over() -> None:
    async with serving() as (rigs, stand_ins, client):
        rig, north, stand_in = rigs["north"], await view(client, "north"), stand_ins["north"]
        await first_samples(rigs)
        for counter in (1, 2, 3):
            await client.write_values([north.nodes["CommandCounter"]],
                                      [ua.Variant(counter, UINT32)])
            await rig.sample_in(SAMPLE, counter * PERIOD_NS)
        await client.write_values([north.nodes["CommandCounter"]], [ua.Variant(4, UINT32)])
        await rig.sample_in(SAMPLE, 0)      # restarted before answering command 4
        assert await north.value("SampleCounter") == await north.value("CommandCounter") == 4
        assert rig.figures()["sim_restarts"] == "1"
        await client.write_values([north.nodes["CommandCounter"]], [ua.Variant(5, UINT32)])
        command, stamp_ns = stand_in.commands[-1]
        assert stamp_ns == 0                # it answers the restarted simulator's sample
        assert (command.speed_rad_s, command.wob_n) == (SETTINGS.speed_rad_s, SETTINGS.wob_n)
        await rig.sample_in(SAMPLE, PERIOD_NS)
        assert await north.value("SampleCounter") == 5


def test_a_restarted_simulator_starts_the_handshake_over_from_command_counter() -> None:
    run(start_over())


# ---- commissioning (issue 53) ---------------------------------------------------------------

SIM = {"limits.max_surface_rpm": 300.0, "limits.max_wob_n": 1e6,
       "top_drive.max_torque_nm": 50_000.0 / 7.0 * 7.0 + 1e-11,   # a scaled round trip's ulp
       "model.surface_rpm": 60.0, "model.applied_wob_n": 6e4, "top_drive.mode": "speed",
       "lockstep": True, "lockstep_trigger": "command", "publish_rate_hz": 100.0}


def test_the_ranges_are_the_settings_without_a_unit_round_trips_drift() -> None:
    settings = RigSettings.of_sim(SIM)
    assert settings.eu_range("SpeedSetpoint") == (0.0, 10.0 * math.pi)
    assert settings.eu_range("TorqueCommand") == (-50_000.0, 50_000.0)


async def plc_arithmetic() -> None:
    async with serving() as (rigs, _, client):
        for rig in rigs.values():
            await rig.follow(RigSettings.of_sim(SIM))
        await first_samples(rigs)
        north = await view(client, "north")
        assert await north.eu_range("SpeedSetpoint") == (0.0, 300 * math.pi / 30)
        # 300 rev/min as a PLC may write it: every form is in range
        for speed in (300 * math.pi / 30, 300 / (30 / math.pi), 300 * 2 * math.pi / 60,
                      math.radians(1800)):
            await north.nodes["SpeedSetpoint"].write_value(ua.Variant(speed, DOUBLE))
            assert await north.value("SpeedSetpoint") == speed
        # an ulp above: the bound goes
        above = math.nextafter(10 * math.pi, math.inf)
        await north.nodes["SpeedSetpoint"].write_value(ua.Variant(above, DOUBLE))
        assert await north.value("SpeedSetpoint") == 10 * math.pi
        with pytest.raises(ua.uaerrors.BadOutOfRange):
            await north.nodes["SpeedSetpoint"].write_value(ua.Variant(31.4159266, DOUBLE))
        await north.nodes["TorqueCommand"].write_value(ua.Variant(-50_000.0, DOUBLE))
        assert await north.value("RejectedWrites") == 1


def test_300_rpm_written_as_a_plc_computes_it_is_in_range() -> None:
    run(plc_arithmetic())


async def an_array_to_a_scalar(caplog: pytest.LogCaptureFixture) -> None:
    async with serving() as (rigs, stand_ins, client):
        await first_samples(rigs)
        north = await view(client, "north")
        for name, value in (("SpeedSetpoint", ua.Variant([3.0], DOUBLE)),
                            ("CommandCounter", ua.Variant([1], UINT32)),
                            ("DriveMode", ua.Variant([TORQUE], INT32))):
            with pytest.raises(ua.uaerrors.BadTypeMismatch):
                await north.nodes[name].write_value(value)
        assert await north.value("RejectedWrites") == 3
        assert await north.value("SpeedSetpoint") == SETTINGS.speed_rad_s
        assert stand_ins["north"].commands == [] and stand_ins["north"].switches == []
    assert not [r for r in caplog.records if r.levelno >= logging.ERROR]


def test_an_array_written_to_a_scalar_is_a_counted_type_mismatch(
        caplog: pytest.LogCaptureFixture) -> None:
    run(an_array_to_a_scalar(caplog))


@asynccontextmanager
async def second_client(client: Client) -> AsyncIterator[Client]:
    other = Client(client.server_url.geturl(), timeout=5)
    await other.connect()
    try:
        yield other
    finally:
        await other.disconnect()


async def two_writers() -> None:
    async with serving() as (rigs, stand_ins, first):
        await first_samples(rigs)
        north, stand_in = await view(first, "north"), stand_ins["north"]
        async with second_client(first) as second_session:
            second = await view(second_session, "north")
            await first.write_values([north.nodes["SpeedSetpoint"], north.nodes["CommandCounter"]],
                                     [ua.Variant(3.0, DOUBLE), ua.Variant(1, UINT32)])
            for name, value in (("SpeedSetpoint", ua.Variant(4.0, DOUBLE)),
                                ("CommandCounter", ua.Variant(1, UINT32)),
                                ("WobSetpoint", ua.Variant(1.0, DOUBLE))):
                with pytest.raises(ua.uaerrors.BadUserAccessDenied):
                    await second.nodes[name].write_value(value)
            await rigs["north"].sample_in(SAMPLE, PERIOD_NS)
            obj = await second_session.nodes.objects.get_child(
                f"{await second_session.get_namespace_index('urn:drill_sim_ros')}:north")
            with pytest.raises(ua.uaerrors.BadUserAccessDenied):
                await obj.call_method(f"{obj.nodeid.NamespaceIndex}:Step")
            assert await second.value("RejectedWrites") == 4
            assert [c.speed_rad_s for c, _ in stand_in.commands] == [3.0]
            assert await second.value("SpeedSetpoint") == 3.0
            # the owner's stale write: a new value with the counter already sent
            with pytest.raises(ua.uaerrors.BadInvalidState):
                await first.write_values(
                    [north.nodes["SpeedSetpoint"], north.nodes["CommandCounter"]],
                    [ua.Variant(5.0, DOUBLE), ua.Variant(1, UINT32)])
            assert await north.value("SpeedSetpoint") == 3.0
            assert await north.value("RejectedWrites") == 5
            # ... the same values again change nothing and are no error
            await first.write_values([north.nodes["SpeedSetpoint"], north.nodes["CommandCounter"]],
                                     [ua.Variant(3.0, DOUBLE), ua.Variant(1, UINT32)])
            await first.disconnect()                    # the owner goes: the second may write
            while rigs["north"].owner is not None:      # (the server closes it just after)
                await asyncio.sleep(0.01)
            await second.nodes["CommandCounter"].write_value(ua.Variant(2, UINT32))
            assert len(stand_in.commands) == 2


def test_one_session_owns_the_setpoints_and_a_stale_write_is_refused() -> None:
    run(two_writers())


RUNNING, WAITING_FOR_CLIENT, HEARTBEAT_LOST, SIM_LOST = 1, 2, 3, 4
WAITING_FOR_SIM = 0


async def wait_for(view_: View, name: str, value: Any, timeout_s: float = 5.0) -> None:
    """Poll the variable ``name`` until it is ``value`` (bounded)."""
    end = asyncio.get_running_loop().time() + timeout_s
    while (now := await view_.value(name)) != value:
        assert asyncio.get_running_loop().time() < end, f"{name} stayed {now}, not {value}"
        await asyncio.sleep(0.01)


async def method(view_: View, name: str) -> Any:
    """Call the method ``name`` of the rig object that ``view_`` shows."""
    nodeid = view_.nodes[name].nodeid
    obj = view_.client.get_node(ua.NodeId(nodeid.Identifier.rpartition(".")[0],
                                          nodeid.NamespaceIndex))
    return await obj.call_method(nodeid)


async def step_and_status() -> None:
    async with serving(sim_timeout_s=0.3) as (rigs, _, client):
        north, rig = await view(client, "north"), rigs["north"]
        assert await north.value("Status") == WAITING_FOR_SIM
        type_node = client.get_node(await north.nodes["Status"].read_data_type())
        names = await (await type_node.get_child("0:EnumStrings")).read_value()
        assert [n.Text for n in names] == ["WaitingForSim", "Running", "WaitingForClient",
                                           "HeartbeatLost", "SimLost", "Faulted"]
        await first_samples(rigs)
        assert await north.value("Status") == WAITING_FOR_CLIENT
        await north.nodes["Heartbeat"].write_value(ua.Variant(1, UINT32))
        assert await north.value("Status") == RUNNING
        # sim_node does not answer: Step gives up after its bounded wait, and a read sent
        # behind it on the same session is answered; the session stays
        step = asyncio.ensure_future(method(north, "Step"))
        await asyncio.sleep(0.05)
        assert await north.value("SampleCounter") == 0
        with pytest.raises(ua.uaerrors.BadTimeout):
            await step
        assert rig.timing.step_timeout_s < 1.0          # below asyncua's 1 s watchdog
        await wait_for(north, "Status", SIM_LOST)
        assert "unanswered" in await north.value("StatusText")
        # sim_node restarted before it left t = 0: its first sample again resyncs
        await rig.sample_in(SAMPLE, 0)
        assert await north.value("SampleCounter") == await north.value("CommandCounter") == 1
        assert await north.value("Status") == RUNNING
        await north.nodes["CommandCounter"].write_value(ua.Variant(2, UINT32))
        await rig.sample_in(SAMPLE, PERIOD_NS)
        assert await north.value("SampleCounter") == 2
        assert rig.figures()["sim_restarts"] == "1"


def test_step_waits_bounded_status_is_honest_and_a_restart_at_t0_resyncs() -> None:
    run(step_and_status())


FREE_RUN = replace(SETTINGS, lockstep=False)
RAMP_RAD_S2 = 2.0


async def feed(rig: Rig, first_ns: int, periods: int) -> int:
    """``periods`` samples of a free-running simulator after ``first_ns``; the last stamp."""
    for k in range(1, periods + 1):
        await rig.sample_in(SAMPLE, first_ns + k * PERIOD_NS)
    return first_ns + periods * PERIOD_NS


async def heartbeat_lost(close: bool) -> None:
    async with serving(heartbeat_timeout_s=0.3, safe_ramp_rad_s2=RAMP_RAD_S2) as (
            rigs, stand_ins, client):
        rig, stand_in = rigs["north"], stand_ins["north"]
        await rig.follow(FREE_RUN)
        await first_samples(rigs)
        north = await view(client, "north")
        await client.write_values([north.nodes["SpeedSetpoint"], north.nodes["CommandCounter"]],
                                  [ua.Variant(6.0, DOUBLE), ua.Variant(1, UINT32)])
        stamp_ns = await feed(rig, 0, 1)
        async with second_client(client) as other_session:
            other = await view(other_session, "north")
            if close:                        # the client goes (the watchdog, fix 9) ...
                await client.disconnect()
            # ... or stays silent: HeartbeatLost either way, and the ramp starts
            await wait_for(other, "Status", HEARTBEAT_LOST)
            sent = len(stand_in.commands)
            stamp_ns = await feed(rig, stamp_ns, 400)
            speeds = [c.speed_rad_s for c, _ in stand_in.commands[sent:]]
            # 6 rad/s at 2 rad/s^2 over 10 ms periods: 300 steps of 0.02 rad/s to rest
            assert len(speeds) == 300 and speeds[-1] == 0.0
            assert all(0.0 <= a - b <= RAMP_RAD_S2 * 0.01 + 1e-12
                       for a, b in zip([6.0, *speeds], speeds, strict=False))
            assert await other.value("SpeedSetpoint") == 0.0
            assert "at rest" in await other.value("StatusText")
            # writes are refused until Reset, which lets the next writer in
            with pytest.raises(ua.uaerrors.BadInvalidState):
                await other.nodes["SpeedSetpoint"].write_value(ua.Variant(3.0, DOUBLE))
            await method(other, "Reset")
            assert await other.value("Status") == WAITING_FOR_CLIENT
            await other.nodes["SpeedSetpoint"].write_value(ua.Variant(3.0, DOUBLE))
            assert await other.value("Status") == RUNNING


def test_a_silent_owner_in_free_run_brings_the_drive_to_rest_until_reset() -> None:
    run(heartbeat_lost(close=False))


def test_a_client_gone_in_free_run_brings_the_drive_to_rest_until_reset() -> None:
    run(heartbeat_lost(close=True))


async def silent_in_lockstep() -> None:
    async with serving(heartbeat_timeout_s=0.2) as (rigs, stand_ins, client):
        await first_samples(rigs)
        north = await view(client, "north")
        await north.nodes["Heartbeat"].write_value(ua.Variant(1, UINT32))
        await wait_for(north, "Status", WAITING_FOR_CLIENT)    # its ownership lapsed
        assert stand_ins["north"].commands == []               # and nothing moved
        await north.nodes["CommandCounter"].write_value(ua.Variant(1, UINT32))
        assert await north.value("Status") == RUNNING


def test_in_lockstep_a_silent_owner_only_loses_the_setpoints() -> None:
    run(silent_in_lockstep())


async def product_names() -> None:
    async with serving() as (rigs, _, client):
        await first_samples(rigs)
        endpoints = await client.get_endpoints()
        assert {e.Server.ApplicationUri for e in endpoints} == {APPLICATION_URI}
        assert "freeopcua" not in " ".join(e.Server.ApplicationName.Text for e in endpoints)
        build = client.get_node(ua.NodeId(ua.ObjectIds.Server_ServerStatus_BuildInfo))
        info = await build.read_value()
        assert (info.ProductUri, info.ProductName) == ("urn:drill_sim_ros",
                                                       "drill_sim_ros OPC UA gateway")
        north = await view(client, "north")
        value = await north.nodes["QuillTorque"].read_data_value()
        assert value.ServerTimestamp is not None and value.SourceTimestamp.year == 1970


def test_the_server_names_itself_and_stamps_its_values() -> None:
    run(product_names())


async def export_and_import(path: Path) -> None:
    settings = RigSettings.of_sim(SIM)
    gateway = RigServer("opc.tcp://127.0.0.1:0/export/", [Rig("Rig", settings, StandIn().send)])
    await gateway.build()
    await gateway.export_nodeset(str(path))
    fresh = Server()
    await fresh.init()
    await fresh.import_xml(str(path))
    index = await fresh.get_namespace_index("urn:drill_sim_ros")
    rig = await fresh.nodes.objects.get_child(f"{index}:Rig")
    nodes = {(await n.read_browse_name()).Name: n for n in await rig.get_children()}
    assert set(nodes) == {v.name for v in VARIABLES} | {"Step", "Reset"}
    speed = nodes["SpeedSetpoint"]
    assert await speed.read_type_definition() == ua.NodeId(ua.ObjectIds.AnalogItemType)
    assert await nodes["QuillTorque"].read_type_definition() == ua.NodeId(
        ua.ObjectIds.AnalogUnitType)
    eu_range = await (await speed.get_child("0:EURange")).read_value()
    assert (eu_range.Low, eu_range.High) == (0.0, 10 * math.pi)
    unit = await (await speed.get_child("0:EngineeringUnits")).read_value()
    assert (unit.DisplayName.Text, unit.UnitId) == ("rad/s", int.from_bytes(b"2A"))
    description = await speed.read_description()
    assert description.Text == VARIABLE_BY_NAME["SpeedSetpoint"].meaning
    status_type = fresh.get_node(await nodes["Status"].read_data_type())
    strings = await (await status_type.get_child("0:EnumStrings")).read_value()
    assert [s.Text for s in strings] == [s.name for s in RigStatus]
    mode_type = fresh.get_node(await nodes["DriveMode"].read_data_type())
    assert (await mode_type.read_browse_name()).Name == "DriveModeEnum"
    assert "command carries" in (await mode_type.read_description()).Text
    strings = await (await mode_type.get_child("0:EnumStrings")).read_value()
    assert [s.Text for s in strings] == ["speed", "torque"]
    assert await nodes["DriveMode"].read_value() == SPEED      # the preset's speed mode
    outputs = await (await nodes["Step"].get_child("0:OutputArguments")).read_value()
    assert [a.Name for a in outputs] == ["SampleCounter"]


def test_the_exported_nodeset_imports_into_a_fresh_server(tmp_path: Path) -> None:
    run(export_and_import(tmp_path / "rig.xml"))


async def safe_stop_in_torque_mode(refuse: bool) -> None:
    async with serving(heartbeat_timeout_s=0.2, safe_ramp_rad_s2=RAMP_RAD_S2) as (
            rigs, stand_ins, client):
        rig, stand_in = rigs["north"], stand_ins["north"]
        await rig.follow(replace(FREE_RUN, drive_mode=DriveModeEnum.torque))
        await rig.sample_in(SAMPLE | {"DriveSpeed": 3.0}, 0)
        north = await view(client, "north")
        await client.write_values([north.nodes["TorqueCommand"], north.nodes["CommandCounter"]],
                                  [ua.Variant(1000.0, DOUBLE), ua.Variant(1, UINT32)])
        stand_in.refuse_with = "refused for the test" if refuse else None
        await client.disconnect()                   # the torque-mode owner goes
        async with second_client(client) as other_session:
            other = await view(other_session, "north")
            await wait_for(other, "Status", 5 if refuse else HEARTBEAT_LOST)     # Faulted
            assert stand_in.switches == ["speed"]
            if refuse:
                assert "speed mode" in await other.value("StatusText")
                await method(other, "Reset")
                assert await other.value("Status") == WAITING_FOR_CLIENT
                return
            sent = len(stand_in.commands)
            await feed(rig, 0, 150)                  # 3 rad/s at 2 rad/s^2: at rest in 1.5 s
            speeds = [c.speed_rad_s for c, _ in stand_in.commands[sent:]]
            assert speeds[0] == 3.0 - RAMP_RAD_S2 * 0.01 and speeds[-1] == 0.0
            assert await other.value("DriveMode") == SPEED


@pytest.mark.parametrize("refuse", [False, True])
def test_in_torque_mode_the_safe_stop_switches_to_speed_and_ramps_from_the_drive_speed(
        refuse: bool) -> None:
    run(safe_stop_in_torque_mode(refuse))
