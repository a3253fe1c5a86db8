"""The gateway's OPC UA server (asyncua): one object per rig, each with the address space of
:mod:`.address_space`, the checks of every client write and its own lockstep handshake
(ROS-free; the gateway node feeds it).

- A client's write request is checked whole before any of it is applied (asyncua's PreWrite
  callback): a read-only variable, a wrong type, NaN, ±inf, a value outside its EURange or a
  CommandCounter out of turn fails the request with the matching Bad status code
  (BadNotWritable, BadTypeMismatch, BadOutOfRange, BadInvalidState), counted in that rig's
  ``RejectedWrites``; nothing of it reaches the simulator. A request may span several rigs.
- A new ``DriveMode`` switches the simulator's drive (``switch_mode``) before anything else of
  the request is applied; a switch the simulator refuses fails the request with
  BadInvalidState, one it does not answer with BadTimeout (both counted).
- ``CommandCounter`` = ``SampleCounter`` + 1 (or a ``Step`` call) hands the setpoints to
  ``send`` as the next period's command, at once; when that period's sample is in the values
  (:meth:`Rig.sample_in`), ``SampleCounter`` takes the same value and ``Step`` returns
  it. Without a new count, nothing is sent: a client that goes away leaves the sim waiting.
- The EURanges, ``Lockstep`` and ``DriveMode`` follow the simulator's settings
  (:meth:`Rig.follow`); a sample older than the latest one means the simulator started
  again: the handshake starts over from it (``SampleCounter`` = ``CommandCounter``).
"""

from __future__ import annotations

import asyncio
import logging
import math
from collections.abc import Awaitable, Callable, Sequence
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
from drill_sim_ros.model.errors import DrillSimError

_log = logging.getLogger(__name__)
SIM_EPOCH = datetime(1970, 1, 1, tzinfo=timezone.utc)
UINT32_MODULUS = 2**32
Bad = ua.StatusCodes
SETPOINTS = ("SpeedSetpoint", "TorqueCommand", "WobSetpoint")
MODE_SWITCH_TIMEOUT_S = 5.0
ASYNCUA_SERVER_LOGGER = "asyncua.server.server"   # logs a failed start's traceback
# switch_mode(mode): None once the simulator drives in ``mode``, else its reason for refusing
# (TimeoutError, or any OSError, if it does not answer)
SwitchMode = Callable[[str], Awaitable[str | None]]


@dataclass(frozen=True)
class RigSettings:
    """What a rig object takes from its simulator: the setpoints' EURanges (SI, from sim_node's
    limits), the setpoints in force at start, the drive mode and whether sim_node runs in
    command lockstep."""

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


def _range_variant(low_high: tuple[float, float]) -> ua.Variant:
    return ua.Variant(ua.Range(*low_high), ua.VariantType.ExtensionObject)


async def _add_property(node: Any, name: str, value: ua.Variant, data_type: int) -> Any:
    """A standard property (BrowseName in namespace 0) of ``node``, NodeId ``<node>.<name>``."""
    index = node.nodeid.NamespaceIndex
    return await node.add_property(ua.NodeId(f"{node.nodeid.Identifier}.{name}", index),
                                   ua.QualifiedName(name, 0), value,
                                   datatype=ua.NodeId(data_type))


def _unset_setpoints() -> dict[str, float]:
    """No setpoint known to be in force: the next command carries them all."""
    return dict.fromkeys(SETPOINTS, math.nan)


