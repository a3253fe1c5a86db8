"""A controller under test, isolated: what it raises or returns wrong is one line.

ROS-free; used by the in-process bench, the controlled maps and the ``top_drive_controller``
node alike. :func:`build_isolated` builds a controller (an exception in its constructor is a
:class:`ControllerError`); :class:`IsolatedController` calls its ``update`` and checks the
answer: an exception, anything but a :class:`~drill_sim_ros.control.command.Command`, or a
command value that is not a finite number is a :class:`ControllerError` naming the
controller, the simulated time and the value. A finite value out of range is NOT an error:
the sim clamps it (``control.command.apply_command``). The first step slower than
:data:`SLOW_STEP_S` of wall time logs one warning with its time per step.
"""

from __future__ import annotations

import logging
import math
import numbers
import time
from collections.abc import Callable
from typing import Any

from drill_sim_ros.control.command import Command, SurfaceMeasurement
from drill_sim_ros.model.errors import DrillSimError

_log = logging.getLogger(__name__)

SLOW_STEP_S = 0.1
COMMAND_FIELDS = ("speed_rad_s", "motor_torque_nm", "wob_n")


def _plainly_valid(value: Any) -> bool:
    """None or a finite float: a valid command field, told without the ABC checks."""
    return value is None or (type(value) is float and math.isfinite(value))


class ControllerError(DrillSimError):
    """The controller under test failed; the message is one line (controller, time, value)."""


def _short(value: Any, limit: int = 80) -> str:
    text = " ".join(repr(value).split())
    return text if len(text) <= limit else text[:limit - 3] + "..."


def _why(exc: BaseException) -> str:
    text = " ".join(str(exc).split())
    text = text if len(text) <= 160 else text[:157] + "..."
    return f"{type(exc).__name__}: {text}" if text else type(exc).__name__


def build_isolated(name: str, factory: Callable[[], Any], period_s: float) -> IsolatedController:
    """``factory()`` (which builds controller ``name``) wrapped; its failure one line."""
    try:
        controller = factory()
    except DrillSimError:
        raise
    except Exception as exc:  # (the user's code: any failure is reported)
        raise ControllerError(f"controller {name!r} cannot be built: {_why(exc)}") from None
    return IsolatedController(name, controller, period_s)


class IsolatedController:
    """``update(measurement) -> Command`` of ``controller``, checked (see the module doc)."""

    def __init__(self, name: str, controller: Any, period_s: float) -> None:
        self.name = name
        self.controller = controller
        self.period_s = period_s
        self.slow_warned = False

    def __getattr__(self, attribute: str) -> Any:      # params, clamped_commands, ...
        return getattr(self.controller, attribute)

    def reset(self) -> None:
        self._call(self.controller.reset, None, "reset()")

    def update(self, measurement: SurfaceMeasurement | None) -> Command:
        start = time.perf_counter()
        command = self._call(self.controller.update, measurement, "update()")
        seconds = time.perf_counter() - start
        time_s = 0.0 if measurement is None else measurement.time_s
        if seconds > SLOW_STEP_S and not self.slow_warned:
            self.slow_warned = True
            _log.warning("warning: controller %r is slow: its step at t = %.3f s took %.3g s "
                         "of wall time (%.0f x the %g ms control period)", self.name, time_s,
                         seconds, seconds / self.period_s, self.period_s * 1e3)
        return self._checked(command, time_s)

    def _call(self, method: Callable[..., Any], measurement: Any, what: str) -> Any:
        try:
            return method(measurement) if what == "update()" else method()
        except DrillSimError:
            raise
        except Exception as exc:  # (the user's code: any failure is reported)
            time_s = 0.0 if measurement is None else measurement.time_s
            raise ControllerError(f"controller {self.name!r} {what} raised at t = "
                                  f"{time_s:.3f} s: {_why(exc)}") from None

    def _checked(self, command: Any, time_s: float) -> Command:
        if type(command) is Command and all(map(_plainly_valid, (
                command.speed_rad_s, command.motor_torque_nm, command.wob_n))):
            return command             # the common case, without the ABC checks below
        where = f"controller {self.name!r} at t = {time_s:.3f} s"
        if not isinstance(command, Command):
            raise ControllerError(f"{where} returned {_short(command)} "
                                  f"({type(command).__name__}); update() must return a "
                                  "Command")
        for field in COMMAND_FIELDS:
            value = getattr(command, field)
            if value is None:
                continue
            if isinstance(value, bool) or not isinstance(value, numbers.Real):
                raise ControllerError(f"{where} commanded {field} = {_short(value)}; a "
                                      "command is a number or None")
            if not math.isfinite(value):
                raise ControllerError(f"{where} commanded {field} = {value!r}; commands "
                                      "must be finite (finite values out of range are "
                                      "clamped)")
        return command
