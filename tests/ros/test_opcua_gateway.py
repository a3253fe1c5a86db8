"""The OPC UA gateway against a real asyncua client, with sim_node and opcua_gateway as
processes over loopback (issue 33).

- The address space: the rig object, its BrowseNames, units (EUInformation, UNECE) and
  EURanges, source timestamps in simulated time.
- Bad writes (NaN, inf, out of range, wrong type, read-only, a counter out of turn) are
  refused with their Bad status codes, counted (``RejectedWrites``, /diagnostics), and never
  advance the sim.
- A PI law closes the loop through the counters (SampleCounter polled), the client goes away
  (the sim waits), another one comes back and goes on through the counters (SampleCounter
  subscribed) and through ``Step``: the recorded telemetry equals the in-process
  bench of the same law, bit for bit. The client uses asyncua and the law only.
- A secured gateway (Basic256Sha256, Sign & Encrypt, user and password) admits its user
  only; an off-loopback endpoint without it is refused at start in one line.
"""

from __future__ import annotations

import asyncio
import math
import signal
import socket
import subprocess
import sys
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import pytest
from asyncua import Client, ua
from asyncua.crypto.cert_gen import setup_self_signed_certificate
from asyncua.crypto.security_policies import SecurityPolicyBasic256Sha256
from cryptography.x509.oid import ExtendedKeyUsageOID

from drill_sim_ros import topics
from drill_sim_ros.control.bench import run_in_process, sim_node_parameters
from drill_sim_ros.control.scenario import Scenario
from drill_sim_ros.hil.security import APPLICATION_URI
from drill_sim_ros.ros.closed_loop import read_telemetry
from tests.archive.helpers import BIN, running, stop
from tests.ros.harness import Probe, Ros, ros_context
from tests.ros.opcua_pi_law import EXAMPLE, pi_step

pytestmark = pytest.mark.ros
SCENARIO = Scenario(controller="tests.ros.opcua_pi_law:PiLaw", duration_s=6.0,
                    enable_at_s=0.0)
PERIODS = 600
NAMESPACE_URI = "urn:drill_sim_ros"
START_TIMEOUT_S = 60.0        # sim_node's start (kernel cache load) and the gateway's
RUN_TIMEOUT_S = 120.0
DOUBLE, UINT32 = ua.VariantType.Double, ua.VariantType.UInt32
WAITING_FOR_SIM, HEARTBEAT_LOST, SIM_LOST = 0, 3, 4      # RigStatus values (docs/hil.md)


def free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


def sim_command(record: Path | None, lockstep: bool = True, namespace: str = "") -> list[str]:
    values = {"lockstep": lockstep, "lockstep_trigger": "command", "status_line": False,
              "publish_clock": False, **sim_node_parameters(SCENARIO, SCENARIO.load_preset())}
    if record is not None:
        values["record.path"] = str(record)
    args = []
    for name, value in values.items():
        text = ("true" if value else "false") if isinstance(value, bool) else str(value)
        args += ["-p", f"{name}:={text}"]
    remap = ["-r", f"__ns:={namespace}"] if namespace else []
    return ["sim_node", "--ros-args", *remap, *args]


@contextmanager
def sim_and_gateway(tmp_path: Path, record: Path | None = None, lockstep: bool = True,
                    namespace: str = "", options: tuple[str, ...] = ()
                    ) -> Iterator[tuple[subprocess.Popen, subprocess.Popen, str]]:
    url = f"opc.tcp://127.0.0.1:{free_port()}/drill_sim/"
    remap = ["-r", f"__ns:={namespace}"] if namespace else []
    with running(sim_command(record, lockstep, namespace), tmp_path / "sim.log") as sim, \
            running(["opcua_gateway", "--ros-args", *remap, "-p", f"endpoint:={url}",
                     *options],
                    tmp_path / "gateway.log") as gateway:
        yield sim, gateway, url


class Rig:
    """A connected client's view of the rig object: its children by BrowseName."""

    def __init__(self, client: Client, index: int, obj: Any, nodes: dict[str, Any]) -> None:
        self.client, self.index, self.obj, self.nodes = client, index, obj, nodes

    async def value(self, name: str) -> Any:
        return await self.nodes[name].read_value()

    async def write(self, **values: ua.Variant) -> None:
        """One write request of several variables."""
        await self.client.write_values([self.nodes[n] for n in values], list(values.values()))

    async def step(self) -> int:
        return await self.obj.call_method(f"{self.index}:Step")


