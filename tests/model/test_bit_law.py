"""The bit law's seam and the bit friction that falls with speed (bit_rock.sliding_torque).

Expected values come from independent paths: the paper's dimensional equations in SI
(RGD07 eqs. 2-5, 11, 18) times the weakening factor written here in plain Python, its
derivative by hand, and RGD07's own law (floor ratio 1 must give its runs bit for bit).
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from drill_sim_ros.model import bit_rock as br
from drill_sim_ros.model import kernel as k
from drill_sim_ros.model.errors import ParameterError
from drill_sim_ros.model.params import DimensionlessParams
from drill_sim_ros.model.presets import Preset, preset_from_dict, preset_path
from drill_sim_ros.model.simulator import SimConfig, Simulator
from drill_sim_ros.model.validate_input import read_preset_file

FIG8A = DimensionlessParams(n=6, psi=50.0, beta=0.3, lam=5.0, w0=7.0, omega0=5.0)


def field(preset: str = "field_8p5in_shale", sigma_l: float | None = None,
          **weakening: object) -> Preset:
    """The field preset with ``physical.friction_weakening`` = ``weakening`` (none: RGD07's
    law, the option removed) and, if given, the bit's sigma l (N/m)."""
    data = read_preset_file(preset_path(preset))
    data["physical"].pop("friction_weakening", None)
    if weakening:
        data["physical"]["friction_weakening"] = dict(weakening)
    if sigma_l is not None:
        data["physical"]["contact_stress_times_wearflat_n_per_m"] = sigma_l
    return preset_from_dict(preset, data)


def factor(omega_rad_s: float, floor: float, speed_rad_s: float) -> float:
    """f(omega) = floor + (1 - floor) exp(-omega / speed), as the docs write it."""
    return floor + (1.0 - floor) * math.exp(-omega_rad_s / speed_rad_s)


def si_torques(preset: Preset) -> tuple[float, float]:
    """(cutting, wearflat friction) torque in N m of steady drilling at the preset's WOB,
    from the paper in SI: W_f = a sigma l, T_f = a^2 gamma mu sigma l / 2 (eq. 11),
    T_c = a (W - W_f) / (2 zeta) (eq. 18)."""
    p = preset.physical
    a, sigma_l = p.bit_radius_m, p.contact_stress_times_wearflat_n_per_m
    w_f = a * sigma_l
    return a * (p.applied_wob_n - w_f) / (2.0 * p.zeta), a * a * p.mu_gamma * sigma_l / 2.0


@pytest.mark.parametrize("applies_to", ["friction", "bit"])
def test_steady_torque_is_the_papers_times_the_factor(applies_to: str) -> None:
    """The simulator starts on the law's steady torque at the top-drive speed: in SI, the
    paper's T_c + T_f with f(omega) on T_f (friction) or on both (bit)."""
    preset = field(floor_ratio=0.5, speed_rad_s=7.0, applies_to=applies_to)
    sc, phys = preset.scales, preset.physical
    sim = Simulator(preset.params, top_drive=preset.top_drive, scales=sc,
                    bit_law=preset.bit_law)
    omega = phys.surface_rpm * 2.0 * math.pi / 60.0
    t_c, t_f = si_torques(preset)
    f = factor(omega, 0.5, 7.0)
    expected = t_c + t_f * f if applies_to == "friction" else (t_c + t_f) * f
    assert sc.tob_nm(sim.trivial.torque) == pytest.approx(expected, rel=1e-9)
    plain = Simulator(preset.params, scales=sc)
    assert sc.tob_nm(plain.trivial.torque) == pytest.approx(t_c + t_f, rel=1e-9)


def test_the_slope_at_rest_is_the_friction_torque_over_the_speed() -> None:
    """-dT/domega at omega = 0 of the wearflat weakening on the sharp bit (sigma l = 1e5
    N/m, the default until 2026-12-06): T_f (1 - floor) / speed, about 20 N m s (issue
    49's estimate), from the compiled law by a central difference in kernel units,
    converted to N m s."""
    preset = field(sigma_l=1.0e5, floor_ratio=0.5, speed_rad_s=7.0)
    law, p, sc = preset.bit_law, preset.params, preset.scales
    doc = max(p.w0 - p.lam, 0.0)
    _, t_f = si_torques(preset)
    for omega_rad_s in (0.0, 3.0, 10.0):
        h = 1e-4 / sc.time_s
        w = max(omega_rad_s * sc.time_s, h)
        slope = -(law.torque(doc, p.lam, p.beta, w + h)
                  - law.torque(doc, p.lam, p.beta, w - h)) / (2.0 * h)
        slope_nm_s = slope * sc.torque_nm * sc.time_s
        at = w / sc.time_s
        assert slope_nm_s == pytest.approx(t_f * 0.5 / 7.0 * math.exp(-at / 7.0), rel=1e-6)
    assert t_f * 0.5 / 7.0 == pytest.approx(20.0, abs=0.5)


