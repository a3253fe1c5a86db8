"""The relations between a preset's values that a drilling engineer checks at a glance.

Each value of a preset is checked on its own where it is read (its type and range); these
are the checks that need two of them, run once the preset is built (presets.preset_from_dict,
so a scenario's ``overrides`` pass them too) and, for the operating point sim_node may set
apart from the preset, at sim_node's start:

- every section is denser than the mud (else its buoyed weight is negative: the string
  floats, the wall's friction pushes energy in, the hook load is negative); the mud is the
  well's, or the hook-load estimate's 1200 kg/m^3 without a well. A value below 100 kg/m^3
  for a density is named as the likely g/cm^3-for-kg/m^3 slip;
- a mud lighter than 100 kg/m^3 but not 0 (air) is refused as the same slip;
- no density above 23 000 kg/m^3 (osmium, the densest element, is 22 590);
- every section's outer radius is below the bit's radius (the string follows the bit into
  the hole it cuts);
- the applied WOB does not exceed the string's buoyed weight along the hole (the hook only
  holds weight back; it cannot push the bit);
- the wall's stick band lies below the operating speed (a string turning inside the band
  never slides on the wall: the band is a few tenths of a rad/s around rest).

Inner radius below outer is checked where each section is read (presets._section,
params.validate_physical). Each error is one ParameterError line naming both keys and their
values. ROS-free.
"""

from __future__ import annotations

import math
from typing import Any

from drill_sim_ros.model.errors import ParameterError

MIN_DENSITY_KG_M3 = 100.0        # below: a g/cm^3 value given for kg/m^3 (steel 7.85)
MAX_DENSITY_KG_M3 = 23000.0      # above the densest element (osmium, 22 590 kg/m^3)
DEFAULT_MUD_KEY = "model.presets.MUD_DENSITY_KG_M3"   # the hook load's mud without a well


def _quoted(key: str) -> str:
    """A preset key or parameter in quotes, a flag (``--rpm``) as it is."""
    return key if key.startswith("-") else f"'{key}'"


def _slip_hint(value: float) -> str:
    if 0.0 < value < MIN_DENSITY_KG_M3:
        return (f"; was it given in g/cm3? {value:g} g/cm3 = {value * 1000.0:g} kg/m3 (the "
                "unit is kg/m3)")
    return ""


def check_mud(mud_key: str, mud_kg_m3: float) -> None:
    """The mud: 0 (air) or at least MIN_DENSITY_KG_M3."""
    if 0.0 < mud_kg_m3 < MIN_DENSITY_KG_M3:
        raise ParameterError(f"'{mud_key}' = {mud_kg_m3:g} kg/m3 is lighter than any mud "
                             f"(0 for air, else >= {MIN_DENSITY_KG_M3:g}){_slip_hint(mud_kg_m3)}")


def check_densities(densities: list[tuple[str, float]], mud_key: str,
                    mud_kg_m3: float) -> None:
    """Every ``(key, density)`` of the string denser than the mud, and below the densest
    element."""
    check_mud(mud_key, mud_kg_m3)
    for key, rho in densities:
        if rho > MAX_DENSITY_KG_M3:
            raise ParameterError(f"'{key}' = {rho:g} kg/m3 is denser than any material (at "
                                 f"most {MAX_DENSITY_KG_M3:g}; steel is 7850)")
        if rho <= mud_kg_m3 or rho < MIN_DENSITY_KG_M3:
            raise ParameterError(
                f"'{key}' = {rho:g} kg/m3 must exceed '{mud_key}' = {mud_kg_m3:g} kg/m3 (a "
                f"string lighter than the mud floats: its buoyed weight is negative)"
                f"{_slip_hint(rho)}")


def check_bit_clears(outer_radii: list[tuple[str, float]], bit_radius_m: float) -> None:
    """Every section's outer radius below the bit's (``physical.bit_radius_m``)."""
    for key, radius in outer_radii:
        if radius >= bit_radius_m:
            raise ParameterError(f"'{key}' = {radius:g} m must be smaller than "
                                 f"'physical.bit_radius_m' = {bit_radius_m:g} m (the string "
                                 "follows the bit into the hole it cuts)")


def check_wob_carried(wob_key: str, wob_n: float, weight_n: float) -> None:
    """The applied WOB at most the string's buoyed weight along the hole."""
    if wob_n > weight_n:
        raise ParameterError(f"{_quoted(wob_key)} = {wob_n:g} N exceeds the string's buoyed "
                             f"weight along the hole, {weight_n:.6g} N (the hook only holds "
                             "weight back; it cannot push the bit)")


def check_stick_band(rpm_key: str, rpm: float, band_rad_s: float) -> None:
    """A turning string (rpm > 0) turns faster than the wall's stick band (``rpm_key`` as
    the reader names it: a preset key, a parameter, a flag)."""
    omega_rad_s = rpm * math.pi / 30.0
    if 0.0 < omega_rad_s <= band_rad_s:
        raise ParameterError(f"{_quoted(rpm_key)} = {rpm:g} rpm ({omega_rad_s:.3g} rad/s) "
                             "must exceed 'well.side_friction.stick_speed_rad_s' = "
                             f"{band_rad_s:g} rad/s (inside the stick band the string never "
                             "slides on the wall)")


def section_keys(data: dict[str, Any], count: int, key: str, shorthand: tuple[str, ...]
                 ) -> list[str]:
    """The name under which the preset file gives ``key`` of each of ``count`` sections:
    ``string.sections[i].key`` where the section says it, else the ``physical`` key
    (``shorthand``: the pipe's and the BHA's, or the material's for all)."""
    raw = (data.get("string") or {}).get("sections")
    names = []
    for i in range(count):
        own = isinstance(raw, list) and i < len(raw) and isinstance(raw[i], dict) \
            and key in raw[i]
        fallback = shorthand[min(i, len(shorthand) - 1)]
        names.append(f"string.sections[{i}].{key}" if own else f"physical.{fallback}")
    return names
