"""Named parameter sets (config/presets/*.yaml): the paper's cases and a field case.

A preset file holds ``description``, either ``dimensionless`` (RGD07 groups; the run is
then in units of t* and L*) or ``physical`` (SI; see :class:`PhysicalParams`), optional
``numerics`` (``dtau``, ``n_nodes``), an optional ``top_drive`` (SI keys of
:class:`TopDrivePhysical` in a physical preset, scaled keys of :class:`TopDrive` in a
dimensionless one; absent: the paper's kinematic drive; either way :attr:`Preset.drive` holds
it in SI) and, in a physical preset, an
optional ``string`` (:func:`string_from_dict`: ``lumped``, RGD07's spring, by default, or
``distributed`` sections; without ``sections`` the ``pipe_*`` / ``bha_*`` keys are the
two-section shorthand). ``physical.friction_weakening`` (optional) is the bit law's
(:func:`bit_rock.friction_weakening_from_dict`; absent: RGD07's law) and
``physical.depth_of_cut_limit`` (optional) its depth-of-cut limit
(:func:`bit_rock.depth_of_cut_limit_from_dict`; absent: none), :attr:`Preset.bit_law` both
in kernel units.
"""

from __future__ import annotations

import math
import os
import sys
from dataclasses import MISSING, Field, dataclass, field, fields, replace
from pathlib import Path
from typing import Any

from drill_sim_ros.model.bit_rock import (
    RGD07_LAW,
    BitLaw,
    DepthOfCutLimit,
    FrictionWeakening,
    depth_of_cut_limit_from_dict,
    friction_weakening_from_dict,
)
from drill_sim_ros.model.checks import check_known_keys, number_in
from drill_sim_ros.model.consistency import (
    DEFAULT_MUD_KEY,
    check_bit_clears,
    check_densities,
    check_stick_band,
    check_wob_carried,
    section_keys,
)
from drill_sim_ros.model.errors import ParameterError
from drill_sim_ros.model.formation import Rock
from drill_sim_ros.model.params import (
    UNIT_SCALES,
    DimensionlessParams,
    PhysicalParams,
    Scales,
    dimensionless_from_dict,
    physical_from_dict,
    scale,
    structure,
)
from drill_sim_ros.model.string import (
    STRING_MODELS,
    KernelString,
    Section,
    StringSpec,
    fastest_hook_loop_s,
    kernel_string,
    walled,
)
from drill_sim_ros.model.top_drive import TopDrive, TopDrivePhysical, top_drive_from_dict
from drill_sim_ros.model.validate_input import check_preset_mapping, read_preset_file
from drill_sim_ros.model.well import well_from_dict

DEFAULT_PRESET = "field_8p5in_shale"
GRAVITY_M_S2 = 9.80665
MUD_DENSITY_KG_M3 = 1200.0
PACKAGE = "drill_sim_ros"