@pytest.mark.parametrize("law", [br.LAW_WEAKENING_FRICTION, br.LAW_WEAKENING_BIT])
def test_floor_ratio_one_is_rgd07_bit_for_bit(law: int) -> None:
    """A weakening law with floor 1 runs RGD07's Fig. 8a case to the same bits, stick and
    slip included."""
    def rows(bit_law: br.BitLaw) -> np.ndarray:
        sim = Simulator(FIG8A, SimConfig(dtau=1e-3), perturb_v=0.01, bit_law=bit_law)
        return sim.advance(sim.steps_for(100.0), every=7).data

    plain, weak = rows(br.RGD07_LAW), rows(br.BitLaw(law, 1.0, 0.3))
    assert (plain[:, k.C_MODE] == k.MODE_STUCK).any()
    assert np.array_equal(plain, weak)


@pytest.mark.parametrize("applies_to", ["friction", "bit"])
def test_the_kernel_applies_the_law_at_the_bits_speed(applies_to: str) -> None:
    """On the distributed string, every sliding step's torque on bit is eq. (30) times the
    factor at the bit's own speed at the step's start (the sample's omega)."""
    preset = field(floor_ratio=0.4, speed_rad_s=2.0, applies_to=applies_to)
    sc, p = preset.scales, preset.params
    sim = Simulator(p, SimConfig(dtau=preset.dtau, n_nodes=256), perturb_omega=-0.6 * p.omega0,
                    top_drive=preset.top_drive, scales=sc, string=preset.kernel_string,
                    bit_law=preset.bit_law)
    data = sim.advance(sim.steps_for(4.0 / sc.time_s), every=1).data
    omega_rad_s = data[:, k.C_OMEGA] / sc.time_s
    f = np.array([factor(w, 0.4, 2.0) for w in omega_rad_s])
    doc, w_f, tob = data[:, k.C_DOC], data[:, k.C_WF], data[:, k.C_TOB]
    mode = data[:, k.C_MODE]
    sliding = (mode == k.MODE_CUTTING) | (mode == k.MODE_LOST_CONTACT)
    expected = doc + p.beta * w_f * f if applies_to == "friction" else (doc + p.beta * w_f) * f
    assert sliding.sum() > 1000 and np.ptp(f[sliding]) > 0.1
    assert tob[sliding] == pytest.approx(expected[sliding], rel=1e-12)


def test_a_lagged_law_reads_the_bits_speed_through_a_first_order_lag() -> None:
    """With ``response_s``, the speed the law reads follows the bit's sampled speed as the
    exact step of a first-order lag, w_k+1 = w_k + (1 - exp(-dt / response)) (omega_k+1 -
    w_k) from w_0 = omega_0, written here in plain Python; every sliding step's torque is
    eq. (30) times the factor at that speed."""
    response_s = 0.05
    preset = field(floor_ratio=0.4, speed_rad_s=2.0, applies_to="bit", response_s=response_s)
    sc, p = preset.scales, preset.params
    sim = Simulator(p, SimConfig(dtau=preset.dtau, n_nodes=256), perturb_omega=-0.6 * p.omega0,
                    top_drive=preset.top_drive, scales=sc, string=preset.kernel_string,
                    bit_law=preset.bit_law)
    data = sim.advance(sim.steps_for(4.0 / sc.time_s), every=1).data
    omega = data[:, k.C_OMEGA]
    alpha = -math.expm1(-preset.dtau * sc.time_s / response_s)
    read = np.empty_like(omega)
    read[0] = omega[0]
    for i in range(1, omega.size):
        read[i] = read[i - 1] + alpha * (omega[i] - read[i - 1])
    f = np.array([factor(w / sc.time_s, 0.4, 2.0) for w in read])
    doc, w_f, tob, mode = data[:, k.C_DOC], data[:, k.C_WF], data[:, k.C_TOB], data[:, k.C_MODE]
    sliding = (mode == k.MODE_CUTTING) | (mode == k.MODE_LOST_CONTACT)
    lagless = np.array([factor(w / sc.time_s, 0.4, 2.0) for w in omega])
    assert sliding.sum() > 1000 and np.max(np.abs(f - lagless)[sliding]) > 0.01
    assert tob[sliding] == pytest.approx(((doc + p.beta * w_f) * f)[sliding], rel=1e-9)


