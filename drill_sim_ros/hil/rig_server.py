"""The gateway's OPC UA server (asyncua): one object per rig, each with the address space of
:mod:`.address_space` (nodes by :mod:`.nodes`), the checks of every client write, its own
lockstep handshake, one writer and a watchdog (ROS-free; the gateway node feeds it).

- A client's write request is checked whole before any of it is applied (asyncua's PreWrite
  callback): a read-only variable, a wrong type or an array, another session's write, NaN,
  ±inf, a value outside its EURange (a few ulps beyond a bound are the bound), a
  CommandCounter out of turn or a new setpoint with the counter already sent fails the request
  with the matching Bad status code (BadNotWritable, BadTypeMismatch, BadUserAccessDenied,
  BadOutOfRange, BadInvalidState), counted in that rig's ``RejectedWrites``; nothing of it
  reaches the simulator. A request may span several rigs.
- The first session that writes owns the rig's setpoints (:mod:`.sessions` tells sessions
  apart) until it closes or writes nothing for ``heartbeat_timeout_s``; in free run that
  starts the safe stop (the speed setpoint ramps to 0) and only ``Reset`` lets writes in again.
- A new ``DriveMode`` switches the simulator's drive (``switch_mode``) before anything else of
  the request is applied; a switch the simulator refuses fails the request with
  BadInvalidState, one it does not answer with BadTimeout (both counted).
- ``CommandCounter`` = ``SampleCounter`` + 1 (or a ``Step`` call) hands the setpoints to
  ``send`` as the next period's command, at once; when that period's sample is in the values
  (:meth:`Rig.sample_in`), ``SampleCounter`` takes the same value and ``Step`` returns it
  (BadTimeout after ``step_timeout_s``: the session's other requests wait behind it).
- The EURanges, ``Lockstep``, ``ControlPeriod`` and ``DriveMode`` follow the simulator's
  settings (:meth:`Rig.follow`); a sample older than the latest one (or sim_node's first one
  again, or a new sim_node, while a command was unanswered) means the simulator started again:
  the handshake starts over (``SampleCounter`` = ``CommandCounter``).
- ``Status`` (:class:`~.address_space.RigStatus`) and ``StatusText`` say what the rig does or
  waits for, updated at every write, sample and SUPERVISE_PERIOD_S.
"""

from __future__ import annotations

import asyncio
import importlib.metadata
import logging
import math
import time
import weakref
from collections.abc import Awaitable, Callable, Sequence
from dataclasses import dataclass
from datetime import datetime, timezone
from enum import IntEnum
from typing import Any

from asyncua import Server, ua
from asyncua.common.callback import CallbackType

from drill_sim_ros.control.command import Command
from drill_sim_ros.hil import sessions
from drill_sim_ros.hil.address_space import (
    ENUMERATIONS,
    METHOD_MEANINGS,
    NAMESPACE_URI,
    RESET_METHOD,
    SAMPLE_VARIABLES,
    STATUS_MEANINGS,
    STEP_METHOD,
    VARIABLE_BY_NAME,
    VARIABLES,
    DriveModeEnum,
    RigStatus,
    Variable,
    exact_setting,
    node_id,
    rad_s_of_rpm,
    within,
)
from drill_sim_ros.hil.nodes import (
    add_property,
    describe,
    enumeration,
    eu_information,
    range_variant,
    retype,
    sim_timestamp,
    subtree,
    variant,
)
from drill_sim_ros.hil.security import APPLICATION_URI, PasswordUser, Security
from drill_sim_ros.hil.sessions import SessionUsers
from drill_sim_ros.model.errors import DrillSimError
from drill_sim_ros.model.top_drive import limit_of_setting

