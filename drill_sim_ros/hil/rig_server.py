"""One rig's OPC UA server (asyncua): the address space of :mod:`.address_space`, the checks
of every client write, and the lockstep handshake (ROS-free; the gateway node feeds it).

- A client's write request is checked whole before any of it is applied (asyncua's PreWrite
  callback): a read-only variable, a wrong type, NaN, ±inf, a value outside its EURange or a
  CommandCounter out of turn fails the request with the matching Bad status code
  (BadNotWritable, BadTypeMismatch, BadOutOfRange, BadInvalidState), counted in
  ``RejectedWrites``; nothing of it reaches the simulator.
- ``CommandCounter`` = ``SampleCounter`` + 1 (or a ``Step`` call) hands the setpoints to
  ``send`` as the next period's command, at once; when that period's sample is in the values
  (:meth:`RigServer.sample_in`), ``SampleCounter`` takes the same value and ``Step`` returns
  it. Without a new count, nothing is sent: a client that goes away leaves the sim waiting.
"""

from __future__ import annotations

import asyncio
import logging
import math
from collections.abc import Callable
from dataclasses import dataclass
from datetime import datetime, timedelta, timezone
from typing import Any

from asyncua import Server, ua
from asyncua.common.callback import CallbackType

from drill_sim_ros.control.command import Command
from drill_sim_ros.hil.address_space import (
    DRIVE_MODES,
    NAMESPACE_URI,
    SAMPLE_VARIABLES,
    STEP_METHOD,
    UNECE_URI,
    VARIABLE_BY_NAME,
    VARIABLES,
    Variable,
    node_id,
    unece_unit_id,
)
from drill_sim_ros.hil.security import APPLICATION_URI, PasswordUser, Security

_log = logging.getLogger(__name__)
SIM_EPOCH = datetime(1970, 1, 1, tzinfo=timezone.utc)
UINT32_MODULUS = 2**32
Bad = ua.StatusCodes


@dataclass(frozen=True)
class RigSettings:
    """What the rig object starts with: the setpoints' EURanges (SI, from sim_node's limits),
    the setpoints in force, the drive mode and whether sim_node runs in command lockstep."""

    max_speed_rad_s: float
    max_torque_nm: float
    max_wob_n: float
    speed_rad_s: float
    wob_n: float
    drive_mode: str
    lockstep: bool

    def eu_range(self, name: str) -> tuple[float, float] | None:
        return {"SpeedSetpoint": (0.0, self.max_speed_rad_s),
                "TorqueCommand": (-self.max_torque_nm, self.max_torque_nm),
                "WobSetpoint": (0.0, self.max_wob_n)}.get(name)

    def initial(self, name: str) -> Any:
        return {"SpeedSetpoint": self.speed_rad_s, "TorqueCommand": 0.0,
                "WobSetpoint": self.wob_n, "DriveMode": self.drive_mode,
                "Lockstep": self.lockstep, "Status": "waiting for the first sample"}.get(
                    name, math.nan if name in SAMPLE_NAMES else 0)


SAMPLE_NAMES = frozenset(v.name for v in SAMPLE_VARIABLES)


def variant(variable: Variable, value: Any) -> ua.Variant:
    return ua.Variant(value, getattr(ua.VariantType, variable.type_name))


def eu_information(variable: Variable) -> ua.EUInformation:
    unit = variable.unit
    return ua.EUInformation(NamespaceUri=UNECE_URI, UnitId=unece_unit_id(unit.code),
                            DisplayName=ua.LocalizedText(unit.symbol),
                            Description=ua.LocalizedText(unit.description))


def sim_timestamp(time_ns: int) -> datetime:
    """The source timestamp of a sample: its simulated time after :data:`SIM_EPOCH`."""
    return SIM_EPOCH + timedelta(microseconds=time_ns / 1000)


async def _add_property(node: Any, name: str, value: Any, data_type: int) -> None:
    """A standard property (BrowseName in namespace 0) of ``node``, NodeId ``<node>.<name>``."""
    index = node.nodeid.NamespaceIndex
    await node.add_property(ua.NodeId(f"{node.nodeid.Identifier}.{name}", index),
                            ua.QualifiedName(name, 0),
                            ua.Variant(value, ua.VariantType.ExtensionObject),
                            datatype=ua.NodeId(data_type))


