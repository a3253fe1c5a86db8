"""The physics guard (issue 52, point 2): a string whose wall creates energy stops as a
named fault instead of returning numbers. The wall's friction only takes energy (each
junction's work grows by limit |w| dtau >= 0 for a wall that presses on the string); a mud
denser than the steel makes the normal force, and so the work, negative. The load checks
refuse such a preset (model.consistency); here the well is changed past them, as a bug
elsewhere could."""

from __future__ import annotations

from dataclasses import replace

import pytest

from drill_sim_ros.model.errors import EnergyFault, NumericalFault
from drill_sim_ros.model.presets import load_preset
from drill_sim_ros.model.session import SessionConfig, SimSession

DEVIATED = "field_8p5in_deviated"


def _session(mud_density_kg_m3: float) -> SimSession:
    preset = load_preset(DEVIATED)
    well = replace(preset.string.well, mud_density_kg_m3=mud_density_kg_m3)
    preset = replace(preset, string=replace(preset.string, well=well))
    return SimSession(SessionConfig(preset=preset, submerged_weight_n=100_000.0))


def test_a_string_lighter_than_the_mud_stops_as_a_named_fault() -> None:
    session = _session(9000.0)                       # steel 7850: the buoyed weight < 0
    with pytest.raises(EnergyFault) as caught:
        session.run(100)                             # 1 s at 100 Hz
    message = str(caught.value)
    assert "\n" not in message
    for part in ("energy fault at t = ", "junction", "m below the top", "gave the string",
                 "lighter than the mud"):
        assert part in message, (part, message)
    with pytest.raises(NumericalFault):               # faulted until reset
        session.run(1)


def test_a_real_well_never_trips_the_guard() -> None:
    session = _session(1200.0)                       # the preset's own mud
    session.run(300)                                 # 3 s: break-away, the wall sliding
    assert session.sim.wall_work() > 0.0
    assert session.sim.fault is None