@dataclass(frozen=True)
class Preset:
    """A resolved preset: the groups, the scales to SI, the numerical step, the drive and
    the string (both in SI)."""

    name: str
    description: str
    params: DimensionlessParams
    scales: Scales
    physical: PhysicalParams | None
    dtau: float
    n_nodes: int | None
    drive: TopDrivePhysical          # SI (a dimensionless preset: in its unit scales)
    string: StringSpec = field(default_factory=StringSpec)
    friction_weakening: FrictionWeakening | None = None   # None: RGD07's bit law
    depth_of_cut_limit: DepthOfCutLimit | None = None     # None: no limit (RGD07's)

    @property
    def bit_law(self) -> BitLaw:
        """The bit law in kernel units (what the simulator takes): RGD07's, or the
        preset's ``physical.friction_weakening`` scaled, with the preset's
        ``physical.depth_of_cut_limit`` scaled if it has one."""
        law = (RGD07_LAW if self.friction_weakening is None
               else self.friction_weakening.scaled(self.scales.time_s))
        limit, phys = self.depth_of_cut_limit, self.physical
        if limit is None or phys is None:
            return law
        return limit.scaled(law, self.scales.length_m, phys.zeta, phys.mu_gamma)

    @property
    def is_physical(self) -> bool:
        return self.physical is not None

    @property
    def rock(self) -> Rock:
        """The reference rock and bit that formation layers are scaled against."""
        phys = self.physical
        if phys is None:
            raise ParameterError(f"preset '{self.name}' is dimensionless; formation layers "
                                 "are given in SI and need a physical preset")
        return Rock(eps_pa=phys.intrinsic_specific_energy_pa, zeta=phys.zeta,
                    mu_gamma=phys.mu_gamma,
                    sigma_l_n_per_m=phys.contact_stress_times_wearflat_n_per_m,
                    length_m=self.scales.length_m)

    @property
    def top_drive(self) -> TopDrive:
        """The drive in kernel units (what a simulator built directly takes), :attr:`drive`
        converted by :meth:`TopDrivePhysical.scaled`."""
        return self.drive.scaled(self.scales)

    @property
    def kernel_string(self) -> KernelString:
        """The string in kernel units (what the simulator builds its delay lines from)."""
        sc = self.scales
        return kernel_string(self.string, sc.time_s, sc.torque_nm, sc.length_m, sc.force_n,
                             self.dtau * self.string.bit_substeps)


def config_dirs() -> list[Path]:
    """Where config/ may live: $DRILL_SIM_CONFIG_DIR, the source tree, install prefixes."""
    dirs: list[Path] = []
    if os.environ.get("DRILL_SIM_CONFIG_DIR"):
        dirs.append(Path(os.environ["DRILL_SIM_CONFIG_DIR"]))
    dirs.append(Path(__file__).resolve().parents[2] / "config")
    prefixes = [p for p in os.environ.get("AMENT_PREFIX_PATH", "").split(os.pathsep) if p]
    prefixes.append(sys.prefix)
    dirs.extend(Path(p) / "share" / PACKAGE / "config" for p in prefixes)
    return dirs


def preset_path(name_or_path: str) -> Path:
    """Resolve a preset name (``fig5_8a``) or a YAML path to an existing file."""
    candidate = Path(name_or_path)
    if candidate.suffix in (".yaml", ".yml") and candidate.exists():
        return candidate
    for base in config_dirs():
        path = base / "presets" / f"{name_or_path}.yaml"
        if path.exists():
            return path
    raise ParameterError(f"preset '{name_or_path}' not found; known presets: "
                         f"{', '.join(available_presets()) or 'none'}")


def available_presets() -> list[str]:
    """Names of the presets found in the first config directory that has any."""
    for base in config_dirs():
        found = sorted(p.stem for p in (base / "presets").glob("*.yaml"))
        if found:
            return found
    return []


def preset_from_dict(name: str, data: dict[str, Any], base_dir: Path | None = None) -> Preset:
    """Build a :class:`Preset` from a parsed preset mapping (files it names, such as a
    well's survey CSV, relative to ``base_dir``)."""
    if not isinstance(data, dict):
        raise ParameterError(f"preset '{name}' must be a mapping")
    check_preset_mapping(data)                # unknown, missing and mistyped keys, one line
    numerics = data.get("numerics") or {}
    has_phys, has_dimless = "physical" in data, "dimensionless" in data
    if has_phys == has_dimless:
        raise ParameterError(f"preset '{name}' needs exactly one of 'physical' or "
                             "'dimensionless'")
    physical, string, weakening, limit = None, StringSpec(), None, None
    if has_phys:
        values = dict(data["physical"])
        weakening = friction_weakening_from_dict(values.pop("friction_weakening", None))
        limit = depth_of_cut_limit_from_dict(values.pop("depth_of_cut_limit", None))
        physical = physical_from_dict(values)
        string = string_from_dict(data.get("string") or {}, physical)
        shorthand = sorted(key for key in data["physical"] if key.startswith(("pipe_", "bha_")))
        if shorthand and (data.get("string") or {}).get("sections") is not None:
            raise ParameterError(f"preset '{name}': physical {', '.join(shorthand)} would be "
                                 "ignored: string.sections defines the string (give one)")
        params, scales = scale(physical, string)
        string = _with_well(name, data, string, base_dir)
    else:
        for key in ("string", "well"):
            if key in data:
                raise ParameterError(f"preset '{name}': '{key}' needs a 'physical' preset (a "
                                     "dimensionless one is RGD07's lumped string)")
        params, scales = dimensionless_from_dict(data["dimensionless"]), UNIT_SCALES
    n_nodes = numerics.get("n_nodes")
    section = data.get("top_drive")
    drive = top_drive_from_dict(section, scales, has_phys)    # SI, as the file gives it
    preset = Preset(name=name, description=str(data.get("description", "")).strip(),
                    params=params, scales=scales, physical=physical,
                    dtau=float(numerics.get("dtau", 1e-4)),
                    n_nodes=None if n_nodes is None else int(n_nodes), drive=drive,
                    string=string, friction_weakening=weakening, depth_of_cut_limit=limit)
    if physical is not None:
        check_consistency(preset, data)
    return preset


