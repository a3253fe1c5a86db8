"""A user's controller for the bench (the example of docs/closed-loop.md): ``module:Class``."""

from __future__ import annotations

from drill_sim_ros.control.command import Command, SurfaceMeasurement
from drill_sim_ros.control.controllers import LowPass, TopDriveController
from drill_sim_ros.model.params import RPM_PER_RAD_S


class TorqueDamper(TopDriveController):
    """omega_ref = omega_0 - gain * (T_sub - <T_sub>): a torque damper with one gain."""

    name = "torque_damper"

    def defaults(self) -> dict[str, float]:
        return {**super().defaults(), "gain_rad_s_per_knm": 2.0}

    def reset(self) -> None:
        super().reset()
        self.mean = LowPass(0.25, self.period_s)

    def reference_rad_s(self, m: SurfaceMeasurement, nominal_rad_s: float) -> float:
        excess_knm = (m.string_torque_nm - self.mean.update(m.string_torque_nm)) / 1e3
        return nominal_rad_s - self.params["gain_rad_s_per_knm"] * excess_knm


class ConstantSpeed:
    """The bare protocol, no base class: reset() and update(measurement) -> Command."""

    def __init__(self, rpm: float = 75.0, **_: object) -> None:
        self.rpm = rpm

    def reset(self) -> None:
        pass

    def update(self, m: SurfaceMeasurement | None) -> Command:
        return Command(speed_rad_s=self.rpm / RPM_PER_RAD_S)
