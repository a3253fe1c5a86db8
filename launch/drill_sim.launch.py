"""One rig: sim_node, and optionally its MCAP recorder, rerun bridge and a controller.

    ros2 launch drill_sim_ros drill_sim.launch.py namespace:=rig1 preset:=fig10 \
        record:=true record_path:=rig1.mcap bridge:=true bridge_path:=rig1.rrd \
        controller:=soft_torque lockstep:=true use_sim_time:=true

Every node runs in ``namespace`` (the sim's topics under /<namespace>/drill/..., the
recorder and the bridge follow them) and takes ``use_sim_time``. The sim reads the
installed config/sim.yaml (keyed /**/drill_sim, so it applies in any namespace), then the
arguments below. With ``controller`` set and ``lockstep:=true`` the controller drives the
sim in command-triggered lockstep (one period per command).
"""

from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument
from launch.conditions import IfCondition
from launch.substitutions import LaunchConfiguration, PathJoinSubstitution, PythonExpression
from launch_ros.actions import Node
from launch_ros.substitutions import FindPackageShare

PACKAGE = "drill_sim_ros"
# name: (default, description)
ARGUMENTS = {
    "namespace": ("", "namespace of the rig's nodes and topics ('' = root)"),
    "use_sim_time": ("false", "every node follows /clock (the sim publishes it)"),
    "preset": ("field_8p5in_shale", "the sim's model.preset (config/presets/<name>.yaml)"),
    "real_time_factor": ("1.0", "simulated seconds per wall second; 0 = as fast as possible"),
    "lockstep": ("false", "true: the sim advances one period per drill/cmd/top_drive command"),
    "record": ("false", "record the rig's topics with mcap_recorder"),
    "record_path": ("drill_sim.mcap", "the recorder's output file"),
    "bridge": ("false", "log the rig's telemetry to rerun with rerun_bridge"),
    "bridge_path": ("drill_sim.rrd", "the bridge's .rrd file"),
    "controller": ("", "top_drive_controller's controller ('' = no controller)"),
}


def _arg(name: str) -> LaunchConfiguration:
    return LaunchConfiguration(name)


def generate_launch_description() -> LaunchDescription:
    namespace, use_sim_time = _arg("namespace"), _arg("use_sim_time")
    sim_yaml = PathJoinSubstitution([FindPackageShare(PACKAGE), "config", "sim.yaml"])
    sim = Node(package=PACKAGE, executable="sim_node", name="drill_sim", namespace=namespace,
               output="screen",
               parameters=[sim_yaml, {"use_sim_time": use_sim_time,
                                      "model.preset": _arg("preset"),
                                      "real_time_factor": _arg("real_time_factor"),
                                      "lockstep": _arg("lockstep"),
                                      "lockstep_trigger": "command",
                                      "status_line": False}])
    recorder = Node(package=PACKAGE, executable="mcap_recorder", name="mcap_recorder",
                    namespace=namespace, output="screen",
                    arguments=["-o", _arg("record_path")],
                    parameters=[{"use_sim_time": use_sim_time}],
                    condition=IfCondition(_arg("record")))
    bridge = Node(package=PACKAGE, executable="rerun_bridge", name="rerun_bridge",
                  namespace=namespace, output="screen",
                  arguments=["--save", _arg("bridge_path")],
                  parameters=[{"use_sim_time": use_sim_time}],
                  condition=IfCondition(_arg("bridge")))
    controller = Node(package=PACKAGE, executable="top_drive_controller",
                      name="top_drive_controller", namespace=namespace, output="screen",
                      parameters=[{"use_sim_time": use_sim_time,
                                   "controller": _arg("controller"),
                                   "preset": _arg("preset")}],
                      condition=IfCondition(PythonExpression(
                          ["'", _arg("controller"), "' != ''"])))
    declared = [DeclareLaunchArgument(name, default_value=default, description=text)
                for name, (default, text) in ARGUMENTS.items()]
    return LaunchDescription([*declared, sim, recorder, bridge, controller])
