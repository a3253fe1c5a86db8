"""The bit's depth-of-cut limit (bit_rock.DepthOfCutLimit, ``physical.depth_of_cut_limit``).

Expected values come from independent paths: the paper's dimensional equations in SI
(RGD07 eqs. 2-5, 11: T_c = eps a^2 d / 2, W_c = zeta eps a d, T_f = mu gamma a W_f / 2 with
W_f = sigma l a) with the cutting depth capped and the limiter's force carried with its own
mu gamma, as docs/model.md writes it; the law written per sample in plain Python; and
RGD07's own runs (a limit never reached must give them bit for bit).
"""

from __future__ import annotations

import math

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


def field(**limit: object) -> Preset:
    """The field preset with ``physical.depth_of_cut_limit`` = ``limit`` (none: removed)."""
    data = read_preset_file(preset_path("field_8p5in_shale"))
    data["physical"].pop("depth_of_cut_limit", None)
    if limit:
        data["physical"]["depth_of_cut_limit"] = dict(limit)
    return preset_from_dict("field_8p5in_shale", data)


def hold_nm(preset: Preset, depth_m: float, force_n: float, mu_gamma_limit: float) -> float:
    """The torque a stuck bit holds in SI, the cutters at ``depth_m`` per revolution, the
    wearflat in full contact and the limiter carrying the rest of ``force_n`` (eqs. 2-5,
    11; docs/model.md#a-depth-of-cut-limit-an-option-off-by-default)."""
    p = preset.physical
    a, eps = p.bit_radius_m, p.intrinsic_specific_energy_pa
    sigma_l = p.contact_stress_times_wearflat_n_per_m
    w_c, w_f = p.zeta * eps * a * depth_m, sigma_l * a
    w_l = max(force_n - w_c - w_f, 0.0)
    return (eps * a * a * depth_m / 2.0 + p.mu_gamma * a * w_f / 2.0
            + mu_gamma_limit * a * w_l / 2.0)


@pytest.mark.parametrize("mu_gamma", [None, 0.2])
def test_a_stuck_bit_deeper_than_the_limit_holds_the_capped_torque(mu_gamma: float | None
                                                                   ) -> None:
    """A bit stuck with 63 mm of rock under it (a stall of docs/string.md) and the limit at
    20 mm per revolution, pressed by 500 kN (more than the 362 kN that 20 mm of cut carries,
    so the limiter bears the rest), holds exactly the SI torque of 20 mm of cut, the
    wearflat and the limiter's friction on the rest of the weight, and slips just above
    it; RGD07's bit at 63 mm holds more than the 50 kN m drive."""
    limit = {"max_depth_m_per_rev": 0.020} | ({} if mu_gamma is None else {"mu_gamma": mu_gamma})
    preset = field(**limit)
    sc, p, law = preset.scales, preset.params, preset.bit_law
    force_n = 500e3
    expected = hold_nm(preset, 0.020, force_n, preset.physical.mu_gamma if mu_gamma is None
                       else mu_gamma)
    assert law.doc_max * sc.length_m == pytest.approx(0.020, rel=1e-12)
    cut = law.doc_max                              # what the kernel hands on: the cap

    def stuck_after(torque_nm: float) -> tuple[bool, float]:
        *_, wob, _, _, stuck = br.bit_response(
            0.0, 1.0, force_n / sc.force_n, 0.0, 1.0, torque_nm / sc.torque_nm, cut, True,
            p.beta, p.lam, law.law, 0.0, law.a, law.b, True, law.beta_limit)
        return stuck, wob * sc.force_n

    held, wob_n = stuck_after(expected * (1.0 - 1e-9))
    assert held and wob_n == pytest.approx(force_n, rel=1e-12)   # the rock carries it all
    assert not stuck_after(expected * (1.0 + 1e-9))[0]
    assert expected < 40e3 < hold_nm(preset, 0.063, 0.0, 0.0) - 30e3


def test_while_turning_the_limiter_stops_the_advance_and_adds_its_friction() -> None:
    """Sliding at the limit: a bit pushed down is stopped (V = 0) by the force its step's
    momentum needs, the wearflat full, and the torque is the capped cut's plus both
    frictions; a bit moving up is left alone (eq. 31's contact, eq. 25)."""
    beta, lam, beta_limit, cut = 0.3, 5.0, 0.2, 1.0
    v_new, omega_new, w_f, wob, tob, mode, stuck = br.bit_response(
        0.5, 0.01, 100.0, 5.0, 0.01, 3.0, cut, False, beta, lam, br.LAW_RGD07, 5.0, 1.0, 1.0,
        True, beta_limit)
    v_free = 0.5 + 0.01 * (100.0 - cut - lam)       # the speed the limiter must take away
    assert (v_new, w_f, mode, stuck) == (0.0, lam, br.MODE_CUTTING, False)
    assert wob == pytest.approx(cut + lam + v_free / 0.01, rel=1e-12)
    assert tob == pytest.approx(cut + beta * lam + beta_limit * v_free / 0.01, rel=1e-12)
    assert omega_new == pytest.approx(5.0 + 0.01 * (3.0 - tob), rel=1e-12)
    up = br.bit_response(-0.5, 0.01, 0.0, 5.0, 0.01, 3.0, cut, False, beta, lam,
                         br.LAW_RGD07, 5.0, 1.0, 1.0, True, beta_limit)
    assert up[0] == pytest.approx(-0.5 + 0.01 * (0.0 - cut), rel=1e-12) and up[3] == cut


