"""The model core, the controllers and the studies never import ROS, MCAP or rerun."""

from __future__ import annotations

import subprocess
import sys


def test_model_imports_no_adapters() -> None:
    code = ("import sys, drill_sim_ros.model.simulator, drill_sim_ros.model.analysis, "
            "drill_sim_ros.model.top_drive, drill_sim_ros.model.measurement, "
            "drill_sim_ros.model.presets, drill_sim_ros.cli, drill_sim_ros.control.bench, "
            "drill_sim_ros.closed_loop_cli, drill_sim_ros.control.scorecard, "
            "drill_sim_ros.study.engine, drill_sim_ros.study.figures, drill_sim_ros.study.cli\n"
            "bad = [m for m in sys.modules if m.split('.')[0] in "
            "('rclpy', 'mcap', 'mcap_ros2', 'rerun', 'rosbags')]\n"
            "print(bad); sys.exit(1 if bad else 0)")
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                            timeout=120)
    assert result.returncode == 0, result.stdout + result.stderr
