"""Numerical safety of the kernel: an unstable speed loop is refused with its bound, and a
state that runs away ends as a fault (no loop in the kernel runs without bound)."""

from __future__ import annotations

import pytest

from drill_sim_ros.model.errors import NumericalFault, ParameterError
from drill_sim_ros.model.presets import load_preset
from drill_sim_ros.model.simulator import SimConfig, Simulator
from drill_sim_ros.model.top_drive import TopDrive
from tests.study.helpers import drill_sim

PRESET = load_preset("field_8p5in_shale_lumped")


def test_a_speed_loop_unstable_at_the_step_is_refused_with_its_bound() -> None:
    dtau = 1e-4
    j = PRESET.top_drive.inertia_ratio
    stable = PRESET.top_drive.with_(kp=1.9 * j / dtau, ki=0.0)   # a = 1.9 < 2
    Simulator(PRESET.params, SimConfig(dtau=dtau), top_drive=stable, scales=PRESET.scales)
    unstable = PRESET.top_drive.with_(kp=2.1 * j / dtau, ki=0.0)
    with pytest.raises(ParameterError, match=r"kp dt / J = 2\.1 must be < 2"):
        Simulator(PRESET.params, SimConfig(dtau=dtau), top_drive=unstable,
                  scales=PRESET.scales)
    sim = Simulator(PRESET.params, SimConfig(dtau=dtau), scales=PRESET.scales,
                    top_drive=TopDrive(mode="torque", inertia_ratio=j, kp=2.1 * j / dtau))
    with pytest.raises(ParameterError, match="unstable"):      # switching into speed mode
        sim.set_top_drive_mode("speed")


def test_a_run_away_state_ends_as_a_fault() -> None:
    sim = Simulator(PRESET.params, SimConfig(dtau=1e-4), scales=PRESET.scales)
    sim.set_inputs(omega_s=1e15)                       # kinematic top: the twist explodes
    with pytest.raises(NumericalFault, match=r"runaway|non-finite"):
        sim.advance(10_000)
    assert sim.fault is not None


@pytest.mark.parametrize("preset", [
    ("field_8p5in_shale",),                            # the issue's command exactly
    ("field_8p5in_shale_lumped", "--top-drive", "speed"),
])
def test_the_stiff_drive_of_the_issue_is_one_line(preset: tuple[str, ...]) -> None:
    result = drill_sim("run", "--params", *preset, "--t-end", "1", "--drive-kp", "1e6",
                       "--drive-max-torque-nm", "inf", timeout=120)
    assert result.returncode == 2, result.stderr
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and "kp dt / J" in lines[0] and "Traceback" not in result.stderr
    assert result.stdout == ""


def test_an_integral_gain_too_large_for_any_kp_names_the_ki_bound() -> None:
    """With b = ki dt^2 / J >= 4 no kp is stable; the bound is then on ki: in SI,
    ki_nm < 4 J / dt^2 (J the drive's inertia in kg m^2, dt the step in s)."""
    dtau = 1e-4
    j = PRESET.top_drive.inertia_ratio
    drive = PRESET.top_drive.with_(kp=0.1 * j / dtau, ki=4.1 * j / dtau**2)
    with pytest.raises(ParameterError) as caught:
        Simulator(PRESET.params, SimConfig(dtau=dtau), top_drive=drive, scales=PRESET.scales)
    si = PRESET.top_drive.physical(PRESET.scales)
    dt_s = dtau * PRESET.scales.time_s
    bound = 4.0 * si.inertia_kg_m2 / dt_s**2
    message = str(caught.value)
    assert f"ki_nm < {bound:.6g}" in message and "kp_nm_s <" not in message, message
