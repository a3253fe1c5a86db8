"""The physics guard (issue 52, point 2): a string whose wall creates energy stops as a
named fault instead of returning numbers. The wall's friction only takes energy (each
junction's work grows by limit |w| dtau >= 0 for a wall that presses on the string); a mud
denser than the steel once made the normal force, and so the work, negative; the load checks
refuse such a preset (model.consistency) and the soft-string normal force is a norm, never
negative. So here a well whose normal force has the wrong sign stands for a bug upstream."""

from __future__ import annotations

from dataclasses import replace

import pytest

from drill_sim_ros.model.errors import EnergyFault, NumericalFault
from drill_sim_ros.model.presets import load_preset
from drill_sim_ros.model.session import SessionConfig, SimSession
from drill_sim_ros.model.well import Well

DEVIATED = "field_8p5in_deviated"


class _SignSlippedWell(Well):
    """The preset's well with its normal force's sign slipped (a bug, not a physics)."""

    def string_normal_force_n(self, *args: object, **kwargs: object) -> object:
        return -super().string_normal_force_n(*args, **kwargs)


def _session(broken: bool) -> SimSession:
    preset = load_preset(DEVIATED)
    well = preset.string.well
    if broken:
        well = _SignSlippedWell(well.survey, well.mud_density_kg_m3, well.side_friction)
    preset = replace(preset, string=replace(preset.string, well=well))
    return SimSession(SessionConfig(preset=preset, dtau_max=preset.dtau,
                                    submerged_weight_n=100_000.0))


def test_a_wall_that_gives_energy_stops_as_a_named_fault() -> None:
    session = _session(broken=True)
    with pytest.raises(EnergyFault) as caught:
        session.run(100)                             # 1 s at 100 Hz
    message = str(caught.value)
    assert "\n" not in message
    for part in ("energy fault at t = ", "junction", "m below the top", "gave the string",
                 "negative normal force"):
        assert part in message, (part, message)
    with pytest.raises(NumericalFault):               # faulted until reset
        session.run(1)


def test_a_real_well_never_trips_the_guard() -> None:
    session = _session(broken=False)
    session.run(300)                                 # 3 s: break-away, the wall sliding
    assert session.sim.wall_work() > 0.0
    assert session.sim.fault is None