class Rig:
    """One rig object ``name``; ``send(command, stamp_ns)`` hands its simulator a command
    answering the sample stamped ``stamp_ns``, ``switch_mode`` switches its drive (both called
    in the event loop). Its nodes exist once :meth:`build` has run."""

    def __init__(self, name: str, settings: RigSettings, send: Callable[[Command, int], None],
                 switch_mode: SwitchMode | None = None, step_timeout_s: float = 10.0,
                 mode_switch_timeout_s: float = MODE_SWITCH_TIMEOUT_S) -> None:
        self.name, self.settings = name, settings
        self._send, self._switch_mode = send, switch_mode
        self.step_timeout_s, self.mode_switch_timeout_s = step_timeout_s, mode_switch_timeout_s
        self.nodes: dict[str, Any] = {}
        self._ranges: dict[str, Any] = {}               # EURange property nodes by variable
        self._server: Server | None = None
        self.values: dict[str, Any] = {v.name: settings.initial(v.name) for v in VARIABLES}
        self._in_force = {"SpeedSetpoint": settings.speed_rad_s, "WobSetpoint": settings.wob_n,
                          "TorqueCommand": math.nan}
        self.latest_ns: int | None = None
        self.outstanding = False
        self.rejected = 0
        self.commands_sent = 0
        self.samples_in = 0
        self.restarts = 0
        self._waiters: list[asyncio.Future[int | None]] = []

    # -- the address space ----------------------------------------------------------------
    async def build(self, server: Server, index: int) -> dict[ua.NodeId, str]:
        """Add the rig object under Objects; its writable variables' names by NodeId."""
        self._server = server
        rig = await server.nodes.objects.add_object(ua.NodeId(self.name, index),
                                                    ua.QualifiedName(self.name, index))
        for variable in VARIABLES:
            await self._add_variable(rig, index, variable)
        await rig.add_method(ua.NodeId(node_id(self.name, STEP_METHOD), index),
                             ua.QualifiedName(STEP_METHOD, index),
                             self._step, [], [ua.VariantType.UInt32])
        return {node.nodeid: name for name, node in self.nodes.items()}

    async def _add_variable(self, rig: Any, index: int, variable: Variable) -> None:
        node = await rig.add_variable(ua.NodeId(node_id(self.name, variable.name), index),
                                      ua.QualifiedName(variable.name, index),
                                      variant(variable, self.values[variable.name]))
        if variable.writable:
            await node.set_writable()
        if variable.unit is not None:
            await _add_property(node, "EngineeringUnits", ua.Variant(
                eu_information(variable), ua.VariantType.ExtensionObject),
                ua.ObjectIds.EUInformation)
        eu_range = self.settings.eu_range(variable.name)
        if eu_range is not None:
            self._ranges[variable.name] = await _add_property(
                node, "EURange", _range_variant(eu_range), ua.ObjectIds.Range)
        self.nodes[variable.name] = node

    async def _set(self, name: str, value: Any, time_ns: int | None = None) -> None:
        """A value of the gateway's own (not a client write; no checks)."""
        self.values[name] = value
        stamp = sim_timestamp(time_ns) if time_ns is not None else None
        await self._server.write_attribute_value(self.nodes[name].nodeid, ua.DataValue(
            variant(VARIABLE_BY_NAME[name], value), SourceTimestamp=stamp))

    async def set_status(self, text: str) -> None:
        if text != self.values["Status"]:
            await self._set("Status", text)

    def figures(self) -> dict[str, str]:
        """The diagnostics' key/values (read from any thread: plain ints and strings)."""
        return {"status": str(self.values["Status"]), "rejected_writes": str(self.rejected),
                "commands_sent": str(self.commands_sent), "samples_in": str(self.samples_in),
                "sample_counter": str(self.values["SampleCounter"]),
                "sim_restarts": str(self.restarts)}

    # -- following the simulator's settings -----------------------------------------------
    async def follow(self, settings: RigSettings) -> None:
        """The simulator's settings now: new EURanges, ``Lockstep`` and ``DriveMode``."""
        old, self.settings = self.settings, settings
        for name, node in self._ranges.items():
            if settings.eu_range(name) != old.eu_range(name):
                await self._server.write_attribute_value(node.nodeid, ua.DataValue(
                    _range_variant(settings.eu_range(name))))
        if settings.lockstep != self.values["Lockstep"]:
            await self._set("Lockstep", settings.lockstep)
        if settings.drive_mode != self.values["DriveMode"]:
            await self._set("DriveMode", settings.drive_mode)
            self._in_force = _unset_setpoints()        # the new mode's setpoint goes next
        if settings != old:
            _log.info("%s follows its sim_node: %s", self.name, settings)

    # -- client writes --------------------------------------------------------------------
    def check(self, name: str, item: ua.WriteValue) -> tuple[int | None, Any]:
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

    async def refuse(self, name: str, code: int, value: Any, why: str = "") -> None:
        """Count a refused write and fail its request with ``code`` (always raises)."""
        self.rejected += 1
        await self._set("RejectedWrites", self.rejected % UINT32_MODULUS)
        _log.warning("refused a write of %r to %s.%s: %s%s (%d refused so far)", value,
                     self.name, name, ua.StatusCode(code).name, f" ({why})" if why else "",
                     self.rejected)
        raise ua.UaStatusCodeError(code)

    async def switch_drive(self, writes: dict[str, Any]) -> None:
        """Switch the simulator's drive if ``writes`` changes DriveMode (refused: raises)."""
        mode = writes.get("DriveMode", self.values["DriveMode"])
        if mode == self.values["DriveMode"] or self._switch_mode is None:
            return
        try:
            reason = await asyncio.wait_for(self._switch_mode(mode),
                                            self.mode_switch_timeout_s)
        except (TimeoutError, OSError) as exc:
            await self.refuse("DriveMode", Bad.BadTimeout, mode, f"sim_node: {exc!r}")
        if reason is not None:
            await self.refuse("DriveMode", Bad.BadInvalidState, mode, f"sim_node: {reason}")
        self._in_force = _unset_setpoints()            # the new mode's setpoint goes next

    def accept(self, writes: dict[str, Any]) -> None:
        """Take a checked request's values (asyncua applies them to the nodes after this);
        a new CommandCounter sends the command."""
        counter = writes.get("CommandCounter")
        send = counter is not None and counter != self.values["CommandCounter"]
        self.values.update(writes)
        if send:
            self._command(self.values, counter)

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
        _log.debug("%s: command %d sent", self.name, counter)

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
        if counter is None:                          # the simulator started again
            return ua.StatusCode(Bad.BadInvalidState)
        return [ua.Variant(counter, ua.VariantType.UInt32)]

    def _answer_waiters(self, counter: int | None) -> None:
        for waiter in self._waiters:
            if not waiter.done():
                waiter.set_result(counter)
        self._waiters.clear()

    async def _start_over(self) -> None:
        """The simulator started again: no command is outstanding, none of its setpoints is
        known, and the client goes on from CommandCounter."""
        self.restarts += 1
        self.latest_ns, self.outstanding = None, False
        self._in_force = _unset_setpoints()
        self._answer_waiters(None)
        await self._set("SampleCounter", self.values["CommandCounter"])
        _log.warning("%s: sim_node started again (its time went back); the handshake goes "
                     "on from CommandCounter %d", self.name, self.values["CommandCounter"])

    async def sample_in(self, values: dict[str, float], time_ns: int) -> None:
        """A sample of sim_node (SAMPLE_VARIABLES' values, stamped ``time_ns``) into the
        variables; it answers the outstanding command, if any. The same stamp again is
        ignored; an older one means sim_node started again."""
        if self.latest_ns is not None and time_ns == self.latest_ns:
            return
        if self.latest_ns is not None and time_ns < self.latest_ns:
            await self._start_over()
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
            self._answer_waiters(self.values["SampleCounter"])


