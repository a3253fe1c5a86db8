"""``drill_sim stability`` (control/stability.py): the bit's slope at the field point from
RGD07's equations in SI, one-line errors, and a smoke run of the command."""

from __future__ import annotations

import json
import math

import pytest

from drill_sim_ros.control import stability as st
from tests.robust.helpers import one_error_line, run_cli

FIELD = "field_8p5in_shale"


def test_slope_at_the_field_point_from_rgd07_in_si() -> None:
    """The default's worn bit at 35 rpm and 60 kN sliding steadily: RGD07's torque in SI,
    T0 = a (W - W_f) / (2 zeta) + mu gamma a W_f / 2 with W_f = a sigma l (eqs. 4-5, 11),
    weakened as a whole by 0.5 + 0.5 e^(-w / 7 rad/s); b = -dT/dw by hand."""
    preset = st.checked_preset(FIELD)
    a, sigma_l, zeta, mu_gamma, wob_n = 0.108, 3.0e5, 0.729, 0.48, 60.0e3
    w_f = a * sigma_l
    t0 = a * (wob_n - w_f) / (2 * zeta) + mu_gamma * a * w_f / 2
    w = 35.0 * 2 * math.pi / 60
    expected = t0 * 0.5 / 7.0 * math.exp(-w / 7.0)
    assert st.bit_slope_nm_s(preset, 35.0, wob_n) == pytest.approx(expected, rel=1e-3)
    assert st.response_s(preset) == pytest.approx(0.06, rel=1e-9)


@pytest.mark.parametrize(("args", "names"), [
    (("--rpm", "0"), ("--rpm", "[1, 400]")),
    (("--wob-n", "nan"), ("--wob-n",)),
    (("--params", "fig8b"), ("fig8b", "physical")),
])
def test_bad_inputs_are_one_line(capsys: pytest.CaptureFixture[str], args: tuple[str, ...],
                                 names: tuple[str, ...]) -> None:
    rc, _, err = run_cli(capsys, "stability", *args)
    one_error_line(rc, err, *names)


def test_cli_smoke(capsys: pytest.CaptureFixture[str]) -> None:
    """The stiff drive at the field point: the JSON holds the loop's parts and G is their
    product; a stiff top returns nearly all of a wave (|r_top| > 0.95, its speed loop)."""
    rc, out, _ = run_cli(capsys, "stability", "--params", FIELD, "--controller", "stiff",
                         "--json")
    assert rc == 0
    lines = out.strip().splitlines()
    assert len(lines) == 1
    result = json.loads(lines[0])
    (p,) = result["predictions"]
    assert p["controller"] == "stiff" and result["rpm"] == 35.0 and result["wob_n"] == 60000.0
    assert p["r_top"] > 0.95
    assert p["loop_gain"] == pytest.approx(p["r_bit"] * p["r_top"] * p["pipe_round_trip"],
                                           rel=1e-3)
    assert p["grows"] == (p["loop_gain"] > 1.0)


def test_complex_top_reflection_of_the_speed_loop_is_the_formula() -> None:
    """The phase too: the drive's own speed loop through the bench reflects the torque wave
    as (Z_TD - Z) / (Z_TD + Z), Z_TD(s) = J s + kp + ki / s (+1 for a clamped top, the
    convention of model/bit_reflection.py)."""
    import numpy as np

    from tests.control import native_reflection as nr
    preset = st.checked_preset(nr.FIELD)
    drive = preset.top_drive.physical(preset.scales)
    z = preset.string.sections[0].torsional_impedance_nm_s
    f = nr.STABILITY_F_HZ
    s = 2j * np.pi * f
    z_td = drive.inertia_kg_m2 * s + drive.kp_nm_s + drive.ki_nm / s
    measured = nr.native_reflection(f)          # 60 s, shared with tests/model/test_string.py
    assert np.max(np.abs(measured - (z_td - z) / (z_td + z))) < 0.03


def test_the_top_reflection_of_a_walled_preset_is_its_drives_alone() -> None:
    """A deviated preset: the instrument's line is a uniform anechoic line that meets only
    the top drive, so the wall of the preset's well is not on it and the speed loop reflects
    as the formula above. (With the wall left on, the line at rest stuck to it and |r|
    read 10^6 to 10^8, and ``drill_sim stability`` called every controller's mode growing.)"""
    import numpy as np

    from drill_sim_ros.control.reflection import complex_reflection_with
    name = "field_8p5in_deviated"
    preset = st.checked_preset(name)
    assert preset.string.well is not None and preset.string.well.has_friction
    drive = preset.top_drive.physical(preset.scales)
    z = preset.string.sections[0].torsional_impedance_nm_s
    f = np.array([0.2, 1.0])
    s = 2j * np.pi * f
    z_td = drive.inertia_kg_m2 * s + drive.kp_nm_s + drive.ki_nm / s
    measured = complex_reflection_with(name, "none", f, seconds=30.0, settle_s=10.0)
    assert np.max(np.abs(measured - (z_td - z) / (z_td + z))) < 0.03
