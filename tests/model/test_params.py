"""Physical <-> dimensionless parameters (eqs. 1, 19-24), presets, and input validation."""

from __future__ import annotations

import math
from pathlib import Path

import pytest
import yaml

from drill_sim_ros.model.errors import ParameterError
from drill_sim_ros.model.params import (
    DimensionlessParams,
    PhysicalParams,
    physical_from_dict,
    scale,
    structure,
    unscale,
)
from drill_sim_ros.model.presets import available_presets, load_preset, string_from_dict

STEEL = 7850.0


def test_structure_eq1_by_hand() -> None:
    """A solid pipe and a solid BHA make the polar moments easy to check by hand."""
    p = PhysicalParams(pipe_outer_radius_m=0.05, pipe_inner_radius_m=0.0, pipe_length_m=1000.0,
                       bha_outer_radius_m=0.1, bha_inner_radius_m=0.0, bha_length_m=100.0,
                       density_kg_m3=STEEL, shear_modulus_pa=80e9)
    s = structure(p)
    j_p, j_b = math.pi / 2 * 0.05**4, math.pi / 2 * 0.1**4
    assert s.mass_kg == pytest.approx(STEEL * math.pi * 0.01 * 100.0)
    assert s.inertia_kg_m2 == pytest.approx(STEEL * (j_b * 100.0 + j_p * 1000.0 / 3.0))
    assert s.stiffness_nm_per_rad == pytest.approx(80e9 * j_p / 1000.0)


def test_scaling_eqs_19_to_24() -> None:
    p = PhysicalParams()
    g, sc = scale(p)
    s = structure(p)
    eps, zeta, a = p.intrinsic_specific_energy_pa, p.zeta, p.bit_radius_m
    assert sc.time_s == pytest.approx(math.sqrt(s.inertia_kg_m2 / s.stiffness_nm_per_rad))
    assert sc.length_m == pytest.approx(2 * s.stiffness_nm_per_rad / (eps * a * a))
    assert g.beta == pytest.approx(p.mu_gamma * zeta)
    assert g.psi == pytest.approx(zeta * eps * a * s.inertia_kg_m2
                                  / (s.mass_kg * s.stiffness_nm_per_rad))
    assert g.lam == pytest.approx(p.contact_stress_times_wearflat_n_per_m
                                  / (zeta * eps * sc.length_m))
    assert g.w0 == pytest.approx(p.applied_wob_n / (zeta * eps * a * sc.length_m))
    assert g.omega0 == pytest.approx(p.surface_rpm * 2 * math.pi / 60 * sc.time_s)
    # the trivial torque in SI equals eq. (18): T0 = T_f + a (W0 - W_f) / (2 zeta)
    from drill_sim_ros.model.analysis import trivial_solution
    w_f = a * p.contact_stress_times_wearflat_n_per_m
    t0_si = a * p.mu_gamma * w_f / 2 + a * (p.applied_wob_n - w_f) / (2 * zeta)
    assert sc.tob_nm(trivial_solution(g).torque) == pytest.approx(t0_si)


def test_round_trip_physical_dimensionless_physical() -> None:
    base = PhysicalParams()
    g, _ = scale(base)
    again = unscale(g, base)
    for name in ("mu_gamma", "contact_stress_times_wearflat_n_per_m", "applied_wob_n",
                 "surface_rpm"):
        assert getattr(again, name) == pytest.approx(getattr(base, name), rel=1e-12)
    changed = g.with_(beta=0.5, lam=2.0, w0=4.0, omega0=3.0)
    g2, _ = scale(unscale(changed, base))
    for name in ("beta", "lam", "w0", "omega0", "psi"):
        assert getattr(g2, name) == pytest.approx(getattr(changed, name), rel=1e-12)


def test_unscale_refuses_a_psi_the_structure_cannot_have() -> None:
    g, _ = scale(PhysicalParams())
    with pytest.raises(ParameterError, match="psi"):
        unscale(g.with_(psi=g.psi * 2), PhysicalParams())


@pytest.mark.parametrize(("field", "value"), [
    ("beta", -0.1), ("lam", float("nan")), ("psi", 0.0), ("w0", float("inf")),
    ("omega0", -1.0), ("n", 0), ("n", 2.5),
])
def test_bad_dimensionless_parameter_is_named(field: str, value: float) -> None:
    with pytest.raises(ParameterError, match=f"'{field}'"):
        DimensionlessParams(**{field: value})