def check_consistency(preset: Preset, data: dict[str, Any]) -> None:
    """The relations between the values of the physical ``preset`` built from ``data``
    (model.consistency), each error naming the keys as the file gives them."""
    phys = preset.physical
    assert phys is not None
    well = preset.string.well
    sections = preset.string.sections
    if sections:
        rho = [s.density_kg_m3 for s in sections]
        radii = [s.outer_radius_m for s in sections]
    else:                                          # RGD07's lumped pipe and BHA
        rho = [phys.density_kg_m3] * 2
        radii = [phys.pipe_outer_radius_m, phys.bha_outer_radius_m]
    n = len(rho)
    mud_key = "well.mud_density_kg_m3" if well is not None else DEFAULT_MUD_KEY
    mud = well.mud_density_kg_m3 if well is not None else MUD_DENSITY_KG_M3
    check_densities(list(zip(section_keys(data, n, "density_kg_m3", ("density_kg_m3",)), rho,
                             strict=True)), mud_key, mud)
    outer = section_keys(data, n, "outer_radius_m", ("pipe_outer_radius_m",
                                                     "bha_outer_radius_m"))
    check_bit_clears(list(zip(outer, radii, strict=True)), phys.bit_radius_m)
    check_wob_carried("physical.applied_wob_n", phys.applied_wob_n,
                      submerged_string_weight_n(preset))
    if well is not None and well.has_friction:
        check_stick_band("physical.surface_rpm", phys.surface_rpm,
                         well.side_friction.stick_speed_rad_s)
    elif well is not None:
        friction = data["well"].get("side_friction") or {}
        if "stick_speed_rad_s" in friction:
            raise ParameterError("'well.side_friction.stick_speed_rad_s' = "
                                 f"{friction['stick_speed_rad_s']!r} has no effect: the wall "
                                 "has no friction (give static and dynamic, or drop it)")


def _with_well(name: str, data: dict[str, Any], string: StringSpec,
               base_dir: Path | None) -> StringSpec:
    """``string`` in the preset's ``well`` (model.well), which needs the distributed string
    (the wall holds the string along its length); no ``well``: a vertical hole."""
    if data.get("well") is None:
        return string
    if not string.distributed:
        raise ParameterError(f"preset '{name}': 'well' needs string.model: distributed (the "
                             "wall's friction acts along the string)")
    spec = replace(string, well=well_from_dict(data["well"], base_dir))
    if walled(spec) and "damping_points" in data.get("string", {}):
        raise ParameterError(
            f"preset '{name}': 'string.damping_points' lumps the damping of a string without "
            "wall friction; in a well with side friction every cell of the wave guide "
            "carries its damping and friction (the resolution: numerics.dtau x "
            "string.bit_substeps): remove the key")
    return spec