class RigServer:
    """The asyncua server of one rig object ``rig`` at ``endpoint``; ``send(command,
    stamp_ns)`` hands the simulator a command answering the sample stamped ``stamp_ns``
    (called in the event loop)."""

    def __init__(self, endpoint: str, rig: str, settings: RigSettings,
                 send: Callable[[Command, int], None], step_timeout_s: float = 10.0,
                 security: Security | None = None) -> None:
        self.security = security
        self.server = Server(user_manager=None if security is None else PasswordUser(
            security.user, security.password))
        self.endpoint, self.rig, self.settings = endpoint, rig, settings
        self._send = send
        self.step_timeout_s = step_timeout_s
        self.nodes: dict[str, Any] = {}
        self._names: dict[ua.NodeId, str] = {}
        self.values: dict[str, Any] = {v.name: settings.initial(v.name) for v in VARIABLES}
        self._in_force = {"SpeedSetpoint": settings.speed_rad_s, "WobSetpoint": settings.wob_n,
                          "TorqueCommand": math.nan}
        self.latest_ns: int | None = None
        self.outstanding = False
        self.rejected = 0
        self.commands_sent = 0
        self.samples_in = 0
        self._waiters: list[asyncio.Future[int]] = []

    async def start(self) -> None:
        await self.server.init()
        self.server.set_endpoint(self.endpoint)
        self.server.set_server_name(f"drill_sim_ros OPC UA gateway ({self.rig})")
        await self._secure()
        index = await self.server.register_namespace(NAMESPACE_URI)
        rig = await self.server.nodes.objects.add_object(ua.NodeId(self.rig, index),
                                                         ua.QualifiedName(self.rig, index))
        for variable in VARIABLES:
            await self._add_variable(rig, index, variable)
        await rig.add_method(ua.NodeId(node_id(self.rig, STEP_METHOD), index),
                             ua.QualifiedName(STEP_METHOD, index),
                             self._step, [], [ua.VariantType.UInt32])
        self.server.subscribe_server_callback(CallbackType.PreWrite, self._pre_write)
        await self.server.start()

    async def _secure(self) -> None:
        """Anonymous and unencrypted (loopback only), or Basic256Sha256 Sign & Encrypt
        with the one user of :attr:`security`."""
        if self.security is None:
            self.server.set_security_policy([ua.SecurityPolicyType.NoSecurity])
            self.server.set_identity_tokens([ua.AnonymousIdentityToken])
            return
        await self.server.set_application_uri(APPLICATION_URI)
        self.server.set_security_policy([ua.SecurityPolicyType.Basic256Sha256_SignAndEncrypt])
        self.server.set_identity_tokens([ua.UserNameIdentityToken])
        await self.server.load_certificate(str(self.security.certificate))
        await self.server.load_private_key(str(self.security.private_key))

    async def stop(self) -> None:
        await self.server.stop()

    def figures(self) -> dict[str, str]:
        """The diagnostics' key/values (read from any thread: plain ints and strings)."""
        return {"endpoint": self.endpoint, "status": str(self.values["Status"]),
                "rejected_writes": str(self.rejected), "commands_sent": str(self.commands_sent),
                "samples_in": str(self.samples_in),
                "sample_counter": str(self.values["SampleCounter"])}

    async def _add_variable(self, rig: Any, index: int, variable: Variable) -> None:
        node = await rig.add_variable(ua.NodeId(node_id(self.rig, variable.name), index),
                                      ua.QualifiedName(variable.name, index),
                                      variant(variable, self.values[variable.name]))
        if variable.writable:
            await node.set_writable()
        if variable.unit is not None:
            await _add_property(node, "EngineeringUnits", eu_information(variable),
                                ua.ObjectIds.EUInformation)
        eu_range = self.settings.eu_range(variable.name)
        if eu_range is not None:
            await _add_property(node, "EURange", ua.Range(*eu_range), ua.ObjectIds.Range)
        self.nodes[variable.name] = node
        self._names[node.nodeid] = variable.name

    async def _set(self, name: str, value: Any, time_ns: int | None = None) -> None:
        """A value of the gateway's own (not a client write; no checks)."""
        self.values[name] = value
        stamp = sim_timestamp(time_ns) if time_ns is not None else None
        await self.server.write_attribute_value(self.nodes[name].nodeid, ua.DataValue(
            variant(VARIABLE_BY_NAME[name], value), SourceTimestamp=stamp))

    async def set_status(self, text: str) -> None:
        if text != self.values["Status"]:
            await self._set("Status", text)

    # -- client writes --------------------------------------------------------------------
    async def _pre_write(self, event: Any, _dispatcher: Any) -> None:
        """Check a whole write request; raise its Bad status code to refuse all of it."""
        writes = {}
        for item in event.request_params.NodesToWrite:
            name = self._names.get(item.NodeId)
            if name is None:
                continue
            code, value = self._check(name, item)
            if code is not None:
                await self._refuse(name, code, value)
            writes[name] = value
        counter = writes.get("CommandCounter")
        send = counter is not None and counter != self.values["CommandCounter"]
        self.values.update(writes)              # (asyncua applies them after this check)
        if send:
            self._command(self.values, counter)

    def _check(self, name: str, item: ua.WriteValue) -> tuple[int | None, Any]:
        """(None, value) if writing ``item`` to ``name`` is allowed, else (Bad code, value)."""
        variable = VARIABLE_BY_NAME[name]
        data = item.Value.Value
        value = data.Value if data is not None else None
        if item.AttributeId != ua.AttributeIds.Value or not variable.writable:
            return Bad.BadNotWritable, value
        if data is None or data.VariantType != getattr(ua.VariantType, variable.type_name):
            return Bad.BadTypeMismatch, value
        if name == "DriveMode":
            return (None if value in DRIVE_MODES else Bad.BadOutOfRange), value
        if name == "CommandCounter":
            return self._check_counter(value), value
        low, high = self.settings.eu_range(name)
        return (None if math.isfinite(value) and low <= value <= high
                else Bad.BadOutOfRange), value

    def _check_counter(self, counter: int) -> int | None:
        if counter == self.values["CommandCounter"]:
            return None                                # unchanged: nothing to send
        turn = (self.values["SampleCounter"] + 1) % UINT32_MODULUS
        if self.latest_ns is None or self.outstanding or counter != turn:
            return Bad.BadInvalidState
        return None

    async def _refuse(self, name: str, code: int, value: Any) -> None:
        self.rejected += 1
        await self._set("RejectedWrites", self.rejected % UINT32_MODULUS)
        _log.warning("refused a write of %r to %s: %s (%d refused so far)", value, name,
                     ua.StatusCode(code).name, self.rejected)
        raise ua.UaStatusCodeError(code)

    # -- the handshake --------------------------------------------------------------------
    def _command(self, values: dict[str, Any], counter: int) -> None:
        """Send the setpoints of ``values`` as the command counted ``counter``: the drive
        mode's setpoint and the WOB, each only if it differs from the one in force."""
        chosen = "SpeedSetpoint" if values["DriveMode"] == "speed" else "TorqueCommand"
        changed = {name: values[name] for name in (chosen, "WobSetpoint")
                   if values[name] != self._in_force[name]}
        self._in_force.update(changed)
        self.outstanding = True
        self.commands_sent += 1
        self._send(Command(speed_rad_s=changed.get("SpeedSetpoint"),
                           motor_torque_nm=changed.get("TorqueCommand"),
                           wob_n=changed.get("WobSetpoint")), self.latest_ns)
        _log.debug("command %d sent", counter)

    async def _step(self, _parent: ua.NodeId) -> Any:
        """The method Step: CommandCounter + 1 by a call; the new SampleCounter."""
        turn = (self.values["SampleCounter"] + 1) % UINT32_MODULUS
        if self.latest_ns is None or self.outstanding:
            return ua.StatusCode(Bad.BadInvalidState)
        waiter = asyncio.get_running_loop().create_future()
        self._waiters.append(waiter)
        self._command(self.values, turn)
        await self._set("CommandCounter", turn)
        try:
            counter = await asyncio.wait_for(waiter, self.step_timeout_s)
        except TimeoutError:
            return ua.StatusCode(Bad.BadTimeout)
        return [ua.Variant(counter, ua.VariantType.UInt32)]

    async def sample_in(self, values: dict[str, float], time_ns: int) -> None:
        """A sample of sim_node (SAMPLE_VARIABLES' values, stamped ``time_ns``) into the
        variables; it answers the outstanding command, if any. An older one is ignored."""
        if self.latest_ns is not None and time_ns <= self.latest_ns:
            return
        first = self.latest_ns is None
        self.latest_ns = time_ns
        self.samples_in += 1
        for name, value in values.items():
            await self._set(name, value, time_ns)
        if first:
            await self.set_status("running")
        if self.outstanding:
            self.outstanding = False
            await self._set("SampleCounter", self.values["CommandCounter"], time_ns)
            for waiter in self._waiters:
                if not waiter.done():
                    waiter.set_result(self.values["SampleCounter"])
            self._waiters.clear()

