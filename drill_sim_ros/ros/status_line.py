"""sim_node's live status line: sim time, bit rpm, WOB, TOB, ROP, mode, real-time factor."""

from __future__ import annotations

import math

from drill_sim_ros import topics
from drill_sim_ros.terminal import StatusLine

__all__ = ["StatusLine", "format_status"]

F = topics.TELEMETRY_INDEX
M_S_TO_M_H = 3600.0


def format_status(row: list[float], achieved_rtf: float, state: str = "") -> str:
    """The status text of one telemetry row (``topics.TELEMETRY_FIELDS`` order)."""
    mode = int(row[F["mode"]])
    mode_name = topics.MODE_NAMES[mode] if 0 <= mode < len(topics.MODE_NAMES) else "?"
    rtf = "  -  " if math.isnan(achieved_rtf) else f"{achieved_rtf:5.2f}"
    text = (f"t {row[F['sim_time_s']]:9.2f} s | bit {row[F['bit_rpm']]:6.1f} rpm | "
            f"WOB {row[F['wob_n']] / 1e3:7.2f} kN | TOB {row[F['tob_nm']] / 1e3:6.2f} kN m | "
            f"ROP {row[F['rop_m_s']] * M_S_TO_M_H:6.2f} m/h | {mode_name:<12} | x{rtf}")
    return f"{text} | {state}" if state else text
