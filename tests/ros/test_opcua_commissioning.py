"""Commissioning the OPC UA gateway as an automation engineer would (issue 53): sim_node and
opcua_gateway as processes over loopback, real asyncua clients with none of this package's
code.

One run, in the order a commissioning goes: 300 rev/min written as a PLC computes it is in
range, an array to a scalar is a counted BadTypeMismatch, a second session is refused
(BadUserAccessDenied) while the first owns the setpoints; sim_node stops (SIGINT) and a Step
is left outstanding: it gives up after its bounded wait, the session's reads go on, Status says
SimLost; sim_node restarted (in free run) resyncs the counters and a writer goes on; the
owner's client then goes away in free run: HeartbeatLost, the drive comes to rest, and only
Reset lets a writer in again. Meanwhile ``opcua_gateway --export-nodeset`` writes a NodeSet2
that a fresh asyncua server imports.
"""

from __future__ import annotations

import asyncio
import math
import signal
import subprocess
from pathlib import Path

import pytest
from asyncua import Client, Server, ua
from rclpy.node import Node

from drill_sim_ros import topics
from drill_sim_ros.control.bench import run_in_process
from drill_sim_ros.ros.closed_loop import read_telemetry
from tests.archive.helpers import BIN, running, stop
from tests.ros.harness import ros_context
from tests.ros.opcua_pi_law import pi_step
from tests.ros.plc_handshake import DONE, IDLE, DriveModeEnum, RigHandshake
from tests.ros.test_opcua_gateway import (
    DOUBLE,
    HEARTBEAT_LOST,
    SCENARIO,
    SIM_LOST,
    START_TIMEOUT_S,
    UINT32,
    Rig,
    connect,
    free_port,
    make_certificates,
    run,
    sim_and_gateway,
    sim_command,
    wait_sample,
    wait_until,
)

pytestmark = pytest.mark.ros
RUNNING, WAITING_FOR_CLIENT = 1, 2
INT32 = ua.VariantType.Int32
REST_RAD_S = 0.05          # |drive speed| at rest (the speed loop holds a zero setpoint)


async def first_session_owns(url: str) -> tuple[Client, Rig]:
    owner, rig = await connect(url)
    await rig.write(SpeedSetpoint=ua.Variant(300 * math.pi / 30, DOUBLE))     # 300 rev/min
    assert await rig.value("SpeedSetpoint") == 300 * math.pi / 30
    with pytest.raises(ua.uaerrors.BadTypeMismatch):
        await rig.write(SpeedSetpoint=ua.Variant([3.0], DOUBLE))
    await rig.write(SpeedSetpoint=ua.Variant(4.0, DOUBLE), CommandCounter=ua.Variant(1, UINT32))
    await wait_sample(rig, 1)
    assert await rig.value("Status") == RUNNING
    other, other_rig = await connect(url)
    # the owner beats once more: a slow connect may outlast heartbeat_timeout_s (1 s here),
    # after which a silent owner in lockstep lets go and the other session's writes would pass
    await rig.write(Heartbeat=ua.Variant(1, UINT32))
    try:
        with pytest.raises(ua.uaerrors.BadUserAccessDenied):
            await other_rig.write(SpeedSetpoint=ua.Variant(5.0, DOUBLE),
                                  CommandCounter=ua.Variant(2, UINT32))
        with pytest.raises(ua.uaerrors.BadUserAccessDenied):
            await other_rig.step()
    finally:
        await other.disconnect()
    assert await rig.value("RejectedWrites") == 3
    assert await rig.value("ControlPeriod") == 0.01
    return owner, rig


async def step_without_sim_node(rig: Rig) -> None:
    step = asyncio.ensure_future(rig.step())
    assert await rig.value("SampleCounter") == 1          # read behind the Step: answered
    with pytest.raises(ua.uaerrors.BadTimeout):
        await step
    await wait_until(rig, "Status", lambda s: s == SIM_LOST)


async def resync_then_client_gone(rig: Rig) -> None:
    await wait_until(rig, "Lockstep", lambda on: on is False, START_TIMEOUT_S)
    # samples come again (the owner, silent meanwhile, lost the setpoints: lockstep)
    await wait_until(rig, "Status", lambda s: s == WAITING_FOR_CLIENT, START_TIMEOUT_S)
    counter = await rig.value("SampleCounter")
    assert await rig.value("CommandCounter") == counter == 2     # resynced
    await rig.write(SpeedSetpoint=ua.Variant(6.0, DOUBLE),
                    CommandCounter=ua.Variant(counter + 1, UINT32))
    await wait_sample(rig, counter + 1)
    assert await rig.value("Status") == RUNNING
    await rig.client.disconnect()                          # the PLC goes away in free run


