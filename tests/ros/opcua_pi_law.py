"""The PI law of examples/opcua_controller.py as a bench controller (``module:Class`` for
:func:`drill_sim_ros.control.bench.run_in_process`): the example file itself is loaded, so the
bench and tests/ros/test_opcua_gateway.py's asyncua client run the very function
(:func:`pi_step`) the example runs, with the same float operations."""

from __future__ import annotations

import importlib.util
from pathlib import Path

from drill_sim_ros.control.command import Command, SurfaceMeasurement

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "opcua_controller.py"
_spec = importlib.util.spec_from_file_location("opcua_controller_example", EXAMPLE)
_example = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(_example)
pi_step = _example.pi_step


class PiLaw:
    """The bench side: the state is the integral."""

    def __init__(self, **_: object) -> None:
        self._integral_nm_s = 0.0

    def reset(self) -> None:
        self._integral_nm_s = 0.0

    def update(self, m: SurfaceMeasurement | None) -> Command:
        if m is None:
            raise ValueError("the PI law answers samples only")
        speed, self._integral_nm_s = pi_step(self._integral_nm_s, m.string_torque_nm)
        return Command(speed_rad_s=speed)