_log = logging.getLogger(__name__)
UINT32_MODULUS = 2**32
Bad = ua.StatusCodes
SETPOINTS = ("SpeedSetpoint", "TorqueCommand", "WobSetpoint")
MODE_SWITCH_TIMEOUT_S = 5.0
SUPERVISE_PERIOD_S = 0.05
PRODUCT_NAME = "drill_sim_ros OPC UA gateway"
ASYNCUA_SERVER_LOGGER = "asyncua.server.server"   # logs a failed start's traceback
# switch_mode(mode), ``mode`` a DriveModeEnum name (sim_node's top_drive.mode): None once the
# simulator drives in ``mode``, else its reason for refusing (TimeoutError, or any OSError, if
# it does not answer)
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
    drive_mode: DriveModeEnum
    lockstep: bool
    control_period_s: float

    @classmethod
    def of_sim(cls, sim: dict[str, Any]) -> RigSettings:
        """The settings of sim_node's parameters (``SIM_PARAMETERS`` of
        :mod:`drill_sim_ros.ros.sim_link`), in SI without a unit round trip's last-digit drift
        (:func:`exact_setting`, :func:`rad_s_of_rpm`); sim_node's kinematic mode, which takes
        speed setpoints too, shows as ``DriveModeEnum.speed``."""
        torque_nm = limit_of_setting(sim["top_drive.max_torque_nm"])     # 0: no limit (inf)
        return cls(
            max_speed_rad_s=rad_s_of_rpm(sim["limits.max_surface_rpm"]),
            max_torque_nm=exact_setting(torque_nm),
            max_wob_n=exact_setting(sim["limits.max_wob_n"]),
            speed_rad_s=rad_s_of_rpm(sim["model.surface_rpm"]),
            wob_n=sim["model.applied_wob_n"],
            drive_mode=DriveModeEnum.torque if sim["top_drive.mode"] == "torque"
            else DriveModeEnum.speed,
            lockstep=bool(sim["lockstep"]) and sim["lockstep_trigger"] == "command",
            control_period_s=1.0 / sim["publish_rate_hz"])

    def eu_range(self, name: str) -> tuple[float, float] | None:
        return {"SpeedSetpoint": (0.0, self.max_speed_rad_s),
                "TorqueCommand": (-self.max_torque_nm, self.max_torque_nm),
                "WobSetpoint": (0.0, self.max_wob_n)}.get(name)

    def initial(self, name: str) -> Any:
        return {"SpeedSetpoint": self.speed_rad_s, "TorqueCommand": 0.0,
                "WobSetpoint": self.wob_n, "DriveMode": int(self.drive_mode),
                "Lockstep": self.lockstep, "Status": int(RigStatus.WaitingForSim),
                "StatusText": STATUS_MEANINGS[RigStatus.WaitingForSim],
                "ControlPeriod": self.control_period_s}.get(
                    name, math.nan if name in SAMPLE_NAMES else 0)


SAMPLE_NAMES = frozenset(v.name for v in SAMPLE_VARIABLES)


@dataclass(frozen=True)
class RigTiming:
    """A rig object's waits (wall time, s) and its safe stop's ramp."""

    step_timeout_s: float = 0.5          # Step's wait for its sample (the session waits too)
    mode_switch_timeout_s: float = MODE_SWITCH_TIMEOUT_S
    heartbeat_timeout_s: float = 2.0     # the owner's silence that ends its ownership
    sim_timeout_s: float = 2.0           # a command unanswered (no sample in free run): SimLost
    safe_ramp_rad_s2: float = 2.0        # the safe stop's speed ramp (rad/s per s, sim time)


def _unset_setpoints() -> dict[str, float]:
    """No setpoint known to be in force: the next command carries them all."""
    return dict.fromkeys(SETPOINTS, math.nan)


