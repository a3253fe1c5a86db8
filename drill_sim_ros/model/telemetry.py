"""The telemetry record: field names and the one conversion of kernel samples to SI.

ROS-free. A telemetry row holds one sample in :data:`TELEMETRY_FIELDS` order, SI units
(speeds in rev/min). :func:`si_rows` is the only place where kernel columns (dimensionless,
RGD07 eqs. 19-24) become SI; sim_node, the recorder and ``drill_sim run --trace`` use it.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from drill_sim_ros.model import kernel as k
from drill_sim_ros.model.params import RPM_PER_RAD_S, Scales

NS_PER_S = 1_000_000_000
NO_COMMAND_S = -1.0     # command_stamp_s before the first stamped command (keeps rows finite)
MODE_NAMES = k.MODE_NAMES

# One flat, atomic record per sample.
TELEMETRY_FIELDS = (
    "sim_time_s",
    "bit_angle_rad",
    "bit_rpm",
    "bit_depth_m",
    "rop_m_s",
    "wob_n",
    "tob_nm",
    "depth_of_cut_m",
    "wearflat_wob_n",
    "mode",
    "surface_angle_rad",
    "surface_rpm",
    "surface_torque_nm",
    "applied_wob_n",
    "hook_load_n",
    "motor_torque_nm",             # top-drive motor torque over the step
    "speed_setpoint_rpm",          # top-drive speed setpoint in force (ramped)
    # what the rig's surface sensors give (model.measurement: noise, quantum, delay)
    "drive_speed_measured_rad_s",  # encoder
    "motor_torque_measured_nm",    # the drive's torque estimate
    "string_torque_measured_nm",   # torque sub at the quill
    "command_stamp_s",             # stamp of the drill/cmd/top_drive command in force (-1: none)
    "hook_load_measured_n",        # deadline load cell (model.measurement)
    "applied_wob_estimate_n",      # the driller's WOB: submerged weight - measured hook load
    "bha_rpm",                     # BHA speed: bottom of the string (lumped: the bit's)
)
TELEMETRY_INDEX = {name: i for i, name in enumerate(TELEMETRY_FIELDS)}
N_FIELDS = len(TELEMETRY_FIELDS)
F = TELEMETRY_INDEX

# Kernel column of each field but sim_time_s and hook_load_n (filled separately).
SOURCE_COLUMNS = {
    "bit_angle_rad": k.C_PHI, "bit_rpm": k.C_OMEGA, "bit_depth_m": k.C_U, "rop_m_s": k.C_V,
    "wob_n": k.C_WOB, "tob_nm": k.C_TOB, "depth_of_cut_m": k.C_DOC, "wearflat_wob_n": k.C_WF,
    "mode": k.C_MODE, "surface_angle_rad": k.C_PHI_S, "surface_rpm": k.C_OMEGA_S,
    "surface_torque_nm": k.C_T_PIPE, "applied_wob_n": k.C_W_APP,
    "motor_torque_nm": k.C_MOTOR_TORQUE, "speed_setpoint_rpm": k.C_OMEGA_REF,
    "bha_rpm": k.C_OMEGA_BHA,
}
_SOURCE_FIELDS = np.array([F[name] for name in SOURCE_COLUMNS], dtype=np.int64)
_SOURCE_KERNEL_COLUMNS = np.array(list(SOURCE_COLUMNS.values()), dtype=np.int64)
# The measured surface signals, in model.measurement.SIGNALS order, and their truth.
MEASURED = [F["drive_speed_measured_rad_s"], F["motor_torque_measured_nm"],
            F["string_torque_measured_nm"], F["hook_load_measured_n"]]
_WOB_ESTIMATE = F["applied_wob_estimate_n"]
_DEPTH = F["bit_depth_m"]
_ANGLES = [F["bit_angle_rad"], F["surface_angle_rad"]]


def field_scales(scales: Scales) -> np.ndarray:
    """SI factor of each telemetry field (1 for sim time, mode and hook load), shape (F,)."""
    rpm = RPM_PER_RAD_S / scales.time_s
    factors = {"bit_rpm": rpm, "surface_rpm": rpm, "speed_setpoint_rpm": rpm, "bha_rpm": rpm,
               "motor_torque_nm": scales.torque_nm, "bit_depth_m": scales.length_m,
               "rop_m_s": scales.length_m / scales.time_s, "depth_of_cut_m": scales.length_m,
               "wob_n": scales.force_n, "wearflat_wob_n": scales.force_n,
               "applied_wob_n": scales.force_n, "tob_nm": scales.torque_nm,
               "surface_torque_nm": scales.torque_nm}
    out = np.ones(N_FIELDS)
    for name, factor in factors.items():
        out[F[name]] = factor
    return out


def si_rows(samples: np.ndarray, offsets: tuple[float, float], factors: np.ndarray,
            sim_times_s: np.ndarray, submerged_weight_n: float,
            command_stamp_s: float = NO_COMMAND_S) -> np.ndarray:
    """SI rows, shape (len(samples), N_FIELDS), of kernel samples (``kernel.C_*`` columns).

    Each value is ``(column + rebasing offset) * factor``; ``offsets`` = (depth, angle) as
    :attr:`Simulator.offsets` gives them; ``factors`` from :func:`field_scales`; the hook
    load is ``submerged_weight_n`` less the string's force at the top (``kernel.C_F_TOP``,
    in the applied WOB's unit: the applied WOB on RGD07's lumped string, what the string
    leans on the hook's loop on the distributed one, 0 hanging off bottom);
    ``command_stamp_s`` is the stamp of the command in force over these samples.
    """
    out = np.empty((samples.shape[0], N_FIELDS))
    _fill_si(samples, float(offsets[0]), float(offsets[1]), factors,
             np.ascontiguousarray(sim_times_s, dtype=np.float64), float(submerged_weight_n),
             float(command_stamp_s), out)
    return out


_TIME, _HOOK, _COMMAND = F["sim_time_s"], F["hook_load_n"], F["command_stamp_s"]
_APPLIED_WOB = F["applied_wob_n"]
_F_TOP = k.C_F_TOP          # the string's force at the hook above its hanging weight
_SURFACE_RPM, _MOTOR, _STRING = F["surface_rpm"], F["motor_torque_nm"], F["surface_torque_nm"]
_MEASURED = np.array(MEASURED, dtype=np.int64)
MEASURED_COLUMNS = _MEASURED    # for RigSensors.measure_into, SIGNALS order
_HOOK_MEASURED = F["hook_load_measured_n"]
_ANGLE_FIELDS = np.array(_ANGLES, dtype=np.int64)


@njit(cache=True)
def _fill_si(samples: np.ndarray, depth_offset: float, angle_offset: float,
             factors: np.ndarray, sim_times_s: np.ndarray, submerged_weight_n: float,
             command_stamp_s: float, out: np.ndarray) -> None:
    """:func:`si_rows` into ``out``, element by element in the same operations and order
    (offset added, then the factor; fields without a source are 1 x their value)."""
    for i in range(samples.shape[0]):
        row = out[i]
        for j in range(_SOURCE_FIELDS.size):
            row[_SOURCE_FIELDS[j]] = samples[i, _SOURCE_KERNEL_COLUMNS[j]]
        row[_DEPTH] = row[_DEPTH] + depth_offset
        for j in range(_ANGLE_FIELDS.size):
            row[_ANGLE_FIELDS[j]] = row[_ANGLE_FIELDS[j]] + angle_offset
        for j in range(row.size):
            row[j] = row[j] * factors[j]
        row[_TIME] = sim_times_s[i]
        # the hook carries the weight less what the string leans on below: the string's
        # force at the top (the applied WOB only once the hook's loop has settled)
        row[_HOOK] = submerged_weight_n - samples[i, _F_TOP] * factors[_APPLIED_WOB]
        row[_COMMAND] = command_stamp_s
        # perfect sensors (see model.measurement), as surface_truth gives them
        row[_MEASURED[0]] = row[_SURFACE_RPM] / RPM_PER_RAD_S
        row[_MEASURED[1]] = row[_MOTOR]
        row[_MEASURED[2]] = row[_STRING]
        row[_MEASURED[3]] = row[_HOOK]
        row[_WOB_ESTIMATE] = submerged_weight_n - row[_HOOK]


@njit(cache=True)
def stamped_si_rows(samples: np.ndarray, depth_offset: float, angle_offset: float,
                    factors: np.ndarray, first_stamp_ns: int, period_ns: int,
                    submerged_weight_n: float,
                    command_stamp_s: float) -> tuple[np.ndarray, np.ndarray]:
    """(SI rows, stamps ns) of kernel samples taken every ``period_ns`` from
    ``first_stamp_ns``: :func:`si_rows` with sim_time_s = stamp / 1e9, in one compiled call
    (a node's tick converts one sample, and each numpy call from Python costs more than the
    conversion)."""
    count = samples.shape[0]
    stamps_ns = np.empty(count, dtype=np.int64)
    times_s = np.empty(count)
    for i in range(count):
        stamps_ns[i] = first_stamp_ns + i * period_ns
        times_s[i] = stamps_ns[i] / NS_PER_S
    out = np.empty((count, N_FIELDS))
    _fill_si(samples, depth_offset, angle_offset, factors, times_s, submerged_weight_n,
             command_stamp_s, out)
    return out, stamps_ns


def surface_truth(rows: np.ndarray) -> np.ndarray:
    """The true surface signals of SI rows, shape (rows, 4): drive speed rad/s, motor torque
    N m, string torque at the quill N m, hook load N (``model.measurement.SIGNALS`` order)."""
    return np.column_stack([rows[:, F["surface_rpm"]] / RPM_PER_RAD_S,
                            rows[:, F["motor_torque_nm"]], rows[:, F["surface_torque_nm"]],
                            rows[:, F["hook_load_n"]]])


@njit(cache=True)
def set_wob_estimate(rows: np.ndarray, submerged_weight_n: float) -> None:
    """The applied-WOB estimate of SI ``rows`` (N) from their measured hook load, in place
    (after ``model.measurement`` has measured the :data:`MEASURED_COLUMNS`)."""
    for i in range(rows.shape[0]):
        rows[i, _WOB_ESTIMATE] = submerged_weight_n - rows[i, _HOOK_MEASURED]