class RigServer:
    """The asyncua server of the rig objects ``rigs`` at ``endpoint`` (their names differ)."""

    def __init__(self, endpoint: str, rigs: Sequence[Rig],
                 security: Security | None = None) -> None:
        self.security = security
        self.server = Server(user_manager=None if security is None else PasswordUser(
            security.user, security.password))
        self.endpoint, self.rigs = endpoint, tuple(rigs)
        self._writable: dict[ua.NodeId, tuple[Rig, str]] = {}

    async def start(self) -> None:
        await self.server.init()
        self.server.set_endpoint(self.endpoint)
        names = ", ".join(rig.name for rig in self.rigs)
        self.server.set_server_name(f"drill_sim_ros OPC UA gateway ({names})")
        await self._secure()
        index = await self.server.register_namespace(NAMESPACE_URI)
        for rig in self.rigs:
            for nodeid, name in (await rig.build(self.server, index)).items():
                self._writable[nodeid] = (rig, name)
        self.server.subscribe_server_callback(CallbackType.PreWrite, self._pre_write)
        await self._listen()

    async def _listen(self) -> None:
        """Start listening; a port that cannot be bound (in use, not allowed) is one
        DrillSimError line. asyncua logs such a failure's traceback before it raises it, so
        its server logger is quiet for this one call."""
        quiet = logging.getLogger(ASYNCUA_SERVER_LOGGER)
        was_disabled, quiet.disabled = quiet.disabled, True
        try:
            await self.server.start()
        except OSError as exc:
            reason = exc.strerror or str(exc)
            raise DrillSimError(f"endpoint {self.endpoint}: cannot listen: {reason} (another "
                                "gateway or server on this port? choose another port with "
                                "-p endpoint:=...)") from None
        finally:
            quiet.disabled = was_disabled

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

    async def _pre_write(self, event: Any, _dispatcher: Any) -> None:
        """Check a whole write request (raise its Bad status code to refuse all of it), switch
        drive modes, then hand each rig its part."""
        writes: dict[Rig, dict[str, Any]] = {}
        for item in event.request_params.NodesToWrite:
            owner = self._writable.get(item.NodeId)
            if owner is None:
                continue
            rig, name = owner
            code, value = rig.check(name, item)
            if code is not None:
                await rig.refuse(name, code, value)
            writes.setdefault(rig, {})[name] = value
        for rig, values in writes.items():
            await rig.switch_drive(values)
        for rig, values in writes.items():
            rig.accept(values)