SECTION_FIELDS = {f.name: f for f in fields(Section)}
SECTION_REQUIRED = tuple(name for name, f in SECTION_FIELDS.items() if f.default is MISSING)
# a ``string`` block's keys: the spec's own, and the sections' damping (their default)
STRING_DEFAULTED = ("torsional_damping_per_s", "axial_damping_per_s")
STRING_FIELDS = {f.name: f for f in fields(StringSpec)}
STRING_KEYS = (*(key for key in STRING_FIELDS if key != "well"), *STRING_DEFAULTED)


def _number(where: str, key: str, value: Any, low: float, high: float,
            low_open: bool = False) -> float:
    """A float in range, or ParameterError naming ``where.key``, the value and the range
    (a YAML number, as the shared checks read one: not ``true``, not ``abc``)."""
    return number_in(f"'{where}.{key}'", value, low, high, low_open)


def _field_value(where: str, key: str, value: Any, f: Field) -> float:
    """``value`` checked against the range in the field's metadata (model.string)."""
    return _number(where, key, value, *f.metadata["range"])


def _section(where: str, values: Any, defaults: dict[str, float]) -> Section:
    """One section mapping (SI keys of :class:`Section`), checked; ``defaults`` (already
    checked) fill the keys it does not give."""
    if not isinstance(values, dict):
        raise ParameterError(f"'{where}' must be a mapping of {', '.join(SECTION_REQUIRED)}")
    check_known_keys(values, tuple(SECTION_FIELDS), where)
    missing = [key for key in SECTION_REQUIRED if key not in values]
    if missing:
        raise ParameterError(f"'{where}' needs {', '.join(missing)}")
    given = {key: _field_value(where, key, v, SECTION_FIELDS[key]) for key, v in values.items()}
    x = {**defaults, **given}
    if x["inner_radius_m"] >= x["outer_radius_m"]:
        raise ParameterError(f"'{where}.inner_radius_m' = {x['inner_radius_m']!r} must be "
                             f"smaller than outer_radius_m = {x['outer_radius_m']!r}")
    return Section(**x)


def _section_defaults(values: dict[str, Any], phys: PhysicalParams) -> dict[str, float]:
    """What a section does not give: the ``physical`` material, the string's damping."""
    damping = {key: _field_value("string", key, values[key], SECTION_FIELDS[key])
               for key in STRING_DEFAULTED if key in values}
    return {"density_kg_m3": phys.density_kg_m3, "shear_modulus_pa": phys.shear_modulus_pa,
            "youngs_modulus_pa": phys.youngs_modulus_pa, **damping}


def _raw_sections(values: dict[str, Any], phys: PhysicalParams) -> list[Any]:
    """The ``sections`` list, or the two-section shorthand of the ``physical`` geometry."""
    raw = values.get("sections")
    if raw is None:
        return [{"outer_radius_m": phys.pipe_outer_radius_m,
                 "inner_radius_m": phys.pipe_inner_radius_m, "length_m": phys.pipe_length_m},
                {"outer_radius_m": phys.bha_outer_radius_m,
                 "inner_radius_m": phys.bha_inner_radius_m, "length_m": phys.bha_length_m}]
    if not isinstance(raw, list) or len(raw) < 2:
        raise ParameterError("'string.sections' must be a list of at least 2 sections, top "
                             "to bottom (the bottom one is the BHA)")
    return raw


def _spec_scalars(values: dict[str, Any]) -> dict[str, float | int]:
    """The string block's own numbers (the :class:`StringSpec` fields with a range),
    checked."""
    out: dict[str, float | int] = {key: _field_value("string", key, values[key], f)
                                   for key, f in STRING_FIELDS.items()
                                   if "range" in f.metadata and key in values}
    for key in ("damping_points", "bit_substeps"):
        if key in out:
            if out[key] != int(out[key]):
                raise ParameterError(f"'string.{key}' = {values[key]!r} must be an integer")
            out[key] = int(out[key])
    return out


