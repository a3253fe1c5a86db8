"""The closed loop over real DDS (issue 12): sim_node and top_drive_controller as processes,
the same telemetry as the in-process bench, bit for bit; the controller node reads only the
rig's surface measurements."""

from __future__ import annotations

import numpy as np
import pytest

from drill_sim_ros import topics
from drill_sim_ros.control.bench import run_in_process
from drill_sim_ros.control.scenario import Scenario
from drill_sim_ros.ros.closed_loop import run_over_dds
from drill_sim_ros.ros.controller_node import ControllerNode
from tests.ros.harness import overrides, ros_context

pytestmark = pytest.mark.ros
SENSORS = {
    "seed": 7,
    "string_torque_nm": {"noise_std": 25.0, "quantum": 1.0},
    "drive_speed_rad_s": {"noise_std": 1e-3, "delay_periods": 2},
    "motor_torque_nm": {"noise_std": 40.0},
}


# the drive's limits and a command delay within a period, as sim_node parameters
DRIVE = {
    "accel_rpm_s": 20.0,
    "wob_rate_n_s": 3000.0,
    "max_torque_nm": 20e3,
    "command_delay_s": 0.0042,
}


# a hard streak crossed at 2 cm (about 10 s in) and a motor torque lag, as sim_node parameters
STREAK = ({"top_m": 0.02, "intrinsic_specific_energy_pa": 400e6, "mu_gamma": 0.6},)


@pytest.mark.parametrize(
    ("controller", "mode", "drive", "formation"),
    [("z_torque", "speed", {}, ()), ("soft_torque", "torque", {}, ()),
     ("z_torque", "speed", DRIVE, ()), ("soft_torque", "torque", {"motor_lag_s": 0.05}, STREAK)],
)
def test_in_process_and_over_dds_give_the_same_telemetry(
    controller: str, mode: str, drive: dict, formation: tuple
) -> None:
    sensors = {**SENSORS, "hook_load_n": {"noise_std": 500.0}} if drive else SENSORS
    scenario = Scenario(
        preset="field_8p5in_shale_lumped",
        controller=controller,
        mode=mode,
        duration_s=30.0,
        enable_at_s=10.0,
        sensors=sensors,
        schedule=({"t_s": 20.0, "rpm": 70.0, "ramp_s": 5.0}, {"t_s": 22.0, "wob_n": 65e3}),
        drive=drive,
        formation=formation,
    )
    local = run_in_process(scenario).rows
    remote = run_over_dds(scenario, timeout_s=240.0).rows
    assert local.shape == remote.shape == (3001, len(topics.TELEMETRY_FIELDS))
    assert local.tobytes() == remote.tobytes()
    # and the controller acted: the setpoint moved, the commands were stamped
    setpoint = local[1:, topics.TELEMETRY_INDEX["speed_setpoint_rpm"]]
    if mode == "speed":
        assert np.ptp(setpoint[1000:]) > 1.0
    np.testing.assert_allclose(
        local[1:, topics.TELEMETRY_INDEX["command_stamp_s"]], local[1:, 0] - 0.01, atol=1e-9
    )


def test_the_controller_node_subscribes_to_surface_measurements_only() -> None:
    with ros_context() as ros:
        node = ros.add(
            ControllerNode(
                context=ros.context,
                parameter_overrides=overrides(
                    controller="soft_torque", enable_at_s=5.0, soft_torque__impedance_factor=1.5
                ),
            )
        )
        assert [sub.topic_name for sub in node.subscriptions] == [topics.SURFACE_MEASURED]
        assert [pub.topic_name for pub in node.publishers if "cmd" in pub.topic_name] == [
            topics.CMD_TOP_DRIVE
        ]
        assert node.controller.params["impedance_factor"] == 1.5
        assert node.scenario.enable_at_s == 5.0