async def plain_client(url: str) -> Client:
    client = Client(url, timeout=5)
    client.session_timeout = 600_000        # (the server's maximum)
    return client


async def connect(url: str, deadline_s: float = START_TIMEOUT_S, rig_name: str = "Rig",
                  make_client: Any = plain_client) -> tuple[Client, Rig]:
    """A client (``await make_client(url)``) connected to the gateway's ``rig_name`` once
    its samples come (Status neither WaitingForSim nor SimLost; bounded)."""
    loop = asyncio.get_running_loop()
    end = loop.time() + deadline_s
    while True:
        try:
            client = await make_client(url)       # (a secured one asks for the certificate)
            await client.connect()
            index = await client.get_namespace_index(NAMESPACE_URI)
            obj = await client.nodes.objects.get_child(f"{index}:{rig_name}")
            nodes = {(await n.read_browse_name()).Name: n for n in await obj.get_children()}
            rig = Rig(client, index, obj, nodes)
            if await rig.value("Status") not in (WAITING_FOR_SIM, SIM_LOST):
                return client, rig
            await client.disconnect()
        except (OSError, asyncio.TimeoutError, ua.UaError):
            pass
        assert loop.time() < end, f"the gateway at {url} did not run in {deadline_s} s"
        await asyncio.sleep(0.2)


async def wait_sample(rig: Rig, counter: int, timeout_s: float = 10.0) -> None:
    """Poll SampleCounter until it equals ``counter``, as a PLC does (bounded)."""
    end = asyncio.get_running_loop().time() + timeout_s
    while await rig.value("SampleCounter") != counter:
        assert asyncio.get_running_loop().time() < end, f"no sample for command {counter}"


def run(coroutine: Any, timeout_s: float = RUN_TIMEOUT_S) -> Any:
    return asyncio.run(asyncio.wait_for(coroutine, timeout_s))


# ---- the address space and bad writes -----------------------------------------------------

EXPECTED_UNITS = {"DriveSpeed": ("rad/s", "2A"), "MotorTorque": ("N·m", "NU"),
                  "QuillTorque": ("N·m", "NU"), "HookLoad": ("N", "NEW"),
                  "WobEstimate": ("N", "NEW"), "BitDepth": ("m", "MTR"), "Rop": ("m/s", "MTS"),
                  "SimTime": ("s", "SEC"), "ControlPeriod": ("s", "SEC"),
                  "SpeedSetpoint": ("rad/s", "2A"),
                  "TorqueCommand": ("N·m", "NU"), "WobSetpoint": ("N", "NEW")}
OTHERS = {"DriveMode", "CommandCounter", "SampleCounter", "Lockstep", "Status",
          "RejectedWrites", "Step", "Heartbeat", "StatusText", "Reset"}


async def check_address_space(rig: Rig) -> None:
    assert set(rig.nodes) == set(EXPECTED_UNITS) | OTHERS
    for name, (symbol, code) in EXPECTED_UNITS.items():
        eu = await (await rig.nodes[name].get_child("0:EngineeringUnits")).read_value()
        assert eu.NamespaceUri == "http://www.opcfoundation.org/UA/units/un/cefact"
        assert (eu.DisplayName.Text, eu.UnitId) == (symbol, int.from_bytes(code.encode()))
    speed = await (await rig.nodes["SpeedSetpoint"].get_child("0:EURange")).read_value()
    assert (speed.Low, speed.High) == (0.0, 300.0 * math.pi / 30.0)   # limits.max_surface_rpm
    torque = await (await rig.nodes["TorqueCommand"].get_child("0:EURange")).read_value()
    assert torque.Low == -torque.High < 0
    assert await rig.value("Lockstep") is True
    assert await rig.value("DriveMode") == 0                  # DriveModeEnum speed
    stamp = (await rig.nodes["SimTime"].read_data_value()).SourceTimestamp
    assert stamp.year == 1970 and await rig.value("SimTime") == 0.0


