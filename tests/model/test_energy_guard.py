"""The physics guard (issue 52, point 2): a string that creates energy, or whose energy
balance drifts, stops as a named fault instead of returning numbers.

Per wave line the simulator sums the work done at its top, at the bit, by the wall and by
the dampers (string.balance); the method of characteristics makes the line's stored energy
change by exactly that each wave step, so the balance closes to rounding (a few eps of the
energy moved per wave step: string.call_tolerance). The wall's friction and the dampers only
take energy (limit |w|, c w^2, D w^2 >= 0 for physical values). Here a normal run of every
shipped preset closes its balance within the guard's tolerance, and three bugs stop with a
fault naming the element and the time: a wall whose normal force has the wrong sign, a
negative damper slipped past the loader, and energy written into the waves between runs."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from drill_sim_ros.model import string as sg
from drill_sim_ros.model.errors import EnergyFault, NumericalFault
from drill_sim_ros.model.presets import Preset, available_presets, load_preset
from drill_sim_ros.model.session import SessionConfig, SimSession
from drill_sim_ros.model.simulator import SimConfig, Simulator
from drill_sim_ros.model.string import lines
from drill_sim_ros.model.well import Well
from tests.robust.helpers import one_error_line, run_cli

DEVIATED = "field_8p5in_deviated"
UNWALLED = "field_8p5in_shale"


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


def _simulator(preset: Preset, string: sg.KernelString | None = None) -> Simulator:
    return Simulator(preset.params, SimConfig(dtau=preset.dtau), top_drive=preset.top_drive,
                     scales=preset.scales, string=string or preset.kernel_string,
                     bit_law=preset.bit_law)


def _drift(start: np.ndarray, end: np.ndarray) -> np.ndarray:
    """Per line: stored change - (top work - bit work - wall work - damper work)."""
    d = end - start
    return d[:, sg.B_STORED] - (d[:, sg.B_TOP] - d[:, sg.B_BIT] - d[:, sg.B_WALL]
                                - d[:, sg.B_DAMPER])


@pytest.mark.parametrize("name", available_presets())
def test_every_shipped_preset_closes_its_energy_balance(name: str) -> None:
    """2 s (the paper's presets: tau 20) in calls of 10 ms, the guard checking after each:
    no fault, and over the whole run each line's stored energy changed by the work done on
    it to the guard's tolerance for that many wave steps (the rounding bound, not a
    measured figure). Every term is there: the drive feeds the torsional line, the bit
    takes work from both, the dampers (the wall) take energy where the preset has them.
    RGD07's lumped spring holds no waves: nothing to balance, nothing tracked."""
    preset = load_preset(name)
    sim = _simulator(preset)
    start = sim.energy_balance()
    seconds = 2.0 if preset.physical is not None else 20.0 * preset.scales.time_s
    calls = 200
    per_call = max(1, sim.steps_for(seconds / preset.scales.time_s) // calls)
    for _ in range(calls):
        sim.advance(per_call)
    end = sim.energy_balance()
    assert sim.fault is None
    if not sim.distributed:
        assert not end.any()
        return
    wave_steps = calls * per_call // sim.string.substeps + 1
    scale = start[:, sg.B_STORED] + np.abs(end).sum(axis=1)
    assert np.all(np.abs(_drift(start, end)) <= sg.call_tolerance(wave_steps) * scale)
    assert end[0, sg.B_TOP] > 0.0 and np.all(end[:, sg.B_BIT] > 0.0)
    assert np.all(end[:, sg.B_WALL] >= 0.0) and np.all(end[:, sg.B_DAMPER] >= 0.0)
    damped = [max(line.damper_below) > 0.0 for line in sim.string.lines]
    assert list(end[:, sg.B_DAMPER] > 0.0) == damped
    assert (end[0, sg.B_WALL] > 0.0) == sg.walled(preset.string)


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


def test_a_negative_damper_stops_as_a_named_fault() -> None:
    """One point damper of the torsional line with its sign slipped past the loader's
    checks (in kernel units): it feeds the string D w^2 < 0 every step. The first run stops
    with a fault naming that junction, its depth and the time; the simulator stays faulted
    until reset. (On the code before the balance, nothing watched the dampers: no fault.)"""
    preset = load_preset(UNWALLED)
    string = preset.kernel_string
    torsion = string.lines[0]
    junction = 2
    assert torsion.damper_below[junction] > 0.0
    dampers = list(torsion.damper_below)
    dampers[junction] = -dampers[junction]
    broken = replace(string, lines=(replace(torsion, damper_below=tuple(dampers)),
                                    string.lines[1]))
    sim = _simulator(preset, broken)
    period = sim.steps_for(0.01 / preset.scales.time_s)
    with pytest.raises(EnergyFault) as caught:
        sim.advance(period)
    message = str(caught.value)
    depth_m = sum(torsion.length_m[:junction + 1])
    t_s = period * preset.dtau * preset.scales.time_s
    for part in (f"energy fault at t = {t_s:.6g} s", "the damper at the torsional line's "
                 f"junction {junction} ({depth_m:.1f} m below the top) gave the string",
                 " J ", "negative damping"):
        assert part in message, (part, message)
    assert "\n" not in message
    with pytest.raises(NumericalFault):
        sim.advance(1)
    sim.reset()
    assert sim.fault is None


def test_energy_that_no_element_accounts_for_stops_as_a_drift() -> None:
    """Energy written into the waves between two runs by a holder of the arrays (a bug:
    the scheme's own writes are all accounted) is a drift of the line's balance: the next
    run stops naming the line, the time and the imbalance, its size the energy written
    (a^2 dtau / 4 Z of the slot, to rounding). The arrays handed out by string_arrays before
    the write start the balance again, so an instrument's pulse is no fault."""
    preset = load_preset(UNWALLED)
    sim = _simulator(preset)
    period = sim.steps_for(0.01 / preset.scales.time_s)
    wave, wave_i, wave_f, parts = sim.string_arrays()
    sim.advance(period)
    slot = int(wave_i[sg.W_OFF, parts[0]])            # the axial line's first slot
    z = float(wave_f[sg.W_Z, parts[0]])
    old = float(wave[slot])
    wave[slot] = 1.01 * old                           # +2 % of that slot's energy
    added_j = ((1.01 * old) ** 2 - old**2) * sim.wave_dtau / (4.0 * z) * (
        preset.scales.force_n * preset.scales.length_m)
    with pytest.raises(EnergyFault) as caught:
        sim.advance(period)
    message = str(caught.value)
    assert "the axial line's energy balance is off by " in message, message
    off_j = float(message.split("is off by ")[1].split(" J")[0])
    assert off_j == pytest.approx(added_j, rel=1e-3)
    assert "created energy" in message and "\n" not in message
    sim.reset()
    sim.advance(period)
    sim.string_arrays()[0][slot] *= 1.01             # handed out again: a new start
    sim.advance(period)
    assert sim.fault is None


def test_the_fault_reaches_a_drill_sim_user_as_one_line(
        capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch) -> None:
    """``drill_sim closed-loop`` on a string whose torsional dampers have their sign slipped (in
    the building of its lines, past the loader): exit 2, one ``error:`` line naming the
    energy fault, the damper and the line, no traceback (as sim_node logs it: one line,
    a numerical fault until ~/reset)."""
    build = lines.wave_line

    def slipped(*args: object, **kwargs: object) -> lines.WaveLine:
        line = build(*args, **kwargs)
        axial = args[1] if len(args) > 1 else kwargs["axial"]
        return line if axial else replace(line, damper_below=tuple(-d for d in
                                                                   line.damper_below))

    monkeypatch.setattr(lines, "wave_line", slipped)
    rc, _, err = run_cli(capsys, "closed-loop", "--params", UNWALLED, "--t-end", "1",
                         "--no-baseline")
    one_error_line(rc, err, "energy fault at t = ", "the damper at the torsional line's "
                   "junction 0", "J (a viscous loss can only take energy")
