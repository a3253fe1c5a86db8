"""The law of examples/lockstep_controller.py as a bench controller (``module:Class`` for
:func:`drill_sim_ros.control.bench.run_in_process`): the example file itself is loaded, so
the bench runs the very function the example node runs."""

from __future__ import annotations

import importlib.util
from pathlib import Path
from types import ModuleType

from drill_sim_ros.control.command import Command, SurfaceMeasurement

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "lockstep_controller.py"


def example_module() -> ModuleType:
    spec = importlib.util.spec_from_file_location("lockstep_controller_example", EXAMPLE)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


class ExampleLaw:
    """Stateless: the command answering a measurement is the example's setpoint of it."""

    def __init__(self, **_: object) -> None:
        self._setpoint_rad_s = example_module().speed_setpoint_rad_s

    def reset(self) -> None:
        pass

    def update(self, m: SurfaceMeasurement | None) -> Command:
        if m is None:
            raise ValueError("the example answers samples only; it has no command before one")
        return Command(speed_rad_s=self._setpoint_rad_s(m.string_torque_nm))