BAD_WRITES = [  # (variable, variant, status code)
    ("SpeedSetpoint", ua.Variant(math.nan, DOUBLE), ua.uaerrors.BadOutOfRange),
    ("SpeedSetpoint", ua.Variant(math.inf, DOUBLE), ua.uaerrors.BadOutOfRange),
    ("WobSetpoint", ua.Variant(-1.0, DOUBLE), ua.uaerrors.BadOutOfRange),
    ("TorqueCommand", ua.Variant(-1e30, DOUBLE), ua.uaerrors.BadOutOfRange),
    ("SpeedSetpoint", ua.Variant(1000.0, DOUBLE), ua.uaerrors.BadOutOfRange),
    ("SpeedSetpoint", ua.Variant(3.0, ua.VariantType.Float), ua.uaerrors.BadTypeMismatch),
    ("DriveMode", ua.Variant(2, ua.VariantType.Int32), ua.uaerrors.BadOutOfRange),
    ("DriveMode", ua.Variant("speed", ua.VariantType.String), ua.uaerrors.BadTypeMismatch),
    ("CommandCounter", ua.Variant(1, ua.VariantType.Int64), ua.uaerrors.BadTypeMismatch),
    ("CommandCounter", ua.Variant(2, UINT32), ua.uaerrors.BadInvalidState),   # out of turn
    ("SampleCounter", ua.Variant(1, UINT32), ua.uaerrors.BadNotWritable),
    ("QuillTorque", ua.Variant(0.0, DOUBLE), ua.uaerrors.BadNotWritable),
]


async def check_bad_writes(rig: Rig) -> None:
    for name, value, error in BAD_WRITES:
        with pytest.raises(error):
            await rig.nodes[name].write_value(value)
    # a request with one bad value is refused whole: its counter increment sends nothing
    with pytest.raises(ua.uaerrors.BadOutOfRange):
        await rig.write(SpeedSetpoint=ua.Variant(5.0, DOUBLE),
                        WobSetpoint=ua.Variant(math.nan, DOUBLE),
                        CommandCounter=ua.Variant(1, UINT32))
    assert await rig.value("RejectedWrites") == len(BAD_WRITES) + 1
    assert await rig.value("CommandCounter") == 0
    assert await rig.value("SpeedSetpoint") != 5.0
    # ... and the sim did not advance; a good command then does
    await rig.write(CommandCounter=ua.Variant(1, UINT32))
    await wait_sample(rig, 1)
    assert await rig.value("SimTime") == pytest.approx(0.01, abs=1e-12)


async def browse_and_refuse(url: str) -> None:
    client, rig = await connect(url)
    try:
        await check_address_space(rig)
        await check_bad_writes(rig)
    finally:
        await client.disconnect()


def gateway_diagnostics(ros: Ros, probe: Probe) -> dict[str, str]:
    """The values of the gateway's latest status on /diagnostics (bounded wait)."""
    def latest() -> dict[str, str] | None:
        for msg in reversed(probe.messages(topics.DIAGNOSTICS)):
            for item in msg.status:
                if item.name == "opcua_gateway: Rig":
                    return {kv.key: kv.value for kv in item.values} | {"level": item.level}
        return None
    assert ros.spin_until(lambda: latest() is not None, 10.0), "no gateway diagnostics"
    return latest()


def test_address_space_units_ranges_and_bad_writes(tmp_path: Path) -> None:
    with sim_and_gateway(tmp_path) as (sim, gateway, url), ros_context() as ros:
        run(browse_and_refuse(url))
        probe = ros.add(Probe(ros.context, [topics.DIAGNOSTICS]))
        figures = gateway_diagnostics(ros, probe)
        assert figures["rejected_writes"] == str(len(BAD_WRITES) + 1)
        assert figures["commands_sent"] == figures["sample_counter"] == "1"
        assert stop(gateway, signal.SIGINT) == 0, (tmp_path / "gateway.log").read_text()
        assert stop(sim, signal.SIGINT) == 0
    assert "Traceback" not in (tmp_path / "gateway.log").read_text()


# ---- the closed loop ------------------------------------------------------------------------

async def law_through_counters(rig: Rig, first: int, last: int, integral: float) -> float:
    """Commands ``first`` .. ``last`` by CommandCounter; the law's integral after them."""
    for counter in range(first, last + 1):
        speed, integral = pi_step(integral, await rig.value("QuillTorque"))
        await rig.write(SpeedSetpoint=ua.Variant(speed, DOUBLE),
                        CommandCounter=ua.Variant(counter, UINT32))
        await wait_sample(rig, counter)
    return integral


class SampleCounterChanges:
    """asyncua's data-change handler for SampleCounter: its latest value, an event per change."""

    def __init__(self) -> None:
        self.value = -1
        self.changed = asyncio.Event()

    def datachange_notification(self, _node: Any, value: int, _data: Any) -> None:
        self.value = value
        self.changed.set()


