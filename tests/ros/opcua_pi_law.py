"""A PI law on the quill torque, written twice over one pure function: as a bench controller
(``module:Class`` for :func:`drill_sim_ros.control.bench.run_in_process`) and for a plain
asyncua client (tests/ros/test_opcua_gateway.py), which uses only :func:`pi_step`.

The speed setpoint drops as the string torque rises above its nominal: proportional plus
integral action, one control period per call, the same float operations in both uses.
"""

from __future__ import annotations

from drill_sim_ros.control.command import Command, SurfaceMeasurement

SETPOINT_RAD_S = 6.0              # about 57 rev/min
NOMINAL_TORQUE_NM = 3400.0
KP_RAD_S_PER_NM = 4e-4
KI_RAD_S2_PER_NM = 2e-4
PERIOD_S = 0.01


def pi_step(integral_nm_s: float, string_torque_nm: float) -> tuple[float, float]:
    """(speed setpoint rad/s, new integral N m s) answering one torque sample."""
    error_nm = string_torque_nm - NOMINAL_TORQUE_NM
    integral_nm_s = integral_nm_s + error_nm * PERIOD_S
    speed = SETPOINT_RAD_S - KP_RAD_S_PER_NM * error_nm - KI_RAD_S2_PER_NM * integral_nm_s
    return min(max(speed, 0.0), 20.0), integral_nm_s


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