class Rig:
    """One rig object ``name``; ``send(command, stamp_ns)`` hands its simulator a command
    answering the sample stamped ``stamp_ns``, ``switch_mode`` switches its drive (both called
    in the event loop). Its nodes exist once :meth:`build` has run."""

    def __init__(self, name: str, settings: RigSettings, send: Callable[[Command, int], None],
                 switch_mode: SwitchMode | None = None, timing: RigTiming = RigTiming()) -> None:
        self.name, self.settings, self.timing = name, settings, timing
        self._send, self._switch_mode = send, switch_mode
        self.nodes: dict[str, Any] = {}
        self._ranges: dict[str, Any] = {}               # EURange property nodes by variable
        self._server: Server | None = None
        self._enumerations: dict[type[IntEnum], ua.NodeId] = {}
        self.nodes_of_object: Any = None                # the rig object, once built
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
        self._owner: weakref.ref[Any] | None = None
        self._owner_seen_s = 0.0                        # the owner's last write (monotonic)
        self._sent_s = 0.0                              # when the outstanding command went
        self._sample_s = 0.0                            # when the latest sample came
        self.sim_lost = False
        self.latched: tuple[RigStatus, str] | None = None   # HeartbeatLost, Faulted: Reset
        self._ramp: tuple[float, int] | None = None     # the safe stop's start (rad/s, ns)
        self._refused_kinds: dict[tuple[str, int], int] = {}

    # -- the address space ----------------------------------------------------------------
    async def build(self, server: Server, index: int,
                    enumerations: dict[type[IntEnum], ua.NodeId]) -> dict[ua.NodeId, str]:
        """Add the rig object under Objects (``Status`` and ``DriveMode`` of their enumeration
        DataTypes, ``enumerations``); its writable variables' names by NodeId."""
        self._server, self._enumerations = server, enumerations
        rig = await server.nodes.objects.add_object(ua.NodeId(self.name, index),
                                                    ua.QualifiedName(self.name, index))
        for variable in VARIABLES:
            await self._add_variable(rig, index, variable)
        await describe(rig, f"the rig {self.name}: a simulated drill string's surface, "
                        "its top drive's setpoints and the lockstep handshake (docs/hil.md)")
        step = await rig.add_method(
            ua.NodeId(node_id(self.name, STEP_METHOD), index),
            ua.QualifiedName(STEP_METHOD, index), self._step, [],
            [ua.Argument(Name="SampleCounter", DataType=ua.NodeId(ua.ObjectIds.UInt32),
                         ValueRank=-1, Description=ua.LocalizedText(
                             "the new SampleCounter: the command's sample is in the values"))])
        await describe(step, METHOD_MEANINGS[STEP_METHOD])
        reset = await rig.add_method(ua.NodeId(node_id(self.name, RESET_METHOD), index),
                                     ua.QualifiedName(RESET_METHOD, index), self._reset, [], [])
        await describe(reset, METHOD_MEANINGS[RESET_METHOD])
        self.nodes_of_object = rig
        return {node.nodeid: name for name, node in self.nodes.items()}

    async def _add_variable(self, rig: Any, index: int, variable: Variable) -> None:
        node = await rig.add_variable(ua.NodeId(node_id(self.name, variable.name), index),
                                      ua.QualifiedName(variable.name, index),
                                      variant(variable, self.values[variable.name]),
                                      datatype=self._enumerations.get(variable.enumeration))
        if variable.writable:
            await node.set_writable()
        await describe(node, variable.meaning)
        if variable.unit is not None:
            await add_property(node, "EngineeringUnits", ua.Variant(
                eu_information(variable), ua.VariantType.ExtensionObject),
                ua.ObjectIds.EUInformation)
        eu_range = self.settings.eu_range(variable.name)
        if eu_range is not None:
            self._ranges[variable.name] = await add_property(
                node, "EURange", range_variant(eu_range), ua.ObjectIds.Range)
        if variable.unit is not None:         # a setpoint: AnalogItemType, else AnalogUnitType
            await retype(node, ua.ObjectIds.AnalogItemType if eu_range is not None
                          else ua.ObjectIds.AnalogUnitType)
        self.nodes[variable.name] = node

    async def _set(self, name: str, value: Any, time_ns: int | None = None) -> None:
        """A value of the gateway's own (not a client write; no checks)."""
        self.values[name] = value
        stamp = sim_timestamp(time_ns) if time_ns is not None else None
        await self._server.write_attribute_value(self.nodes[name].nodeid, ua.DataValue(
            variant(VARIABLE_BY_NAME[name], value), SourceTimestamp=stamp,
            ServerTimestamp=datetime.now(timezone.utc)))

    def status(self, now_s: float) -> tuple[RigStatus, str]:
        """The Status now, and its text."""
        if self.latched is not None:
            return self.latched
        if self.latest_ns is None:
            return RigStatus.WaitingForSim, STATUS_MEANINGS[RigStatus.WaitingForSim]
        if self.sim_lost:
            what = ("a command unanswered" if self.outstanding else "no sample")
            return RigStatus.SimLost, (f"sim_node lost: {what} for "
                                       f"{now_s - max(self._sent_s, self._sample_s):.1f} s")
        if self.owner is None:
            return RigStatus.WaitingForClient, ("samples come; no session owns the setpoints "
                                                "(the first that writes will)")
        return RigStatus.Running, f"running: {getattr(self.owner, 'name', 'a session')} " \
            "owns the setpoints"

    async def show_status(self, now_s: float) -> None:
        status, text = self.status(now_s)
        if int(status) != self.values["Status"]:
            _log.info("%s: %s (%s)", self.name, status.name, text)
            await self._set("Status", int(status))
        if text != self.values["StatusText"]:
            await self._set("StatusText", text)

    def figures(self) -> dict[str, str]:
        """The diagnostics' key/values (read from any thread: plain ints and strings)."""
        return {"status": f"{RigStatus(self.values['Status']).name}: "
                          f"{self.values['StatusText']}", "rejected_writes": str(self.rejected),
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
                    range_variant(settings.eu_range(name))))
        if settings.lockstep != self.values["Lockstep"]:
            await self._set("Lockstep", settings.lockstep)
            if settings.lockstep:
                self._end_ramp("sim_node went to lockstep")
        if settings.control_period_s != self.values["ControlPeriod"]:
            await self._set("ControlPeriod", settings.control_period_s)
        if settings.drive_mode != self.values["DriveMode"]:
            await self._set("DriveMode", int(settings.drive_mode))
            self._in_force = _unset_setpoints()        # the new mode's setpoint goes next
        if settings != old:
            _log.info("%s follows its sim_node: %s", self.name, settings)

    # -- client writes --------------------------------------------------------------------
    def check(self, name: str, item: ua.WriteValue, user: Any = None
              ) -> tuple[int | None, Any]:
        """(None, value) if ``user``'s session may write ``item`` to ``name``, else (Bad code,
        value); a value within a few ulps of an EURange bound is that bound."""
        variable = VARIABLE_BY_NAME[name]
        data = item.Value.Value
        value = data.Value if data is not None else None
        if item.AttributeId != ua.AttributeIds.Value or not variable.writable:
            return Bad.BadNotWritable, value
        if (data is None or data.is_array or data.Dimensions
                or data.VariantType != getattr(ua.VariantType, variable.type_name)):
            return Bad.BadTypeMismatch, value
        if not self._may_write(user):
            return Bad.BadUserAccessDenied, value
        if self.latched is not None:
            return Bad.BadInvalidState, value
        if name == "Heartbeat":
            return None, value
        if variable.enumeration is not None:
            known = value in {member.value for member in variable.enumeration}
            return (None if known else Bad.BadOutOfRange), value
        if name == "CommandCounter":
            return self._check_counter(value), value
        inside = within(value, *self.settings.eu_range(name))
        return (None, inside) if inside is not None else (Bad.BadOutOfRange, value)

    # -- one writer ------------------------------------------------------------------------
    @property
    def owner(self) -> Any:
        """The session (its User object) that owns the setpoints, or None."""
        return None if self._owner is None else self._owner()

    def _may_write(self, user: Any) -> bool:
        owner = self.owner
        return owner is None or owner is user

    def _claim(self, user: Any) -> None:
        """The first session that writes owns the setpoints (until it closes or goes
        silent); each of its writes is a heartbeat."""
        if self.owner is None and user is not None:
            self._owner = weakref.ref(user)
            _log.info("%s: the setpoints are %s's", self.name, getattr(user, "name", user))
        self._owner_seen_s = time.monotonic()

    def check_request(self, writes: dict[str, Any]) -> tuple[int, str] | None:
        """(Bad code, why) if a request's values, each allowed, are not as a whole: a new
        setpoint with the CommandCounter already sent is stale."""
        if writes.get("CommandCounter", -1) != self.values["CommandCounter"]:
            return None
        changed = [n for n in (*SETPOINTS, "DriveMode") if n in writes
                   and writes[n] != self.values[n]]
        if changed:
            return Bad.BadInvalidState, (f"stale: {', '.join(changed)} with CommandCounter "
                                         f"{writes['CommandCounter']}, already sent")
        return None

    def _check_counter(self, counter: int) -> int | None:
        if counter == self.values["CommandCounter"]:
            return None                                # unchanged: nothing to send
        turn = (self.values["SampleCounter"] + 1) % UINT32_MODULUS
        if self.latest_ns is None or self.outstanding or counter != turn:
            return Bad.BadInvalidState
        return None

    async def count_refusal(self, name: str, code: int, value: Any, why: str = "") -> None:
        """Count a refused write or call; log it at WARNING the first time of its kind
        (variable and code), at DEBUG after."""
        self.rejected += 1
        await self._set("RejectedWrites", self.rejected % UINT32_MODULUS)
        kind = (name, code)
        self._refused_kinds[kind] = self._refused_kinds.get(kind, 0) + 1
        level = logging.WARNING if self._refused_kinds[kind] == 1 else logging.DEBUG
        _log.log(level, "refused %r to %s.%s: %s%s (%d refused so far; further %s of %s are "
                 "logged at DEBUG)", value, self.name, name, ua.StatusCode(code).name,
                 f" ({why})" if why else "", self.rejected, ua.StatusCode(code).name, name)

    async def refuse(self, name: str, code: int, value: Any, why: str = "") -> None:
        """Count a refused write and fail its request with ``code`` (always raises)."""
        await self.count_refusal(name, code, value, why)
        raise ua.UaStatusCodeError(code)

    async def switch_drive(self, writes: dict[str, Any]) -> None:
        """Switch the simulator's drive if ``writes`` changes DriveMode (refused: raises)."""
        mode = writes.get("DriveMode", self.values["DriveMode"])
        if mode == self.values["DriveMode"] or self._switch_mode is None:
            return
        try:
            reason = await asyncio.wait_for(self._switch_mode(DriveModeEnum(mode).name),
                                            self.timing.mode_switch_timeout_s)
        except (TimeoutError, OSError) as exc:
            await self.refuse("DriveMode", Bad.BadTimeout, mode, f"sim_node: {exc!r}")
        if reason is not None:
            await self.refuse("DriveMode", Bad.BadInvalidState, mode, f"sim_node: {reason}")
        self._in_force = _unset_setpoints()            # the new mode's setpoint goes next

    def accept(self, writes: dict[str, Any], user: Any = None) -> None:
        """Take a checked request's values (asyncua applies them to the nodes after this);
        a new CommandCounter sends the command. The writer owns the setpoints from now."""
        self._claim(user)
        counter = writes.get("CommandCounter")
        send = counter is not None and counter != self.values["CommandCounter"]
        self.values.update(writes)
        if send:
            self._command(self.values, counter)

    # -- the handshake --------------------------------------------------------------------
    def _command(self, values: dict[str, Any], counter: int) -> None:
        """Send the setpoints of ``values`` as the command counted ``counter``: the drive
        mode's setpoint and the WOB, each only if it differs from the one in force."""
        chosen = ("SpeedSetpoint" if values["DriveMode"] == DriveModeEnum.speed
                  else "TorqueCommand")
        changed = {name: values[name] for name in (chosen, "WobSetpoint")
                   if values[name] != self._in_force[name]}
        self._in_force.update(changed)
        self.outstanding = True
        self._sent_s = time.monotonic()
        self.commands_sent += 1
        self._send(Command(speed_rad_s=changed.get("SpeedSetpoint"),
                           motor_torque_nm=changed.get("TorqueCommand"),
                           wob_n=changed.get("WobSetpoint")), self.latest_ns)
        _log.debug("%s: command %d sent", self.name, counter)

    async def _caller_refused(self, method: str) -> ua.StatusCode | None:
        """The Bad code for a method call by a session that may not write (counted)."""
        user = sessions.current()
        code = None
        if not self._may_write(user) or (user is None and self.owner is not None):
            code = Bad.BadUserAccessDenied
        elif self.latched is not None and method != RESET_METHOD:
            code = Bad.BadInvalidState
        if code is None:
            return None
        await self.count_refusal(f"{method}()", code, None, self.values["StatusText"])
        return ua.StatusCode(code)

    async def _step(self, _parent: ua.NodeId) -> Any:
        """The method Step: CommandCounter + 1 by a call; the new SampleCounter, or BadTimeout
        after ``step_timeout_s`` (the command stays outstanding, its sample comes later)."""
        refused = await self._caller_refused(STEP_METHOD)
        if refused is not None:
            return refused
        if self.latest_ns is None or self.outstanding:
            return ua.StatusCode(Bad.BadInvalidState)
        self._claim(sessions.current())
        turn = (self.values["SampleCounter"] + 1) % UINT32_MODULUS
        waiter = asyncio.get_running_loop().create_future()
        self._waiters.append(waiter)
        self._command(self.values, turn)
        await self._set("CommandCounter", turn)
        try:
            counter = await asyncio.wait_for(waiter, self.timing.step_timeout_s)
        except TimeoutError:
            return ua.StatusCode(Bad.BadTimeout)
        if counter is None:                          # the simulator started again
            return ua.StatusCode(Bad.BadInvalidState)
        return [ua.Variant(counter, ua.VariantType.UInt32)]

    async def _reset(self, _parent: ua.NodeId) -> Any:
        """The method Reset: after HeartbeatLost (the drive at rest) or Faulted, the rig takes
        writes again; the first session that writes owns the setpoints."""
        refused = await self._caller_refused(RESET_METHOD)
        if refused is not None:
            return refused
        if self._ramp is not None:
            await self.count_refusal(f"{RESET_METHOD}()", Bad.BadInvalidState, None,
                                     "the drive is still stopping")
            return ua.StatusCode(Bad.BadInvalidState)
        if self.latched is not None:
            _log.warning("%s: Reset after %s", self.name, self.latched[0].name)
        self.latched, self._owner = None, None
        await self.show_status(time.monotonic())
        return []

    def _answer_waiters(self, counter: int | None) -> None:
        for waiter in self._waiters:
            if not waiter.done():
                waiter.set_result(counter)
        self._waiters.clear()

    async def _start_over(self, why: str) -> None:
        """The simulator started again: no command is outstanding, none of its setpoints is
        known, and the client goes on from CommandCounter (SampleCounter takes its value)."""
        self.restarts += 1
        self.latest_ns, self.outstanding = None, False
        self._end_ramp("sim_node started again")
        self._in_force = _unset_setpoints()
        self._answer_waiters(None)
        await self._set("SampleCounter", self.values["CommandCounter"])
        _log.warning("%s: sim_node started again (%s); the handshake goes on from "
                     "CommandCounter %d", self.name, why, self.values["CommandCounter"])

    async def sim_replaced(self) -> None:
        """Another sim_node publishes the samples (it started again, whatever its time): none
        of its setpoints is known, and a command the lost one left unanswered is given up
        (start over). The graph can tell this after the new sim_node's first samples: a
        command sent since (sim_node not lost) stands."""
        self._in_force = _unset_setpoints()
        if self.outstanding and self.sim_lost:
            await self._start_over("a new sim_node publishes the samples")

    async def sample_in(self, values: dict[str, float], time_ns: int) -> None:
        """A sample of sim_node (SAMPLE_VARIABLES' values, stamped ``time_ns``) into the
        variables; it answers the outstanding command, if any. An older stamp means sim_node
        started again, and so does the same stamp again while sim_node was lost (a sim_node
        restarted before it left that time); the same stamp otherwise is ignored."""
        if self.latest_ns is not None and time_ns < self.latest_ns:
            await self._start_over("its time went back")
        elif self.latest_ns is not None and time_ns == self.latest_ns:
            if not (self.sim_lost and self.outstanding):
                return
            await self._start_over("its first sample again while a command was unanswered")
        self.latest_ns = time_ns
        self._sample_s, self.sim_lost = time.monotonic(), False
        self.samples_in += 1
        for name, value in values.items():
            await self._set(name, value, time_ns)
        if self.outstanding:
            self.outstanding = False
            await self._set("SampleCounter", self.values["CommandCounter"], time_ns)
            self._answer_waiters(self.values["SampleCounter"])
        if self._ramp is not None and not self.settings.lockstep:
            await self._ramp_down(time_ns)
        await self.show_status(self._sample_s)

    # -- supervision: the owner's heartbeat, sim_node's answers ---------------------------
    async def supervise(self, now_s: float) -> None:
        """Called every SUPERVISE_PERIOD_S: a closed or silent owner, a lost sim_node."""
        if self._owner is not None:
            closed = self.owner is None
            if closed or now_s - self._owner_seen_s > self.timing.heartbeat_timeout_s:
                await self._owner_lost("its session closed" if closed else
                                       f"it wrote nothing for {now_s - self._owner_seen_s:.1f} "
                                       "s")
        waited_s = now_s - (self._sent_s if self.outstanding else self._sample_s)
        self.sim_lost = self.latest_ns is not None and waited_s > self.timing.sim_timeout_s \
            and (self.outstanding or not self.settings.lockstep)
        await self.show_status(now_s)

    async def _owner_lost(self, why: str) -> None:
        """The owner's heartbeat lapsed: in lockstep nothing moves without it (its ownership
        ends); in free run the drive stops safely, and only Reset lets writes in again."""
        self._owner = None
        if self.settings.lockstep or self.latched is not None:
            _log.info("%s: the owner of the setpoints is gone (%s)", self.name, why)
            return
        self.latched = (RigStatus.HeartbeatLost, f"heartbeat lost ({why}): the speed setpoint "
                        f"ramps to 0 at {self.timing.safe_ramp_rad_s2:g} rad/s^2; Reset to go on")
        _log.warning("%s: %s", self.name, self.latched[1])
        await self._safe_stop()

    async def _safe_stop(self) -> None:
        """Start the ramp to zero speed, from the setpoint in force (speed mode) or from the
        measured speed once sim_node has switched to speed mode (torque mode)."""
        start = self.values["SpeedSetpoint"]
        if self.values["DriveMode"] != DriveModeEnum.speed:
            try:
                await self.switch_drive({"DriveMode": int(DriveModeEnum.speed)})
            except ua.UaStatusCodeError as exc:
                self.latched = (RigStatus.Faulted, "heartbeat lost, and sim_node did not switch "
                                f"to speed mode for the safe stop ({exc}); Reset to go on")
                _log.error("%s: %s", self.name, self.latched[1])
                return
            await self._set("DriveMode", int(DriveModeEnum.speed))
            start = self.values["DriveSpeed"]
        self._ramp = (max(0.0, min(start, self.settings.max_speed_rad_s)), self.latest_ns)

    def _end_ramp(self, why: str) -> None:
        """No more of the safe stop's ramp: sim_node started again, or runs in lockstep, where
        nothing moves without a command. Status stays HeartbeatLost until Reset."""
        if self._ramp is None:
            return
        self._ramp = None
        self.latched = (RigStatus.HeartbeatLost, f"{self.latched[1].split(':')[0]}: the safe "
                        f"stop ended ({why}); Reset to go on")
        _log.warning("%s: %s", self.name, self.latched[1])

    async def _ramp_down(self, time_ns: int) -> None:
        """The safe stop's speed setpoint at the sample stamped ``time_ns`` (free run): the
        ramp from its start, sent with that sample."""
        start_rad_s, start_ns = self._ramp
        speed = max(0.0, start_rad_s - self.timing.safe_ramp_rad_s2 * (time_ns - start_ns) / 1e9)
        self._ramp = None if speed == 0.0 else self._ramp
        self._in_force["SpeedSetpoint"] = speed
        self.commands_sent += 1
        self._send(Command(speed_rad_s=speed), self.latest_ns)
        await self._set("SpeedSetpoint", speed)
        if speed == 0.0:
            self.latched = (RigStatus.HeartbeatLost, self.latched[1].split(":")[0]
                            + ": the drive is at rest (speed setpoint 0); Reset to go on")
            _log.warning("%s: %s", self.name, self.latched[1])


