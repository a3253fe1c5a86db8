"""Checks of a preset file's raw YAML mapping, before it is turned into a preset.

A preset names every value it sets: an unknown key (a misspelling is the common case) is an
error naming it and the known ones, a physical or dimensionless section must give every
quantity (no silent default), and every value has its type: a number is a YAML number (not
``abc``, not ``true``), an integer is a whole number (``n_blades: 6.5`` is refused, not
truncated). Each error is one :class:`ParameterError` line naming the key, the value and
what is allowed; :func:`read_preset_file` adds the file. The key and number checks shared
with the other readers of input are in :mod:`drill_sim_ros.model.checks`.
"""

from __future__ import annotations

import math
from dataclasses import fields
from pathlib import Path
from typing import Any

import yaml

from drill_sim_ros.model.checks import as_number, check_known_keys, shown
from drill_sim_ros.model.errors import ParameterError
from drill_sim_ros.model.params import DimensionlessParams, PhysicalParams
from drill_sim_ros.model.top_drive import MODES, TopDrive, TopDrivePhysical
from drill_sim_ros.model.yaml_input import load_yaml

PRESET_SECTIONS = ("description", "physical", "dimensionless", "numerics", "top_drive",
                   "string", "well")  # 'string' and 'well': checked by model.presets and
                                      # model.well
# optional mappings in ``physical``: the bit law's (bit_rock.friction_weakening_from_dict,
# bit_rock.depth_of_cut_limit_from_dict)
PHYSICAL_MAPPINGS = ("friction_weakening", "depth_of_cut_limit")
# the lumped string's geometry: given by ``string.sections`` when the preset has them
GEOMETRY_KEYS = ("pipe_outer_radius_m", "pipe_inner_radius_m", "pipe_length_m",
                 "bha_outer_radius_m", "bha_inner_radius_m", "bha_length_m")
INTEGER_KEYS = frozenset({"n", "n_blades", "n_nodes"})
STRING_KEYS = frozenset({"mode"})
NUMERICS_KEYS = ("dtau", "n_nodes")
DTAU_RANGE = (1e-7, 0.1)
N_NODES_RANGE = (16, 1_000_000)


def _names(cls: type) -> tuple[str, ...]:
    return tuple(f.name for f in fields(cls))


def check_value(where: str, key: str, value: Any) -> None:
    """``value`` of ``where.key`` has its key's type: an integer, a string or a number."""
    if key in STRING_KEYS:
        if not isinstance(value, str):
            raise ParameterError(f"'{where}.{key}' = {value!r} must be a string")
        return
    number = as_number(value)
    if number is None:
        raise ParameterError(f"'{where}.{key}' = {value!r} must be a number")
    if not math.isfinite(number) and not (key.startswith("max_torque") and number > 0):
        raise ParameterError(f"'{where}.{key}' = {shown(value)} must be finite")
    if key in INTEGER_KEYS and not number.is_integer():
        raise ParameterError(f"'{where}.{key}' = {value!r} must be a whole number")



def check_section(where: str, values: Any, known: tuple[str, ...], required: bool,
                  optional: tuple[str, ...] = ()) -> None:
    """A mapping of ``known`` keys only (all of them but ``optional`` if ``required``), each
    of its type."""
    if not isinstance(values, dict):
        raise ParameterError(f"'{where}' must be a mapping of {', '.join(known)}; "
                             f"got {values!r}")
    check_known_keys(values, known, where)
    missing = [k for k in known if k not in values and k not in optional]
    if required and missing:
        raise ParameterError(f"'{where}' is missing {', '.join(missing)} (a preset gives "
                             "every quantity; there is no silent default)")
    for key, value in values.items():
        check_value(where, key, value)


def check_no_empty_block(data: dict[str, Any], where: str, keys: tuple[str, ...]) -> None:
    """None of ``keys`` written with nothing under it (``well:`` alone reads as no well,
    which is not what a file that names the block means); one line naming the key."""
    for key in keys:
        if key in data and data[key] is None:
            raise ParameterError(f"'{where}{key}' is empty: give its keys or remove the line "
                                 "(an empty block is not read as its default)")


def check_numerics(values: Any) -> None:
    """``numerics``: dtau in DTAU_RANGE, n_nodes a whole number in N_NODES_RANGE."""
    check_section("numerics", values, NUMERICS_KEYS, required=False)
    for key, (low, high) in (("dtau", DTAU_RANGE), ("n_nodes", N_NODES_RANGE)):
        if key in values and not low <= as_number(values[key]) <= high:
            raise ParameterError(f"'numerics.{key}' = {values[key]!r} is outside the allowed "
                                 f"range [{low:g}, {high:g}]")


def check_preset_mapping(data: Any) -> None:
    """The raw mapping of a preset file (see the module doc); ParameterError if not."""
    if not isinstance(data, dict):
        raise ParameterError(f"a preset file holds a mapping of {', '.join(PRESET_SECTIONS)}; "
                             f"got {data!r}")
    check_known_keys(data, PRESET_SECTIONS)
    check_no_empty_block(data, "", PRESET_SECTIONS[1:])
    for section, keys in (("string", ("sections",)), ("physical", PHYSICAL_MAPPINGS)):
        if isinstance(data.get(section), dict):
            check_no_empty_block(data[section], f"{section}.", keys)
    physical = "physical" in data
    if physical == ("dimensionless" in data):
        raise ParameterError("a preset needs exactly one of 'physical' or 'dimensionless'")
    if physical:
        sections = isinstance(data.get("string"), dict) and "sections" in data["string"]
        values = data["physical"]
        if isinstance(values, dict):        # its mappings: checked by their own readers
            values = {key: v for key, v in values.items() if key not in PHYSICAL_MAPPINGS}
        check_section("physical", values, (*_names(PhysicalParams), *PHYSICAL_MAPPINGS),
                      required=True,
                      optional=(*(GEOMETRY_KEYS if sections else ()), *PHYSICAL_MAPPINGS))
    else:
        check_section("dimensionless", data["dimensionless"], _names(DimensionlessParams),
                      required=True)
    if data.get("numerics") is not None:
        check_numerics(data["numerics"])
    if data.get("top_drive") is not None:
        drive = data["top_drive"]
        check_section("top_drive", drive, _names(TopDrivePhysical if physical else TopDrive),
                      required=False)
        if drive.get("mode", MODES[0]) not in MODES:
            raise ParameterError(f"'top_drive.mode' = {drive['mode']!r} is not one of "
                                 f"{', '.join(MODES)}")


def read_preset_file(path: Path) -> Any:
    """The parsed YAML of the preset file ``path``, read once (checked by
    :func:`check_preset_mapping` where it is built); the error names the file."""
    try:
        return load_yaml(path.read_text())
    except OSError as exc:
        raise ParameterError(f"preset file {path}: {exc.strerror or exc}") from None
    except yaml.YAMLError as exc:
        raise ParameterError(f"preset file {path} is not valid YAML: "
                             f"{' '.join(str(exc).split())}") from None