def test_a_limit_never_reached_is_rgd07_bit_for_bit() -> None:
    """RGD07's Fig. 8a case (stick and slip, cutting at up to a few L*) with a limit far
    below anything it reaches runs to the same bits as without one."""
    def rows(law: br.BitLaw) -> np.ndarray:
        sim = Simulator(FIG8A, SimConfig(dtau=1e-3), perturb_v=0.01, bit_law=law)
        return sim.advance(sim.steps_for(100.0), every=7).data

    plain = rows(br.RGD07_LAW)
    limited = rows(br.BitLaw(doc_max=10.0 * plain[:, k.C_DOC].max(), beta_limit=0.3))
    assert (plain[:, k.C_MODE] == k.MODE_STUCK).any()
    assert np.array_equal(plain, limited)


def test_drilling_into_the_limit_cuts_at_it() -> None:
    """Fig. 8a's bit with the limit at half its steady cut (delta_0 = w0 - lambda = 2):
    every sample deeper than the limit carries the law at the capped cut (T = d_max +
    beta W_f + beta_l (W - d_max - W_f)), every shallower one RGD07's (W = delta + W_f,
    T = delta + beta W_f); the bit advances its mean cut, near the limit, per revolution
    (eq. 8) and the mean WOB is the applied weight."""
    d_max, beta_l = 1.0, 0.25
    sim = Simulator(FIG8A, SimConfig(dtau=1e-3), bit_law=br.BitLaw(doc_max=d_max,
                                                                   beta_limit=beta_l))
    sim.advance(sim.steps_for(50.0))
    data = sim.advance(sim.steps_for(50.0), every=1).data
    doc, wob, tob, w_f = (data[:, c] for c in (k.C_DOC, k.C_WOB, k.C_TOB, k.C_WF))
    mode = data[:, k.C_MODE]
    sliding = (mode == k.MODE_CUTTING) | (mode == k.MODE_LOST_CONTACT)
    deep, shallow = sliding & (doc >= d_max), sliding & (doc < d_max) & (doc >= 0.0)
    beta = FIG8A.beta
    assert deep.sum() > 1000
    assert tob[deep] == pytest.approx(d_max + beta * w_f[deep] + beta_l * (wob[deep] - d_max
                                                                           - w_f[deep]))
    assert wob[shallow] == pytest.approx(doc[shallow] + w_f[shallow], rel=1e-12)
    assert tob[shallow] == pytest.approx(doc[shallow] + beta * w_f[shallow], rel=1e-12)
    # the limiter stops the advance but does not lift the bit: turning over rock that
    # the blade before left higher, the geometric depth may pass the limit a little
    assert doc.max() < 1.05 * d_max
    rop = (data[-1, k.C_U] - data[0, k.C_U]) / (data[-1, k.C_TAU] - data[0, k.C_TAU])
    per_rev = doc.mean() * data[:, k.C_OMEGA].mean() / (2.0 * math.pi)
    assert rop == pytest.approx(per_rev, rel=0.01)       # eq. 8: delta per revolution
    assert 0.95 * d_max < doc.mean() <= d_max            # RGD07's steady cut: 2 d_max
    assert wob.mean() == pytest.approx(FIG8A.w0, rel=0.02)


@pytest.mark.parametrize("values, words", [
    ({"max_depth_m_per_rev": 0.0}, "max_depth_m_per_rev"),
    ({"max_depth_m_per_rev": 0.02, "mu_gamma": -1.0}, "mu_gamma"),
    ({"mu_gamma": 0.5}, "max_depth_m_per_rev"),
    ({"max_depth_m_per_rev": 0.02, "exposure": 1.0}, "exposure"),
])
def test_a_bad_limit_is_one_line_naming_it(values: dict, words: str) -> None:
    with pytest.raises(ParameterError) as err:
        field(**values)
    assert words in str(err.value) and "\n" not in str(err.value)


def test_without_the_option_the_preset_has_no_limit() -> None:
    law = field().bit_law
    assert law.doc_max == math.inf and law.beta_limit == 0.0
