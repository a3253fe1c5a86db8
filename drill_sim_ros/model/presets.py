"""Named parameter sets (config/presets/*.yaml): the paper's cases and a field case.

A preset file holds ``description``, either ``dimensionless`` (RGD07 groups; the run is
then in units of t* and L*) or ``physical`` (SI; see :class:`PhysicalParams`), optional
``numerics`` (``dtau``, ``n_nodes``) and an optional ``top_drive`` (SI keys of
:class:`TopDrivePhysical` in a physical preset, scaled keys of :class:`TopDrive` in a
dimensionless one; absent: the paper's kinematic drive).
"""

from __future__ import annotations

import math
import os
import sys
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import yaml

from drill_sim_ros.model.errors import ParameterError
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
from drill_sim_ros.model.top_drive import TopDrive, top_drive_from_dict

DEFAULT_PRESET = "field_8p5in_shale"
GRAVITY_M_S2 = 9.80665
MUD_DENSITY_KG_M3 = 1200.0
PACKAGE = "drill_sim_ros"


@dataclass(frozen=True)
class Preset:
    """A resolved preset: the groups, the scales to SI, and the numerical step."""

    name: str
    description: str
    params: DimensionlessParams
    scales: Scales
    physical: PhysicalParams | None
    dtau: float
    n_nodes: int | None
    top_drive: TopDrive = field(default_factory=TopDrive)

    @property
    def is_physical(self) -> bool:
        return self.physical is not None


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


def preset_from_dict(name: str, data: dict[str, Any]) -> Preset:
    """Build a :class:`Preset` from a parsed preset mapping."""
    if not isinstance(data, dict):
        raise ParameterError(f"preset '{name}' must be a mapping")
    numerics = data.get("numerics") or {}
    has_phys, has_dimless = "physical" in data, "dimensionless" in data
    if has_phys == has_dimless:
        raise ParameterError(f"preset '{name}' needs exactly one of 'physical' or "
                             "'dimensionless'")
    physical = None
    if has_phys:
        physical = physical_from_dict(data["physical"])
        params, scales = scale(physical)
    else:
        params, scales = dimensionless_from_dict(data["dimensionless"]), UNIT_SCALES
    n_nodes = numerics.get("n_nodes")
    drive = data.get("top_drive")
    top_drive = TopDrive() if drive is None else top_drive_from_dict(drive, scales, has_phys)
    return Preset(name=name, description=str(data.get("description", "")).strip(),
                  params=params, scales=scales, physical=physical,
                  dtau=float(numerics.get("dtau", 1e-4)),
                  n_nodes=None if n_nodes is None else int(n_nodes), top_drive=top_drive)


def load_preset(name_or_path: str = DEFAULT_PRESET) -> Preset:
    """Load a preset by name or path; errors name the file and the bad key."""
    path = preset_path(name_or_path)
    try:
        data = yaml.safe_load(path.read_text())
    except yaml.YAMLError as exc:
        raise ParameterError(f"preset file {path} is not valid YAML: {exc}") from exc
    try:
        return preset_from_dict(path.stem, data)
    except ParameterError as exc:
        raise ParameterError(f"{path}: {exc}") from exc


def submerged_string_weight_n(preset: Preset | None,
                              mud_density_kg_m3: float = MUD_DENSITY_KG_M3) -> float:
    """Buoyed weight of pipe + BHA: steel mass x g x (1 - rho_mud / rho_steel); 0 if none."""
    if preset is None or preset.physical is None:
        return 0.0
    phys = preset.physical
    pipe_m3 = math.pi * (phys.pipe_outer_radius_m**2 - phys.pipe_inner_radius_m**2) \
        * phys.pipe_length_m
    mass_kg = pipe_m3 * phys.density_kg_m3 + structure(phys).mass_kg
    return mass_kg * GRAVITY_M_S2 * (1.0 - mud_density_kg_m3 / phys.density_kg_m3)
