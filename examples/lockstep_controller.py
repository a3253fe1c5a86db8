"""A top-drive controller in plain rclpy, for sim_node in command-triggered lockstep.

    sim_node --ros-args -p lockstep:=true -p lockstep_trigger:=command
    python examples/lockstep_controller.py          # before or after sim_node; Ctrl-C stops

It answers every sample of drill/surface/measured with one drill/cmd/top_drive command
stamped with that sample's stamp, and sends nothing before its first sample. The samples are
latched (reliable, transient local, depth 1): whenever this node connects, it gets the
latest one. The commands are volatile: an answer sent before sim_node's subscription has
matched this node's publisher is lost (discovery can bring the sample first), so the first
answer waits for that match. The law: a torque-feedback speed setpoint that damps stick-slip.
"""

import math

import rclpy
from rclpy.clock import Clock, ClockType
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from sensor_msgs.msg import JointState

LATEST_SAMPLE = QoSProfile(depth=1, reliability=ReliabilityPolicy.RELIABLE,
                           durability=DurabilityPolicy.TRANSIENT_LOCAL)
SETPOINT_RAD_S = 2.0 * math.pi     # 60 rev/min
NOMINAL_TORQUE_NM = 3400.0         # the string torque of steady drilling on the field preset
GAIN_RAD_S_PER_NM = 1e-3           # slow down 1 rad/s per kN m of excess string torque


def speed_setpoint_rad_s(string_torque_nm: float) -> float:
    return max(0.0, SETPOINT_RAD_S - GAIN_RAD_S_PER_NM * (string_torque_nm - NOMINAL_TORQUE_NM))


class LockstepController(Node):
    def __init__(self) -> None:
        super().__init__("lockstep_controller")
        self.commands = self.create_publisher(JointState, "drill/cmd/top_drive", 10)
        self.create_subscription(JointState, "drill/surface/measured", self.on_sample,
                                 LATEST_SAMPLE)
        self.held: JointState | None = None              # an answer waiting for the match
        self.create_timer(0.01, self.send_held,          # wall time, also on use_sim_time
                          clock=Clock(clock_type=ClockType.STEADY_TIME))

    def on_sample(self, sample: JointState) -> None:
        # joints (top_drive, quill); effort: measured motor torque, torque-sub string torque
        command = JointState(name=["top_drive"],
                             velocity=[speed_setpoint_rad_s(sample.effort[1])])
        command.header.stamp = sample.header.stamp       # the sample this command answers
        self.held = command
        self.send_held()

    def send_held(self) -> None:
        if self.held is not None and self.commands.get_subscription_count() > 0:
            self.commands.publish(self.held)
            self.held = None


def main() -> None:
    rclpy.init()
    node = LockstepController()
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


if __name__ == "__main__":
    main()