async def law_through_subscription(rig: Rig, first: int, last: int, integral: float) -> float:
    """Commands ``first`` .. ``last`` by CommandCounter, SampleCounter by data changes."""
    changes = SampleCounterChanges()
    subscription = await rig.client.create_subscription(1, changes)
    await subscription.subscribe_data_change(rig.nodes["SampleCounter"])
    for counter in range(first, last + 1):
        speed, integral = pi_step(integral, await rig.value("QuillTorque"))
        changes.changed.clear()
        await rig.write(SpeedSetpoint=ua.Variant(speed, DOUBLE),
                        CommandCounter=ua.Variant(counter, UINT32))
        while changes.value != counter:
            await asyncio.wait_for(changes.changed.wait(), 10.0)
            changes.changed.clear()
    await subscription.delete()
    return integral


async def law_through_step(rig: Rig, first: int, last: int, integral: float) -> float:
    """Commands ``first`` .. ``last`` by the method Step."""
    for counter in range(first, last + 1):
        speed, integral = pi_step(integral, await rig.value("QuillTorque"))
        await rig.write(SpeedSetpoint=ua.Variant(speed, DOUBLE))
        assert await rig.step() == counter
    return integral


async def close_the_loop(url: str) -> None:
    half = PERIODS // 2
    client, rig = await connect(url)
    integral = await law_through_counters(rig, 1, half, 0.0)
    await client.disconnect()                    # the client goes away ...
    await asyncio.sleep(0.5)
    client, rig = await connect(url)             # ... and comes back: the sim waited
    try:
        assert await rig.value("SampleCounter") == await rig.value("CommandCounter") == half
        assert await rig.value("SimTime") == pytest.approx(half * 0.01, abs=1e-9)
        integral = await law_through_subscription(rig, half + 1, half + 100, integral)
        await law_through_step(rig, half + 101, PERIODS, integral)
    finally:
        await client.disconnect()


def test_a_pi_law_through_opcua_gives_the_bench_telemetry_bit_for_bit(tmp_path: Path) -> None:
    record = tmp_path / "run.mcap"
    with sim_and_gateway(tmp_path, record) as (sim, gateway, url):
        run(close_the_loop(url))
        assert stop(gateway, signal.SIGINT) == 0, (tmp_path / "gateway.log").read_text()
        assert stop(sim, signal.SIGINT) == 0, (tmp_path / "sim.log").read_text()
    remote = read_telemetry(record)
    local = run_in_process(SCENARIO).rows
    assert remote.shape == local.shape == (PERIODS + 1, local.shape[1])
    assert remote.tobytes() == local.tobytes()


EXAMPLE_PERIODS = 300


def test_the_example_controller_gives_the_bench_telemetry_bit_for_bit(tmp_path: Path) -> None:
    """examples/opcua_controller.py, a process with asyncua and the law only."""
    record = tmp_path / "run.mcap"
    with sim_and_gateway(tmp_path, record) as (sim, gateway, url):
        done = subprocess.run([sys.executable, str(EXAMPLE), "--endpoint", url, "--periods",
                               str(EXAMPLE_PERIODS)], capture_output=True, text=True,
                              timeout=RUN_TIMEOUT_S)
        assert done.returncode == 0, done.stderr[-2000:]
        assert stop(gateway, signal.SIGINT) == 0
        assert stop(sim, signal.SIGINT) == 0
    remote = read_telemetry(record)
    local = run_in_process(SCENARIO).rows[:EXAMPLE_PERIODS + 1]
    assert remote.tobytes() == local.tobytes()


# ---- free run: a PLC's own cycle at real time -----------------------------------------------

async def wait_until(rig: Rig, name: str, holds: Any, timeout_s: float = 20.0) -> Any:
    """Poll ``name`` until ``holds(value)`` (bounded); the value."""
    end = asyncio.get_running_loop().time() + timeout_s
    while not holds(value := await rig.value(name)):
        assert asyncio.get_running_loop().time() < end, f"{name} stayed at {value}"
        await asyncio.sleep(0.02)
    return value


async def drive_in_free_run(url: str) -> None:
    client, rig = await connect(url, rig_name="rig2")           # the namespace's last part
    assert rig.obj.nodeid == ua.NodeId("rig2", rig.index)
    try:
        assert await rig.value("Lockstep") is False
        start_s = await rig.value("SimTime")
        await wait_until(rig, "SimTime", lambda t: t > start_s)       # the values follow
        counter = await rig.value("SampleCounter") + 1
        await rig.write(SpeedSetpoint=ua.Variant(8.0, DOUBLE),
                        CommandCounter=ua.Variant(counter, UINT32))
        await wait_sample(rig, counter)
        await wait_until(rig, "DriveSpeed", lambda w: abs(w - 8.0) < 0.4)   # and it acts
    finally:
        await client.disconnect()