@pytest.mark.parametrize(("field", "value"), [
    ("pipe_length_m", 0.0), ("bit_radius_m", -0.1), ("applied_wob_n", -5.0),
    ("pipe_inner_radius_m", 0.07), ("surface_rpm", float("nan")),
])
def test_bad_physical_parameter_is_named(field: str, value: float) -> None:
    with pytest.raises(ParameterError, match=f"'{field}'"):
        PhysicalParams(**{field: value})


def test_unknown_keys_are_named() -> None:
    with pytest.raises(ParameterError, match="bit_radius_in"):
        physical_from_dict({"bit_radius_in": 4.25})


def test_every_preset_loads_and_the_paper_cases_match_their_figures() -> None:
    names = available_presets()
    assert {"fig5_8a", "fig8b", "fig9", "fig10", "fig11", "fig12", "fig13", "fig14",
            "field_8p5in_shale_lumped"} <= set(names)
    for name in names:
        load_preset(name)
    fig8a = load_preset("fig5_8a").params
    assert (fig8a.n, fig8a.psi, fig8a.beta, fig8a.lam, fig8a.w0, fig8a.omega0) == \
        (6, 50.0, 0.3, 5.0, 7.0, 5.0)


def test_field_preset_is_realistic() -> None:
    """Appendix A: 8.5-in bit, eps ~ 230 MPa, mu gamma ~ 0.48, beta ~ 0.35; psi of order
    1e2-1e3 (Sec. 3.1); t* ~ 1 s and L* ~ 1 mm."""
    pr = load_preset("field_8p5in_shale_lumped")
    assert pr.physical is not None
    assert pr.physical.bit_radius_m == pytest.approx(8.5 * 0.0254 / 2, rel=0.01)
    assert pr.params.beta == pytest.approx(0.35, abs=0.01)
    assert 100 <= pr.params.psi <= 1000
    assert 0.1 < pr.scales.time_s < 3.0 and 1e-5 < pr.scales.length_m < 1e-2


def test_missing_preset_lists_the_known_ones() -> None:
    with pytest.raises(ParameterError, match="fig5_8a"):
        load_preset("no_such_case")


def test_a_preset_file_is_parsed_once(monkeypatch: pytest.MonkeyPatch) -> None:
    """load_preset reads and checks the YAML once, then builds from that mapping."""
    calls: list[str] = []
    load = yaml.load                        # what model.yaml_input.load_yaml calls

    def counting(text: str, **kwargs: object) -> object:
        calls.append(text)
        return load(text, **kwargs)

    monkeypatch.setattr(yaml, "load", counting)
    load_preset("field_8p5in_shale")
    assert len(calls) == 1


@pytest.mark.parametrize(("name", "words"), [
    (5, ("preset = 5", "preset name or a YAML path")),
    ("", ("preset = ''",)),
])
def test_a_preset_that_is_not_a_name_is_one_line(name: object, words: tuple[str, ...]) -> None:
    with pytest.raises(ParameterError) as caught:
        load_preset(name)
    assert "\n" not in str(caught.value)
    for word in words:
        assert word in str(caught.value)


def test_a_preset_file_that_is_not_yaml_is_one_line_naming_it(tmp_path: Path) -> None:
    path = tmp_path / "broken.yaml"
    path.write_text("physical: [1,\n  2\n")
    with pytest.raises(ParameterError) as caught:
        load_preset(str(path))
    message = str(caught.value)
    assert "\n" not in message and f"preset file {path} is not valid YAML" in message


def test_a_string_value_that_is_not_a_yaml_number_is_one_line() -> None:
    """The string block reads numbers as the shared checks do: ``true`` is not 1.0."""
    phys = load_preset("field_8p5in_shale").physical
    section = {"outer_radius_m": 0.06, "inner_radius_m": 0.05, "length_m": 100.0}
    with pytest.raises(ParameterError, match=r"string.bit_inertia_kg_m2' = True"):
        string_from_dict({"model": "distributed", "sections": [section, section],
                          "bit_inertia_kg_m2": True}, phys)
    spec = string_from_dict({"model": "distributed", "sections": [section, section],
                             "bit_inertia_kg_m2": "2.5e1"}, phys)
    assert spec.bit_inertia_kg_m2 == 25.0
