"""ament_python package set-up: console scripts go to lib/drill_sim_ros for `ros2 run`."""

from glob import glob

from setuptools import find_packages, setup

PACKAGE = "drill_sim_ros"

setup(
    name=PACKAGE,
    version="0.1.0",
    packages=find_packages(include=[PACKAGE, f"{PACKAGE}.*"]),
    data_files=[
        ("share/ament_index/resource_index/packages", [f"resource/{PACKAGE}"]),
        (f"share/{PACKAGE}", ["package.xml"]),
        (f"share/{PACKAGE}/config", glob("config/*.yaml") + glob("config/*.xml")),
        (f"share/{PACKAGE}/config/presets", glob("config/presets/*.yaml")
         + glob("config/presets/*.csv")),
        (f"share/{PACKAGE}/config/scenarios", glob("config/scenarios/*.yaml")),
        (f"share/{PACKAGE}/launch", glob("launch/*.launch.py")),
    ],
    install_requires=["setuptools"],
    zip_safe=True,
    maintainer="drill_sim_ros developers",
    maintainer_email="drill-sim@example.org",
    description="Real-time drill-bit stick-slip simulation (Richard, Germay & Detournay 2007) "
                "for ROS 2 Jazzy",
    license="Apache-2.0",
    entry_points={
        "console_scripts": [
            "drill_sim = drill_sim_ros.cli:main",
            "sim_node = drill_sim_ros.ros.sim_node:main",
            "top_drive_controller = drill_sim_ros.ros.controller_node:main",
            "opcua_gateway = drill_sim_ros.ros.opcua_gateway:main",
            "mcap_recorder = drill_sim_ros.archive.recorder_node:main",
            "mcap_replay = drill_sim_ros.archive.replay_node:main",
            "mcap_reindex = drill_sim_ros.archive.reindex:main",
            "rerun_bridge = drill_sim_ros.viz.bridge_node:main",
            "mcap_to_rerun = drill_sim_ros.viz.mcap_to_rerun:main",
        ],
    },
)