async def safe_stop_and_reset(url: str) -> None:
    client, rig = await connect(url)
    try:
        await wait_until(rig, "Status", lambda s: s == HEARTBEAT_LOST)    # (just closed)
        await wait_until(rig, "StatusText", lambda text: "at rest" in text)
        assert await rig.value("SpeedSetpoint") == 0.0
        await wait_until(rig, "DriveSpeed", lambda w: abs(w) < REST_RAD_S)
        with pytest.raises(ua.uaerrors.BadInvalidState):
            await rig.write(SpeedSetpoint=ua.Variant(1.0, DOUBLE))
        await rig.obj.call_method(f"{rig.index}:Reset")
        assert await rig.value("Status") == WAITING_FOR_CLIENT
        await rig.write(SpeedSetpoint=ua.Variant(1.0, DOUBLE))
        assert await rig.value("Status") == RUNNING
    finally:
        await client.disconnect()


async def export_nodeset(path: Path) -> None:
    """``opcua_gateway --export-nodeset``, with the running sim_node's ranges, into a fresh
    asyncua server (tests/hil/test_rig_server.py checks the whole round trip)."""
    done = await asyncio.to_thread(subprocess.run, [str(BIN / "opcua_gateway"),
                                                    "--export-nodeset", str(path)],
                                   capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    fresh = Server()
    await fresh.init()
    await fresh.import_xml(str(path))
    index = await fresh.get_namespace_index("urn:drill_sim_ros")
    speed = fresh.get_node(ua.NodeId("Rig.SpeedSetpoint", index))
    assert await speed.read_type_definition() == ua.NodeId(ua.ObjectIds.AnalogItemType)
    assert (await (await speed.get_child("0:EURange")).read_value()).High == 10 * math.pi
    mode_type = fresh.get_node(await fresh.get_node(ua.NodeId("Rig.DriveMode", index))
                               .read_data_type())
    names = await (await mode_type.get_child("0:EnumStrings")).read_value()
    assert [n.Text for n in names] == [m.name for m in DriveModeEnum]


async def commission(url: str, sim: subprocess.Popen, tmp_path: Path) -> None:
    _, rig = await first_session_owns(url)
    await export_nodeset(tmp_path / "rig.xml")
    assert await asyncio.to_thread(stop, sim, signal.SIGINT) == 0     # sim_node goes
    await step_without_sim_node(rig)
    with running([*sim_command(None, lockstep=False)], tmp_path / "sim_again.log") as again:
        await resync_then_client_gone(rig)
        await safe_stop_and_reset(url)
        assert await asyncio.to_thread(stop, again, signal.SIGINT) == 0


def test_commissioning_one_writer_a_lost_sim_node_and_a_lost_client(tmp_path: Path) -> None:
    url = f"opc.tcp://127.0.0.1:{free_port()}/drill_sim/"
    with running(sim_command(None), tmp_path / "sim.log") as sim, \
            running(["opcua_gateway", "--ros-args", "-p", f"endpoint:={url}",
                     "-p", "heartbeat_timeout_s:=1.0"], tmp_path / "gateway.log") as gateway:
        run(commission(url, sim, tmp_path))
        assert stop(gateway, signal.SIGINT) == 0, (tmp_path / "gateway.log").read_text()
    log = (tmp_path / "gateway.log").read_text()
    assert "Traceback" not in log and "[ERROR]" not in log


PROGRESS_TIMEOUT_S = 30.0     # for the gateway's first progress line (one every 5 s)
SIM_VALUES = {"limits.max_surface_rpm": 300.0, "limits.max_wob_n": 2e5,
              "top_drive.max_torque_nm": 5e4, "publish_rate_hz": 100.0,
              "model.surface_rpm": 60.0, "model.applied_wob_n": 6e4, "top_drive.mode": "speed",
              "lockstep": True, "lockstep_trigger": "command"}


def test_a_slow_first_start_is_waited_for_with_progress_lines(tmp_path: Path) -> None:
    """A sim_node whose parameter services answer before its parameters are declared (a first
    start loading the kernel) is asked again until they are, and the gateway says so."""
    url = f"opc.tcp://127.0.0.1:{free_port()}/drill_sim/"
    log = tmp_path / "gateway.log"
    with ros_context() as ros:
        stand_in = ros.add(Node(topics.NODE_NAME, namespace="/slow_start", context=ros.context))
        with running(["opcua_gateway", "--ros-args", "-r", "__ns:=/slow_start",
                      "-p", f"endpoint:={url}", "-p", "sim_wait_s:=60.0"], log) as gateway:
            # the stand-in answers at once and declares its parameters only after the
            # gateway said it waits for them
            assert ros.spin_until(lambda: "waiting for" in log.read_text(),
                                  PROGRESS_TIMEOUT_S), log.read_text()
            assert gateway.poll() is None, log.read_text()
            for name, value in SIM_VALUES.items():
                stand_in.declare_parameter(name, value)
            assert ros.spin_until(lambda: "serving" in log.read_text(), 30.0), log.read_text()
            assert stop(gateway, signal.SIGINT) == 0, log.read_text()
    text = log.read_text()
    assert "waiting for /slow_start/drill_sim's parameters" in text
    assert "it answers, not all declared yet" in text
    assert "FATAL" not in text and "Traceback" not in text, text


@pytest.mark.parametrize("mismatch", ["uri", "key"])
def test_a_certificate_that_cannot_serve_is_refused_at_start_in_one_line(
        tmp_path: Path, mismatch: str) -> None:
    run(make_certificates(tmp_path))            # the gateway's (its URI) and a client's
    (tmp_path / "password").write_text("s3cret\n")
    certificate, key = tmp_path / "server_cert.der", tmp_path / "server_key.pem"
    if mismatch == "uri":                       # a client certificate: another URI
        certificate, key = tmp_path / "client_cert.der", tmp_path / "client_key.pem"
    else:                                       # the gateway's certificate, another key
        key = tmp_path / "client_key.pem"
    done = subprocess.run(
        [str(BIN / "opcua_gateway"), "--ros-args", "-p", f"security.certificate:={certificate}",
         "-p", f"security.private_key:={key}", "-p", "security.user:=plc",
         "-p", f"security.password_file:={tmp_path / 'password'}"],
        capture_output=True, text=True, timeout=60)
    assert done.returncode == 2
    lines = (done.stdout + done.stderr).strip().splitlines()
    assert len(lines) == 1 and "FATAL" in lines[0], lines
    assert ("urn:drill_sim_ros:test_client" if mismatch == "uri" else "is not the key of") \
        in lines[0]


PLC_PERIODS = 300


async def plc_task(url: str, periods: int) -> None:
    """A PLC's cyclic task around FB_RigHandshake (its Python mirror): each scan one read list
    (SampleCounter, Status, QuillTorque), the block, and the write list (DriveMode speed, the
    speed setpoint, CommandCounter) when it says so."""
    client, rig = await connect(url)
    fb, integral, written = RigHandshake(), 0.0, 0
    reads = [rig.nodes[name] for name in ("SampleCounter", "Status", "QuillTorque")]
    write_done = write_error = False
    try:
        while written < periods or fb.busy:
            fb.sample_counter, fb.status, torque_nm = await rig.client.read_values(reads)
            fb.write_done, fb.write_error = write_done, write_error
            write_done = write_error = False
            fb.execute = fb.state in (IDLE, DONE) and written < periods
            if fb.execute:
                speed, next_integral = pi_step(integral, torque_nm)
            fb.cycle()
            assert not fb.error, f"FB_RigHandshake failed: ErrorID {fb.error_id:#06x}"
            if fb.do_write:
                integral, written = next_integral, written + 1
                try:
                    await rig.write(DriveMode=ua.Variant(int(DriveModeEnum.speed), INT32),
                                    SpeedSetpoint=ua.Variant(speed, DOUBLE),
                                    CommandCounter=ua.Variant(fb.command_counter, UINT32))
                    write_done = True
                except ua.UaStatusCodeError:
                    write_error = True
    finally:
        await client.disconnect()


def test_the_structured_text_handshake_closes_the_loop_bit_for_bit(tmp_path: Path) -> None:
    record = tmp_path / "run.mcap"
    with sim_and_gateway(tmp_path, record) as (sim, gateway, url):
        run(plc_task(url, PLC_PERIODS))
        assert stop(gateway, signal.SIGINT) == 0
        assert stop(sim, signal.SIGINT) == 0
    remote = read_telemetry(record)
    local = run_in_process(SCENARIO).rows[:PLC_PERIODS + 1]
    assert remote.tobytes() == local.tobytes()
