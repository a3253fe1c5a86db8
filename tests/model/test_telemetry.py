"""The one SI conversion: each telemetry field is its kernel column (plus the rebasing
offset) in the unit the Scales of RGD07 eqs. 19-20 give, computed here field by field."""

from __future__ import annotations

import math

import numpy as np
import pytest

from drill_sim_ros.model import kernel as k
from drill_sim_ros.model.presets import load_preset
from drill_sim_ros.model.telemetry import (
    MODE_NAMES,
    TELEMETRY_INDEX,
    field_scales,
    si_rows,
)

F = TELEMETRY_INDEX


def test_si_rows_match_the_scales_field_by_field():
    sc = load_preset("field_8p5in_shale").scales
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
        assert r[F["hook_load_n"]] == pytest.approx(weight_n - sc.wob_n(d[k.C_W_APP]),
                                                    rel=1e-14)
        assert MODE_NAMES[int(r[F["mode"]])] == MODE_NAMES[int(d[k.C_MODE])]
