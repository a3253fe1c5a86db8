"""Telemetry from the real Simulator, and an MCAP of it written with mcap_ros2's Writer.

An independent path (not the sim_node's conversion, not the archive's writer) used as the
input of the viz tests and of benchmarks/bench_bridge.py.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
from mcap_ros2.writer import Writer

from drill_sim_ros import topics
from drill_sim_ros.model import kernel as k
from drill_sim_ros.model.presets import Preset, load_preset
from drill_sim_ros.model.simulator import SimConfig, Simulator

SEPARATOR = "=" * 80
LAYOUT_DEF = """MultiArrayDimension[] dim
uint32 data_offset
"""
DIMENSION_DEF = """string label
uint32 size
uint32 stride
"""
FLOAT64_MULTI_ARRAY_DEF = (
    "MultiArrayLayout layout\nfloat64[] data\n"
    f"{SEPARATOR}\nMSG: std_msgs/MultiArrayLayout\n{LAYOUT_DEF}"
    f"{SEPARATOR}\nMSG: std_msgs/MultiArrayDimension\n{DIMENSION_DEF}"
)


def telemetry_rows(preset: Preset, seconds: float, rate_hz: float = 100.0) -> np.ndarray:
    """(n, len(TELEMETRY_FIELDS)) SI rows sampled every 1/rate_hz s of sim time."""
    sim = Simulator(preset.params, SimConfig(dtau=preset.dtau), perturb_omega=0.01)
    sc = preset.scales
    every = max(1, round(1.0 / rate_hz / sc.time_s / preset.dtau))
    samples = sim.advance(sim.steps_for(seconds / sc.time_s), every)
    col = samples.column
    fields = {
        "sim_time_s": col(k.C_TAU) * sc.time_s,
        "bit_angle_rad": col(k.C_PHI),
        "bit_rpm": sc.rpm(col(k.C_OMEGA)),
        "bit_depth_m": col(k.C_U) * sc.length_m,
        "rop_m_s": sc.rop_m_s(col(k.C_V)),
        "wob_n": sc.wob_n(col(k.C_WOB)),
        "tob_nm": sc.tob_nm(col(k.C_TOB)),
        "depth_of_cut_m": col(k.C_DOC) * sc.length_m,
        "wearflat_wob_n": sc.wob_n(col(k.C_WF)),
        "mode": col(k.C_MODE),
        "surface_angle_rad": col(k.C_PHI_S),
        "surface_rpm": sc.rpm(col(k.C_OMEGA_S)),
        "surface_torque_nm": sc.tob_nm(col(k.C_T_PIPE)),
        "applied_wob_n": sc.wob_n(col(k.C_W_APP)),
        "hook_load_n": -sc.wob_n(col(k.C_F_TOP)),      # no weight: minus the string's force
        "motor_torque_nm": sc.tob_nm(col(k.C_MOTOR_TORQUE)),
        "speed_setpoint_rpm": sc.rpm(col(k.C_OMEGA_REF)),
        "drive_speed_measured_rad_s": col(k.C_OMEGA_S) / sc.time_s,
        "motor_torque_measured_nm": sc.tob_nm(col(k.C_MOTOR_TORQUE)),
        "string_torque_measured_nm": sc.tob_nm(col(k.C_T_PIPE)),
        "command_stamp_s": np.full(len(samples), -1.0),
        "hook_load_measured_n": -sc.wob_n(col(k.C_F_TOP)),
        "applied_wob_estimate_n": sc.wob_n(col(k.C_F_TOP)),
        "bha_rpm": sc.rpm(col(k.C_OMEGA_BHA)),
    }
    return np.column_stack([fields[name] for name in topics.TELEMETRY_FIELDS])


def default_rows(seconds: float = 30.0, preset: str = "field_8p5in_shale_lumped") -> np.ndarray:
    return telemetry_rows(load_preset(preset), seconds)


def telemetry_message(row: np.ndarray) -> dict:
    """A std_msgs/Float64MultiArray as mcap_ros2 encodes it (labels: comma-joined fields)."""
    label = ",".join(topics.TELEMETRY_FIELDS)
    dim = {"label": label, "size": len(row), "stride": len(row)}
    return {"layout": {"dim": [dim], "data_offset": 0}, "data": [float(v) for v in row]}


def write_mcap(path: Path, rows: np.ndarray, metadata: dict[str, str] | None = None,
               run_info: dict | None = None) -> None:
    """One /drill/telemetry message per row, log time = 1e9 ns + sim time; ``run_info`` as
    one /drill/run_info message (std_msgs/String, JSON) first."""
    with open(path, "wb") as stream:
        writer = Writer(stream)
        schema = writer.register_msgdef("std_msgs/msg/Float64MultiArray",
                                        FLOAT64_MULTI_ARRAY_DEF)
        if run_info is not None:
            string = writer.register_msgdef("std_msgs/msg/String", "string data\n")
            writer.write_message(topics.RUN_INFO, string, {"data": json.dumps(run_info)},
                                 log_time=1_000_000_000, publish_time=1_000_000_000)
        for i, row in enumerate(rows):
            stamp = 1_000_000_000 + round(row[0] * 1e9)
            writer.write_message(topics.TELEMETRY, schema, telemetry_message(row),
                                 log_time=stamp, publish_time=stamp, sequence=i)
        if metadata:
            writer.add_metadata("drill_sim", metadata)
        writer.finish()