def string_from_dict(values: Any, phys: PhysicalParams) -> StringSpec:
    """A physical preset's ``string`` mapping (see the module doc); the material defaults
    are the ``physical`` ones, the damping defaults the string's own keys."""
    if not isinstance(values, dict):
        raise ParameterError("'string' must be a mapping (model, sections, ...)")
    check_known_keys(values, STRING_KEYS, "string")
    model = values.get("model", "lumped")
    if model not in STRING_MODELS:
        raise ParameterError(f"'string.model' = {model!r} must be one of {STRING_MODELS}")
    defaults = _section_defaults(values, phys)
    sections = tuple(_section(f"string.sections[{i}]", sec, defaults)
                     for i, sec in enumerate(_raw_sections(values, phys)))
    spec = StringSpec(model=model, sections=sections, **_spec_scalars(values))
    if not spec.distributed and values.get("sections") is None:
        return StringSpec()                  # RGD07's lumped string of pipe_* / bha_*
    fastest_s = fastest_hook_loop_s(spec) if spec.distributed else 0.0
    if spec.hook_wob_time_s <= fastest_s:
        raise ParameterError(
            f"'string.hook_wob_time_s' = {spec.hook_wob_time_s:g} s must be longer than "
            f"{fastest_s:.3g} s on this string (about twice that without "
            "axial losses): a faster hook loop pushes the axial wave guide harder than it "
            "answers (gain 2 Z_top x compliance / hook_wob_time_s above 1) and runs away")
    return spec


def read_preset_data(path: Path) -> dict[str, Any]:
    """The mapping of the preset file ``path``, with the file it may name (a well's survey
    CSV, relative to the preset's directory) made absolute: it then builds by
    :func:`preset_from_dict` from any working directory, without ``base_dir`` (the fit's
    replays and a scenario's overrides build it from the mapping)."""
    data = read_preset_file(path)
    well = data.get("well") if isinstance(data, dict) else None
    survey = well.get("survey") if isinstance(well, dict) else None
    if isinstance(survey, str) and survey:
        named = Path(survey).expanduser()
        well["survey"] = str(named if named.is_absolute() else path.parent / named)
    return data


def load_preset(name_or_path: Any = DEFAULT_PRESET) -> Preset:
    """Load a preset by name or path, its file read once; each error is one line naming the
    file and the bad key."""
    if not isinstance(name_or_path, str) or not name_or_path:
        raise ParameterError(f"preset = {name_or_path!r} must be a preset name or a YAML path")
    path = preset_path(name_or_path)
    data = read_preset_file(path)
    try:
        return preset_from_dict(path.stem, data, path.parent)
    except ParameterError as exc:
        raise ParameterError(f"preset file {path}: {exc}") from None


def submerged_string_weight_n(preset: Preset | None,
                              mud_density_kg_m3: float | None = None) -> float:
    """Buoyed weight of pipe + BHA: steel mass x g x (1 - rho_mud / rho_steel); 0 if none
    (the mud ``MUD_DENSITY_KG_M3`` unless given). In a preset's well: the weight along the
    hole's axis in its own mud (:meth:`Well.hanging_weight_n`), the wall carrying the rest."""
    if preset is None or preset.physical is None:
        return 0.0
    well = preset.string.well
    if well is not None and mud_density_kg_m3 is None:
        return well.hanging_weight_n(preset.string.sections)
    if mud_density_kg_m3 is None:
        mud_density_kg_m3 = MUD_DENSITY_KG_M3
    phys = preset.physical
    if preset.string.sections:
        return sum(s.mass_kg * GRAVITY_M_S2 * (1.0 - mud_density_kg_m3 / s.density_kg_m3)
                   for s in preset.string.sections)
    pipe_m3 = math.pi * (phys.pipe_outer_radius_m**2 - phys.pipe_inner_radius_m**2) \
        * phys.pipe_length_m
    mass_kg = pipe_m3 * phys.density_kg_m3 + structure(phys).mass_kg
    return mass_kg * GRAVITY_M_S2 * (1.0 - mud_density_kg_m3 / phys.density_kg_m3)
