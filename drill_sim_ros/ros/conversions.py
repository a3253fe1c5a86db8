"""Simulator samples -> SI telemetry rows (``topics.TELEMETRY_FIELDS``; rpm for speeds).

:func:`telemetry_rows` is the column-wise numpy form, for whole runs and as the reference
that the compiled per-sample path (:mod:`drill_sim_ros.ros.frame`) must equal bit for bit.
"""

from __future__ import annotations

import numpy as np
from builtin_interfaces.msg import Time

from drill_sim_ros import topics
from drill_sim_ros.model import kernel as k
from drill_sim_ros.model.params import RPM_PER_RAD_S, Scales
from drill_sim_ros.model.simulator import Samples

F = topics.TELEMETRY_INDEX
N_FIELDS = len(topics.TELEMETRY_FIELDS)
NS_PER_S = 1_000_000_000
# Kernel column of each telemetry field but sim_time_s and hook_load_n (filled separately).
SOURCE_COLUMNS = {
    "bit_angle_rad": k.C_PHI, "bit_rpm": k.C_OMEGA, "bit_depth_m": k.C_U, "rop_m_s": k.C_V,
    "wob_n": k.C_WOB, "tob_nm": k.C_TOB, "depth_of_cut_m": k.C_DOC, "wearflat_wob_n": k.C_WF,
    "mode": k.C_MODE, "surface_angle_rad": k.C_PHI_S, "surface_rpm": k.C_OMEGA_S,
    "surface_torque_nm": k.C_T_PIPE, "applied_wob_n": k.C_W_APP,
}
SOURCE_FIELDS = np.array([F[name] for name in SOURCE_COLUMNS], dtype=np.int64)
SOURCE_KERNEL_COLUMNS = np.array(list(SOURCE_COLUMNS.values()), dtype=np.int64)
_DEPTH = F["bit_depth_m"]
_ANGLES = [F["bit_angle_rad"], F["surface_angle_rad"]]


def field_scales(scales: Scales) -> np.ndarray:
    """SI factor of each telemetry field (1 for sim time, mode and hook load), shape (F,)."""
    rpm = RPM_PER_RAD_S / scales.time_s
    factors = {"bit_rpm": rpm, "surface_rpm": rpm, "bit_depth_m": scales.length_m,
               "rop_m_s": scales.length_m / scales.time_s, "depth_of_cut_m": scales.length_m,
               "wob_n": scales.force_n, "wearflat_wob_n": scales.force_n,
               "applied_wob_n": scales.force_n, "tob_nm": scales.torque_nm,
               "surface_torque_nm": scales.torque_nm}
    out = np.ones(N_FIELDS)
    for name, factor in factors.items():
        out[F[name]] = factor
    return out


def telemetry_rows(samples: Samples, scales: Scales, sim_times_s: np.ndarray,
                   submerged_weight_n: float) -> np.ndarray:
    """SI rows, shape (len(samples), N_FIELDS), columns in ``TELEMETRY_FIELDS`` order.

    Each value is ``(column + rebasing offset) * factor``, as :meth:`Samples.column` gives it.
    """
    factors = field_scales(scales)
    out = np.empty((len(samples), N_FIELDS))
    out[:, SOURCE_FIELDS] = samples.data[:, SOURCE_KERNEL_COLUMNS]
    out[:, _DEPTH] += samples.depth_offset
    out[:, _ANGLES] += samples.angle_offset
    out *= factors
    out[:, F["sim_time_s"]] = sim_times_s
    out[:, F["hook_load_n"]] = submerged_weight_n - out[:, F["applied_wob_n"]]
    return out


def stamp(time_ns: int) -> Time:
    """builtin_interfaces/Time of an integer nanosecond count."""
    sec, nanosec = divmod(int(time_ns), NS_PER_S)
    return Time(sec=sec, nanosec=nanosec)
