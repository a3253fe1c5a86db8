"""The dimensionless variables of the 2D views against RGD07's definitions."""

from __future__ import annotations

import math

import numpy as np
import pytest

from drill_sim_ros.model.presets import load_preset
from drill_sim_ros.viz.paper_units import PaperUnits


def test_es_scaling_equals_eq_48_in_si() -> None:
    """E = <T>/<delta> = 2 T/(eps a^2 d) and S = <W>/<delta> = W/(zeta eps a d)."""
    preset = load_preset("field_8p5in_shale_lumped")
    units, phys = PaperUnits.from_preset(preset), preset.physical
    torque, weight, doc = 3.0e3, 4.0e4, 2.0e-3
    eps, a = phys.intrinsic_specific_energy_pa, phys.bit_radius_m
    energy = units.torque(torque) / units.depth_of_cut(doc)
    strength = units.weight(weight) / units.depth_of_cut(doc)
    assert energy == pytest.approx(2 * torque / (eps * a * a * doc), rel=1e-12)
    assert strength == pytest.approx(weight / (phys.zeta * eps * a * doc), rel=1e-12)


def test_trivial_state_lies_on_the_friction_line() -> None:
    """Eq. 49 holds for the trivial solution, so (S0, E0) is on E = 1 - beta + beta S."""
    units = PaperUnits.load("fig12")
    s0, e0 = units.w0 / units.delta0, units.t0 / units.delta0
    assert e0 == pytest.approx(float(units.friction_line(np.array(s0))), rel=1e-12)


def test_omega_scaling() -> None:
    units = PaperUnits.load("field_8p5in_shale_lumped")
    rpm = 60.0
    assert units.omega(rpm) == pytest.approx(rpm * 2 * math.pi / 60 * units.scales.time_s)
