"""The one SI conversion: each telemetry field is its kernel column (plus the rebasing
offset) in the unit the Scales of RGD07 eqs. 19-20 give, computed here field by field."""

from __future__ import annotations

import math

import numpy as np
import pytest

from drill_sim_ros.model import kernel as k
from drill_sim_ros.model.params import RPM_PER_RAD_S
from drill_sim_ros.model.presets import load_preset
from drill_sim_ros.model.telemetry import (
    MODE_NAMES,
    SOURCE_COLUMNS,
    TELEMETRY_INDEX,
    field_scales,
    si_rows,
)

F = TELEMETRY_INDEX


def test_si_rows_match_the_scales_field_by_field():
    sc = load_preset("field_8p5in_shale_lumped").scales
    rng = np.random.default_rng(7)
    data = rng.uniform(-50.0, 50.0, (5, k.N_COLS))
    data[:, k.C_MODE] = rng.integers(0, 4, 5)
    offsets, weight_n = (1234.0, 2.0 * math.pi * 57), 2.5e6
    times_s = np.arange(5) * 0.01
    rows = si_rows(data, offsets, field_scales(sc), times_s, weight_n)
    for i, d in enumerate(data):
        r = rows[i]
        assert r[F["sim_time_s"]] == times_s[i]
        assert r[F["bit_rpm"]] == pytest.approx(sc.rpm(d[k.C_OMEGA]), rel=1e-14)
        assert r[F["surface_rpm"]] == pytest.approx(sc.rpm(d[k.C_OMEGA_S]), rel=1e-14)
        assert r[F["rop_m_s"]] == pytest.approx(sc.rop_m_s(d[k.C_V]), rel=1e-14)
        assert r[F["wob_n"]] == pytest.approx(sc.wob_n(d[k.C_WOB]), rel=1e-14)
        assert r[F["wearflat_wob_n"]] == pytest.approx(sc.wob_n(d[k.C_WF]), rel=1e-14)
        assert r[F["tob_nm"]] == pytest.approx(sc.tob_nm(d[k.C_TOB]), rel=1e-14)
        assert r[F["surface_torque_nm"]] == pytest.approx(sc.tob_nm(d[k.C_T_PIPE]), rel=1e-14)
        assert r[F["depth_of_cut_m"]] == pytest.approx(d[k.C_DOC] * sc.length_m, rel=1e-14)
        assert r[F["bit_depth_m"]] == pytest.approx((d[k.C_U] + offsets[0]) * sc.length_m,
                                                    rel=1e-14)
        assert r[F["bit_angle_rad"]] == pytest.approx(d[k.C_PHI] + offsets[1], rel=1e-14)
        assert r[F["surface_angle_rad"]] == pytest.approx(d[k.C_PHI_S] + offsets[1],
                                                          rel=1e-14)
        assert r[F["hook_load_n"]] == pytest.approx(weight_n - sc.wob_n(d[k.C_F_TOP]),
                                                    rel=1e-14)
        assert MODE_NAMES[int(r[F["mode"]])] == MODE_NAMES[int(d[k.C_MODE])]


def test_compiled_si_rows_equal_the_vectorised_reference_bit_for_bit():
    """The compiled conversion does the numpy formulation's operations in its order:
    (column + offset) * factor, then time, hook load, command stamp and the true surface
    signals; here that formulation, written out with whole-array numpy."""
    sc = load_preset("field_8p5in_shale_lumped").scales
    rng = np.random.default_rng(11)
    data = rng.uniform(-1e3, 1e3, (64, k.N_COLS))
    offsets, factors = (98765.4321, 2.0 * math.pi * 1234), field_scales(sc)
    times_s, weight_n, stamp_s = np.arange(64) * 0.01, 1.8e6, 12.34
    ref = np.empty((64, len(TELEMETRY_INDEX)))
    source = dict(SOURCE_COLUMNS)
    for name, column in source.items():
        ref[:, F[name]] = data[:, column]
    ref[:, F["bit_depth_m"]] += offsets[0]
    ref[:, [F["bit_angle_rad"], F["surface_angle_rad"]]] += offsets[1]
    ref[:, [F[n] for n in source]] *= factors[[F[n] for n in source]]
    ref[:, F["sim_time_s"]] = times_s
    ref[:, F["hook_load_n"]] = weight_n - data[:, k.C_F_TOP] * factors[F["applied_wob_n"]]
    ref[:, F["command_stamp_s"]] = stamp_s
    ref[:, F["drive_speed_measured_rad_s"]] = ref[:, F["surface_rpm"]] / RPM_PER_RAD_S
    ref[:, F["motor_torque_measured_nm"]] = ref[:, F["motor_torque_nm"]]
    ref[:, F["string_torque_measured_nm"]] = ref[:, F["surface_torque_nm"]]
    ref[:, F["hook_load_measured_n"]] = ref[:, F["hook_load_n"]]
    ref[:, F["applied_wob_estimate_n"]] = weight_n - ref[:, F["hook_load_measured_n"]]
    rows = si_rows(data, offsets, factors, times_s, weight_n, stamp_s)
    assert rows.tobytes() == ref.tobytes()
