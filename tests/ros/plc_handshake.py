"""The Python mirror of the Structured Text function block ``FB_RigHandshake`` of docs/hil.md
(issue 53), statement for statement: one call of :meth:`RigHandshake.cycle` is one scan of
the PLC task. Its inputs are what the task read this scan (one read list) and what its
write-list instruction reported; its outputs say whether to start the write list this scan.
:class:`RigStatus` and :class:`DriveModeEnum` are the block's ENUM TYPEs, written out as a
PLC project has them (not taken from the gateway's code). Keep the two in step:
tests/ros/test_opcua_commissioning.py closes the loop with it against the real gateway.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import IntEnum

# States (the ST block's constants)
IDLE, WRITING, WAITING, DONE, FAILED = 0, 10, 20, 30, 90
# ErrorID (WORD)
WRITE_REFUSED = 0x8001     # the write list came back Bad (RejectedWrites counts it)
SAMPLE_TIMEOUT = 0x8002    # SampleCounter did not reach CommandCounter in TimeoutCycles
RIG_NOT_READY = 0x8003     # Status is WaitingForSim, HeartbeatLost, SimLost or Faulted
UDINT_MODULUS = 2**32


class RigStatus(IntEnum):
    """TYPE RigStatus (DINT): the values of the gateway's RigStatus EnumStrings."""

    WaitingForSim = 0
    Running = 1
    WaitingForClient = 2
    HeartbeatLost = 3
    SimLost = 4
    Faulted = 5


class DriveModeEnum(IntEnum):
    """TYPE DriveModeEnum (DINT): what the write list's DriveMode carries."""

    speed = 0
    torque = 1


READY = (RigStatus.Running, RigStatus.WaitingForClient)


@dataclass
class RigHandshake:
    """FB_RigHandshake: VAR_INPUT, VAR_OUTPUT and VAR as attributes."""

    # VAR_INPUT
    execute: bool = False              # rising edge: send the setpoints with the next count
    sample_counter: int = 0            # Rig.SampleCounter, read this scan
    status: RigStatus = RigStatus.WaitingForSim    # Rig.Status, read this scan
    write_done: bool = False           # the write list's Done, this scan
    write_error: bool = False          # the write list's Error, this scan
    timeout_cycles: int = 100
    # VAR_OUTPUT
    do_write: bool = False             # start the write list (DriveMode, setpoints, counter)
    command_counter: int = 0
    done: bool = False
    busy: bool = False
    error: bool = False
    error_id: int = 0
    # VAR
    state: int = IDLE
    cycles: int = 0
    execute_before: bool = False

    def cycle(self) -> None:
        """One scan (the ST block's body, CASE for CASE)."""
        rising = self.execute and not self.execute_before
        self.execute_before = self.execute
        self.do_write = False
        if self.state in (IDLE, DONE, FAILED):
            if rising:
                if self.status not in READY:
                    self._fail(RIG_NOT_READY)
                else:
                    self.command_counter = (self.sample_counter + 1) % UDINT_MODULUS
                    self.do_write, self.cycles = True, 0
                    self.state, self.busy, self.done, self.error = WRITING, True, False, False
        elif self.state == WRITING:
            self.cycles += 1
            if self.write_error:
                self._fail(WRITE_REFUSED)
            elif self.write_done:
                self.state = WAITING
            elif self.cycles >= self.timeout_cycles:
                self._fail(SAMPLE_TIMEOUT)
        elif self.state == WAITING:
            self.cycles += 1
            if self.sample_counter == self.command_counter:
                self.state, self.busy, self.done = DONE, False, True
            elif self.status not in READY:
                self._fail(RIG_NOT_READY)
            elif self.cycles >= self.timeout_cycles:
                self._fail(SAMPLE_TIMEOUT)

    def _fail(self, error_id: int) -> None:
        self.state, self.busy, self.done = FAILED, False, False
        self.error, self.error_id = True, error_id
