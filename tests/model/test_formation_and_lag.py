"""Formation layers (the bit law's rock by depth) and the motor torque lag, in the model core.

Expected values: eq. (30) with the layer's own eps, mu gamma and sigma l, the layer top
crossed at the step the bit reaches it, and the exact step response of a first-order lag.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from drill_sim_ros.model import kernel as k
from drill_sim_ros.model.formation import layers_from_dicts
from drill_sim_ros.model.presets import load_preset
from drill_sim_ros.model.simulator import SimConfig, Simulator

PRESET = load_preset("field_8p5in_shale_lumped")


def simulator(**drive: float) -> Simulator:
    p = PRESET
    return Simulator(p.params, SimConfig(dtau=1e-4), perturb_v=1e-3,
                     top_drive=p.top_drive.with_(**drive), scales=p.scales)


def test_a_hard_streak_takes_effect_at_its_top() -> None:
    phys, sc = PRESET.physical, PRESET.scales
    plain, layered = simulator(), simulator()
    steps = layered.steps_for(20.0)
    depth_l = plain.advance(steps, every=1).column(k.C_U)     # in L*
    top_m = 0.5 * depth_l[-1] * sc.length_m                  # crossed half way through the run
    eps2, mu_gamma2, sigma_l2 = 2.0 * phys.intrinsic_specific_energy_pa, 0.6, 4.0e5
    layered.set_formation(layers_from_dicts(
        [{"top_m": top_m, "intrinsic_specific_energy_pa": eps2, "mu_gamma": mu_gamma2,
          "contact_stress_times_wearflat_n_per_m": sigma_l2}], PRESET.rock))
    rows = layered.advance(steps, every=1)
    depth_m = rows.column(k.C_U) * sc.length_m
    first = int(np.argmax(depth_m >= top_m))          # the first step that starts in it
    assert 0 < first < steps and depth_m[first - 1] < top_m
    reference = simulator().advance(first, every=1).data
    assert np.array_equal(rows.data[:first], reference)   # above the top: untouched
    below = rows.data[first:]
    cutting = below[:, k.C_MODE] == k.MODE_CUTTING
    assert cutting.sum() > 100
    cut = eps2 / phys.intrinsic_specific_energy_pa
    beta = mu_gamma2 * phys.zeta
    lam = sigma_l2 / (phys.zeta * phys.intrinsic_specific_energy_pa * sc.length_m)
    expected_tob = cut * below[cutting, k.C_DOC] + beta * lam            # eq. (30)
    assert below[cutting, k.C_TOB] == pytest.approx(expected_tob, rel=1e-12)
    assert below[cutting, k.C_WF] == pytest.approx(lam, rel=1e-12)      # eq. (31)
    assert layered.layer_index == 0


def test_layers_are_checked_one_line() -> None:
    with pytest.raises(Exception, match=r"formation\[0\]\.mu_gamma = 'x'"):
        layers_from_dicts([{"top_m": 0.1, "mu_gamma": "x"}], PRESET.rock)
    with pytest.raises(Exception, match="unknown key"):
        layers_from_dicts([{"top_m": 0.1, "hardness": 3}], PRESET.rock)


def test_motor_torque_lags_its_command_by_a_first_order_law() -> None:
    lag_s = 0.2
    lag = lag_s / PRESET.scales.time_s
    sim = simulator(mode="torque", motor_lag=lag)
    m0 = float(sim.state[k.S_MOTOR_TORQUE])
    sim.set_inputs(motor_torque=m0 + 5.0)
    rows = sim.advance(sim.steps_for(3 * lag), every=1).data
    tau = rows[:, k.C_TAU] - rows[0, k.C_TAU] + sim.config.dtau      # after each step
    expected = m0 + 5.0 * (1.0 - np.exp(-tau / lag))
    assert rows[:, k.C_MOTOR_TORQUE] == pytest.approx(expected, rel=1e-9)
    one = round(lag / sim.config.dtau) - 1
    assert (rows[one, k.C_MOTOR_TORQUE] - m0) / 5.0 == pytest.approx(1 - math.exp(-1),
                                                                      abs=1e-3)