def _version() -> str:
    try:
        return importlib.metadata.version("drill_sim_ros")
    except importlib.metadata.PackageNotFoundError:
        return "unknown"


class _FaultsAreClientErrors(logging.Filter):
    """asyncua logs every service fault it sends (a refused write too) at ERROR; the gateway
    logs its refusals itself, so these are INFO."""

    def filter(self, record: logging.LogRecord) -> bool:
        if record.msg.startswith("sending service fault response"):
            record.levelno, record.levelname = logging.INFO, "INFO"
        return True


FAULT_FILTER = _FaultsAreClientErrors()


class RigServer:
    """The asyncua server of the rig objects ``rigs`` at ``endpoint`` (their names differ)."""

    def __init__(self, endpoint: str, rigs: Sequence[Rig],
                 security: Security | None = None) -> None:
        self.security = security
        self.server = Server(user_manager=SessionUsers(None if security is None else PasswordUser(
            security.user, security.password)))
        self.endpoint, self.rigs = endpoint, tuple(rigs)
        self._writable: dict[ua.NodeId, tuple[Rig, str]] = {}
        self._supervisor: asyncio.Task[None] | None = None
        self.enumerations: dict[type[IntEnum], ua.NodeId] = {}

    async def start(self) -> None:
        await self.build()
        self.server.subscribe_server_callback(CallbackType.PreWrite, self._pre_write)
        self.server.subscribe_server_callback(CallbackType.PreRead, self._pre_read)
        await self._listen()
        self._supervisor = asyncio.create_task(self._supervise())

    async def build(self) -> None:
        """The address space, without listening (what :meth:`start` serves)."""
        logging.getLogger("asyncua.server.uaprocessor").addFilter(FAULT_FILTER)
        await self.server.init()
        self.server.set_endpoint(self.endpoint)
        await self._name_the_product()
        self.server.set_force_server_timestamp(True)
        await self._secure()
        index = await self.server.register_namespace(NAMESPACE_URI)
        self.enumerations = {members: await enumeration(self.server, index, members)
                             for members in ENUMERATIONS}
        for rig in self.rigs:
            for nodeid, name in (await rig.build(self.server, index, self.enumerations)).items():
                self._writable[nodeid] = (rig, name)

    async def export_nodeset(self, path: str) -> None:
        """The rigs' address space (namespace :data:`NAMESPACE_URI`: the enumeration DataTypes,
        the rig objects, their variables, properties and methods) as a NodeSet2 XML file."""
        nodes = []
        for data_type in self.enumerations.values():
            nodes += await subtree(self.server.get_node(data_type))
        for rig in self.rigs:
            nodes += await subtree(rig.nodes_of_object)
        await self.server.export_xml(nodes, path, export_values=True)

    async def _supervise(self) -> None:
        while True:
            await asyncio.sleep(SUPERVISE_PERIOD_S)
            for rig in self.rigs:
                try:
                    await rig.supervise(time.monotonic())
                except Exception:       # one rig's bug must not stop the others' watchdog
                    _log.exception("%s: supervision failed", rig.name)

    async def _name_the_product(self) -> None:
        """The product's own ApplicationUri (the certificate's), names and build info."""
        names = ", ".join(rig.name for rig in self.rigs)
        self.server.set_server_name(f"{PRODUCT_NAME} ({names})")
        await self.server.set_application_uri(APPLICATION_URI)
        self.server.product_uri = NAMESPACE_URI
        await self.server.set_build_info(NAMESPACE_URI, "drill_sim_ros", PRODUCT_NAME,
                                         _version(), _version(), datetime.now(timezone.utc))

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
        self.server.set_security_policy([ua.SecurityPolicyType.Basic256Sha256_SignAndEncrypt])
        self.server.set_identity_tokens([ua.UserNameIdentityToken])
        await self.server.load_certificate(str(self.security.certificate))
        await self.server.load_private_key(str(self.security.private_key))

    async def stop(self) -> None:
        if self._supervisor is not None:
            self._supervisor.cancel()
        await self.server.stop()

    async def _pre_write(self, event: Any, _dispatcher: Any) -> None:
        """Check a whole write request (raise its Bad status code to refuse all of it), switch
        drive modes, then hand each rig its part."""
        sessions.note(event.user)
        writes: dict[Rig, dict[str, Any]] = {}
        for item in event.request_params.NodesToWrite:
            owner = self._writable.get(item.NodeId)
            if owner is None:
                continue
            rig, name = owner
            code, value = rig.check(name, item, event.user)
            if code is not None:
                await rig.refuse(name, code, value)
            if value != item.Value.Value.Value:               # a bound, a few ulps away
                item.Value.Value = ua.Variant(value, item.Value.Value.VariantType)
            writes.setdefault(rig, {})[name] = value
        for rig, values in writes.items():
            refused = rig.check_request(values)
            if refused is not None:
                await rig.refuse("CommandCounter", refused[0], values["CommandCounter"],
                                 refused[1])
        for rig, values in writes.items():
            await rig.switch_drive(values)
        for rig, values in writes.items():
            rig.accept(values, event.user)
            await rig.show_status(time.monotonic())

    async def _pre_read(self, event: Any, _dispatcher: Any) -> None:
        sessions.note(event.user)
