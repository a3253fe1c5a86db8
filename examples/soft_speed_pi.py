"""A textbook SoftSpeed PI, written from the controller API of docs/closed-loop.md alone.

Kyllingstad & Nessjøen 2009 (SPE/IADC 119660) tune the top drive's PI speed loop as a damper
matched to the drill pipe: the proportional gain kp = Z, the pipe's torsional impedance, so
the top absorbs an arriving torsional wave; the integral gain ki = J omega_1^2, so the
integral's reactance ki / (j omega) cancels the drive inertia's j omega J at the string's
first mode omega_1, where the top then meets the string as the damper Z alone. A setpoint
cannot retune the drive's own loop, so this controller runs in torque mode: it closes that
PI loop itself on the operator's setpoint and sends the motor torque. Before the switch-on
the loop has the drive's delivered gains (the base class's).

    .venv/bin/drill_sim closed-loop --mode torque \
        --controller examples/soft_speed_pi.py:SoftSpeedPI
"""

from __future__ import annotations

from typing import Any, ClassVar

from drill_sim_ros.control.controllers import TopDriveController
from drill_sim_ros.model.errors import ParameterError


class SoftSpeedPI(TopDriveController):
    """Torque mode: a PI speed loop on the setpoint with kp = Z, ki = J omega_1^2."""

    name = "soft_speed_pi"
    PARAMS: ClassVar[dict[str, str]] = {
        **TopDriveController.PARAMS,
        "kp_nm_s": "proportional gain, N m s/rad (default Z)",
        "ki_nm": "integral gain, N m/rad (default J omega_1^2)",
    }

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        if self.mode != "torque":
            raise ParameterError("controller 'soft_speed_pi' closes its own speed loop: "
                                 "use --mode torque")

    def defaults(self) -> dict[str, float]:
        rig = self.rig
        return {**super().defaults(), "kp_nm_s": rig.impedance_nm_s,
                "ki_nm": rig.drive_inertia_kg_m2 * rig.first_mode_rad_s**2}

    def loop_gains(self) -> tuple[float, float]:
        return self.params["kp_nm_s"], self.params["ki_nm"]