def test_in_free_run_in_a_namespace_the_values_follow_and_a_counted_command_acts(
        tmp_path: Path) -> None:
    with sim_and_gateway(tmp_path, lockstep=False, namespace="/site/rig2") as (sim, gateway,
                                                                              url):
        run(drive_in_free_run(url))
        assert stop(gateway, signal.SIGINT) == 0, (tmp_path / "gateway.log").read_text()
        assert stop(sim, signal.SIGINT) == 0


# ---- safe by default ------------------------------------------------------------------------

async def make_certificates(folder: Path) -> None:
    """Self-signed certificates for the gateway (its URI) and for a client."""
    for name, uri, use in (("server", APPLICATION_URI, ExtendedKeyUsageOID.SERVER_AUTH),
                           ("client", "urn:drill_sim_ros:test_client",
                            ExtendedKeyUsageOID.CLIENT_AUTH)):
        await setup_self_signed_certificate(folder / f"{name}_key.pem",
                                            folder / f"{name}_cert.der", uri, "localhost",
                                            [use], {})


def secured_client(folder: Path, password: str) -> Any:
    async def make(url: str) -> Client:
        client = await plain_client(url)
        client.application_uri = "urn:drill_sim_ros:test_client"
        await client.set_security(SecurityPolicyBasic256Sha256, str(folder / "client_cert.der"),
                                  str(folder / "client_key.pem"))
        client.set_user("plc")
        client.set_password(password)
        return client
    return make


async def secured_session(url: str, folder: Path) -> None:
    client, rig = await connect(url, make_client=secured_client(folder, "s3cret"))
    try:
        assert await rig.step() == 1
    finally:
        await client.disconnect()
    with pytest.raises(ua.UaError, match="No matching endpoints"):   # anonymous, no security
        await (await plain_client(url)).connect()
    with pytest.raises(ua.uaerrors.BadUserAccessDenied):
        await (await secured_client(folder, "guess")(url)).connect()


def test_a_secured_gateway_admits_its_user_only(tmp_path: Path) -> None:
    run(make_certificates(tmp_path))
    (tmp_path / "password").write_text("s3cret\n")
    options = ["-p", f"security.certificate:={tmp_path / 'server_cert.der'}",
               "-p", f"security.private_key:={tmp_path / 'server_key.pem'}",
               "-p", "security.user:=plc",
               "-p", f"security.password_file:={tmp_path / 'password'}"]
    with sim_and_gateway(tmp_path, options=tuple(options)) as (sim, gateway, url):
        run(secured_session(url, tmp_path))
        assert stop(gateway, signal.SIGINT) == 0, (tmp_path / "gateway.log").read_text()
        assert stop(sim, signal.SIGINT) == 0


def test_half_a_security_setting_is_refused_in_one_line() -> None:
    done = subprocess.run([str(BIN / "opcua_gateway"), "--ros-args", "-p", "security.user:=plc"],
                          capture_output=True, text=True, timeout=60)
    assert done.returncode == 2
    lines = (done.stdout + done.stderr).strip().splitlines()
    assert len(lines) == 1 and "missing: security.certificate, security.private_key" in lines[0]


@pytest.mark.parametrize("endpoint", ["opc.tcp://0.0.0.0:4840/drill_sim/",
                                      "opc.tcp://192.0.2.7:4840/", "http://127.0.0.1:4840/"])
def test_an_insecure_or_malformed_endpoint_is_refused_in_one_line(endpoint: str) -> None:
    done = subprocess.run([str(BIN / "opcua_gateway"), "--ros-args", "-p",
                           f"endpoint:={endpoint}"], capture_output=True, text=True,
                          timeout=60)
    assert done.returncode == 2
    lines = (done.stdout + done.stderr).strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in lines[0]
    assert endpoint in lines[0]


def test_without_a_sim_node_the_gateway_says_so_in_one_line() -> None:
    endpoint = f"opc.tcp://127.0.0.1:{free_port()}/drill_sim/"
    done = subprocess.run([str(BIN / "opcua_gateway"), "--ros-args", "-p", f"endpoint:={endpoint}",
                           "-p", "sim_wait_s:=1.0", "-r", "__ns:=/nobody_here"],
                          capture_output=True, text=True, timeout=60)
    assert done.returncode == 2
    lines = (done.stdout + done.stderr).strip().splitlines()
    assert len(lines) == 1 and "no sim_node /nobody_here/drill_sim answered" in lines[0], lines