def test_the_stuck_bit_holds_rgd07s_static_torque() -> None:
    """Stuck, the bit holds a string torque just below delta + beta lambda whatever the law;
    just above it slips, and the torque it then meets is that static level (f(0) = 1): the
    law is continuous at the slip."""
    doc, beta, lam = 2.0, 0.3, 5.0
    static = doc + beta * lam
    for law in range(len(br.LAWS)):
        args = (0.0, 1e-3, 7.0, 0.0, 1e-3)
        held = br.bit_response(*args, static * (1 - 1e-12), doc, True, beta, lam, law, 0.0,
                               0.3, 0.5, False, 0.0)
        assert held[5] == br.MODE_STUCK and held[6]
        slip = br.bit_response(*args, static * (1 + 1e-9), doc, True, beta, lam, law, 0.0,
                               0.3, 0.5, False, 0.0)
        assert not slip[6] and slip[1] > 0.0
        assert slip[4] == static


def test_a_stuck_bit_pulled_up_rises_held_only_by_its_step() -> None:
    """Stuck, a bit that the string would pull up (v0 + kick f_ext < 0) rises at that speed:
    the rock cannot pull, so W = W_f = 0, and with the wearflat unloaded only the blades'
    step delta holds the torque (eq. 14 with W_f = 0). Above delta it slips, in lost contact
    (W = delta, T = delta: eqs. 29-31 with W_f = 0). Pushed down (f_ext >= 0) the stick is
    RGD07's, held up to delta + beta lambda."""
    doc, beta, lam, kick_v, kick_w = 2.0, 0.3, 5.0, 1e-3, 1e-3
    for law in range(len(br.LAWS)):
        def respond(v0: float, f_ext: float, t_ext: float, law: int = law) -> tuple:
            return br.bit_response(v0, kick_v, f_ext, 0.0, kick_w, t_ext, doc, True, beta,
                                   lam, law, 0.0, 0.3, 0.5, False, 0.0)
        v_new, omega_new, w_f, wob, tob, mode, stuck = respond(-0.01, -3.0, doc * 0.999)
        assert v_new == pytest.approx(-0.01 - kick_v * 3.0, rel=1e-12)
        assert (omega_new, w_f, wob, tob, mode, stuck) == (0.0, 0.0, 0.0, doc * 0.999,
                                                           br.MODE_STUCK, True)
        v_new, omega_new, w_f, wob, tob, mode, stuck = respond(-0.01, -3.0, doc * 1.001)
        assert not stuck and omega_new > 0.0 and mode == br.MODE_LOST_CONTACT
        assert (w_f, wob, tob) == (0.0, doc, doc)
        assert v_new == pytest.approx(-0.01 - kick_v * (3.0 + doc), rel=1e-12)
        held = respond(0.0, doc + 1.0, doc + beta * lam * 0.999)   # pushed down: W_f = 1
        assert held[:2] == (0.0, 0.0) and held[5] == br.MODE_STUCK and held[6]


def test_the_option_is_checked_one_line() -> None:
    """floor_ratio in (0, 1], speed_rad_s in (0, 1e4], applies_to friction | bit, no
    unknown key: one ParameterError line naming the key and the range."""
    cases = [({"floor_ratio": 0.0}, r"floor_ratio' = 0\.0 must be a number in \(0, 1\]"),
             ({"floor_ratio": 1.5}, "floor_ratio"),
             ({"speed_rad_s": -1.0}, r"speed_rad_s' = -1\.0 must be a number in \(0, 10000\]"),
             ({"speed_rad_s": "fast"}, "speed_rad_s"),
             ({"applies_to": "rock"}, "applies_to' = 'rock' must be one of friction, bit"),
             ({"response_s": -0.1}, r"response_s' = -0\.1 must be a number in \[0, 100\]"),
             ({"floor": 0.5}, "unknown key")]
    for values, message in cases:
        with pytest.raises(ParameterError, match=message) as info:
            field(**values)
        assert "\n" not in str(info.value)


def test_the_option_scales_once() -> None:
    """The e-folding speed in kernel units is speed_rad_s x t*; no option: RGD07's law."""
    preset = field(floor_ratio=0.5, speed_rad_s=7.0, applies_to="bit")
    assert preset.bit_law == br.BitLaw(br.LAW_WEAKENING_BIT, 0.5, 7.0 * preset.scales.time_s)
    assert field().bit_law == br.RGD07_LAW
    assert replace(preset, friction_weakening=None).bit_law == br.RGD07_LAW
