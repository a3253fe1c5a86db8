"""The top drive as an inertia turned by a motor (RGD07 eq. 12 extended), checked against
physics: the stiff speed loop tends to the paper's imposed speed, the free oscillations of
the drive on the string, the energy balance, the torque limit, bumpless mode switches and the
speed loop's anti-windup."""

from __future__ import annotations

import math

import numpy as np
import pytest

from drill_sim_ros.model import analysis as an
from drill_sim_ros.model import kernel as k
from drill_sim_ros.model import top_drive as td
from drill_sim_ros.model.errors import ParameterError
from drill_sim_ros.model.params import RPM_PER_RAD_S, DimensionlessParams
from drill_sim_ros.model.presets import load_preset, preset_from_dict
from drill_sim_ros.model.simulator import SimConfig, Simulator
from drill_sim_ros.model.top_drive import TopDrive, TopDrivePhysical
from tests.model.helpers import FIG8A

FIG11_BASE = DimensionlessParams(n=6, psi=63.0, beta=0.28, lam=5.0, w0=8.5, omega0=4.0)


def _averages(p: DimensionlessParams, drive: TopDrive) -> an.CycleAverages:
    sim = Simulator(p, SimConfig(dtau=1e-4, tau_avg=300.0), perturb_v=0.01, top_drive=drive)
    sim.advance(sim.steps_for(600.0))
    return an.cycle_averages(p, sim.accumulators)


@pytest.mark.parametrize("p", [FIG8A, FIG11_BASE], ids=["fig8a", "fig11"])
def test_a_very_stiff_speed_loop_converges_to_the_kinematic_drive(p: DimensionlessParams
                                                                  ) -> None:
    """Loop bandwidth kp / j = 1400 against the string's 1 (critically damped PI)."""
    j, kp = 14.0, 2.0e4
    stiff = _averages(p, TopDrive(mode="speed", inertia_ratio=j, kp=kp, ki=kp**2 / (4 * j)))
    kinematic = _averages(p, TopDrive(mode="kinematic"))
    assert kinematic.stick_fraction > 0.0
    for name in ("kappa", "mean_torque", "stick_fraction"):
        assert getattr(stiff, name) == pytest.approx(getattr(kinematic, name), rel=1e-2), name


def _crossing_frequency(tau: np.ndarray, signal: np.ndarray) -> float:
    """Angular frequency from the upward zero crossings of ``signal - mean`` (interpolated)."""
    x = signal - signal.mean()
    up = np.flatnonzero((x[:-1] < 0.0) & (x[1:] >= 0.0))
    t_cross = tau[up] - x[up] * (tau[up + 1] - tau[up]) / (x[up + 1] - x[up])
    assert t_cross.size >= 5
    return 2.0 * math.pi * (t_cross.size - 1) / (t_cross[-1] - t_cross[0])


def test_torque_mode_with_the_bit_stuck_oscillates_at_sqrt_c_over_j() -> None:
    """Bit held by the rock (W0 < lam: the twist stays below the slip torque beta lam), the
    motor at a constant torque: j phi_s'' = m - (phi_s - phi) oscillates at sqrt(1/j),
    i.e. sqrt(C/J) in SI."""
    j = 2.0
    p = FIG8A.with_(w0=3.0, omega0=0.2)          # T0 = beta W0 = 0.9 < beta lam = 1.5
    sim = Simulator(p, SimConfig(dtau=1e-3), perturb_omega=-p.omega0,
                    top_drive=TopDrive(mode="torque", inertia_ratio=j))
    rows = sim.advance(sim.steps_for(120.0), every=1).data
    assert np.all(rows[1:, k.C_MODE] == k.MODE_STUCK)
    assert np.all(rows[:, k.C_MOTOR_TORQUE] == an.trivial_solution(p).torque)   # held
    omega = _crossing_frequency(rows[:, k.C_TAU], rows[:, k.C_T_PIPE])
    assert omega == pytest.approx(math.sqrt(1.0 / j), rel=2e-3)


def test_torque_mode_off_bottom_oscillates_at_the_two_inertia_frequency() -> None:
    """No weight, the bit lifted off the rock (T = 0): drive and bit on the spring oscillate
    at sqrt(1 + 1/j), i.e. sqrt(C (1/J + 1/I)) in SI, while both accelerate."""
    j, motor = 3.0, 0.5
    p = FIG8A.with_(w0=0.0, omega0=1.0)
    sim = Simulator(p, SimConfig(dtau=1e-3), perturb_v=-1.0,
                    top_drive=TopDrive(mode="torque", inertia_ratio=j))
    sim.set_inputs(motor_torque=motor)
    rows = sim.advance(sim.steps_for(80.0), every=1).data
    assert np.all(rows[2:, k.C_MODE] == k.MODE_OFF_BOTTOM)
    assert np.all(rows[2:, k.C_TOB] == 0.0) and rows[:, k.C_OMEGA].min() > 0.0
    omega = _crossing_frequency(rows[:, k.C_TAU], rows[:, k.C_T_PIPE])
    assert omega == pytest.approx(math.sqrt(1.0 + 1.0 / j), rel=2e-3)
    assert rows[:, k.C_T_PIPE].mean() == pytest.approx(motor / (1.0 + j), rel=2e-2)


def _energy_residual(dtau: float, tau_end: float) -> tuple[float, float, int]:
    """Torque mode in stick-slip: (motor work - bit-rock dissipation - change of the kinetic
    and spring energy) / motor work, the motor work, and the stuck steps."""
    j = 5.0
    p = FIG8A
    sim = Simulator(p, SimConfig(dtau=dtau), perturb_omega=-3.0,
                    top_drive=TopDrive(mode="torque", inertia_ratio=j))
    total = sim.steps_for(tau_end)
    work = dissipated = 0.0
    stuck = 0
    first = last = None
    for start in range(0, total, 100_000):
        rows = sim.advance(min(100_000, total - start), every=1).data
        if last is not None:
            rows = np.vstack([last, rows])
        first = rows[0] if first is None else first
        w_s, w_b = rows[:, k.C_OMEGA_S], rows[:, k.C_OMEGA]
        work += np.sum(rows[:-1, k.C_MOTOR_TORQUE] * (w_s[:-1] + w_s[1:])) * 0.5 * dtau
        dissipated += np.sum(rows[:-1, k.C_TOB] * (w_b[:-1] + w_b[1:])) * 0.5 * dtau
        stuck += int(np.sum(rows[:-1, k.C_MODE] == k.MODE_STUCK))
        last = rows[-1]

    def energy(r: np.ndarray) -> float:
        return 0.5 * (j * r[k.C_OMEGA_S] ** 2 + r[k.C_OMEGA] ** 2 + r[k.C_T_PIPE] ** 2)
    change = energy(last) - energy(first)
    return (work - dissipated - change) / work, work, stuck


def test_energy_balance_in_torque_mode_closes_as_the_step_shrinks() -> None:
    """Motor work = bit-rock dissipation + change of (drive + bit) kinetic and spring energy,
    to a residual of first order in the step (symplectic Euler, stick included)."""
    coarse, work, stuck = _energy_residual(2e-4, 30.0)
    fine, _, _ = _energy_residual(1e-4, 30.0)
    print(f"energy residual: {coarse:.3e} (dtau 2e-4), {fine:.3e} (1e-4); work {work:.1f}")
    assert stuck > 0 and work > 0.0
    assert abs(coarse) < 1e-5
    assert abs(fine) < 0.7 * abs(coarse)


def test_the_motor_torque_limit_holds() -> None:
    limit = 6.0
    drive = TopDrive(mode="speed", inertia_ratio=14.0, kp=500.0, ki=2000.0, max_torque=limit)
    sim = Simulator(FIG8A, SimConfig(dtau=1e-4), perturb_v=0.01, top_drive=drive)
    sim.advance(sim.steps_for(20.0))
    sim.set_inputs(omega_s=3.0 * FIG8A.omega0)        # a big step: the loop saturates
    rows = sim.advance(sim.steps_for(20.0), every=1).data
    motor = rows[:, k.C_MOTOR_TORQUE]
    assert np.all(np.abs(motor) <= limit) and np.any(motor == limit)
    sim.set_top_drive_mode("torque")
    assert sim.set_motor_torque_nm(2.0 * limit)       # unit scales: N m = torque units
    rows = sim.advance(100, every=1).data
    assert np.all(rows[1:, k.C_MOTOR_TORQUE] == limit)
    assert not sim.set_motor_torque_nm(0.5 * limit)
    sim.set_top_drive(drive.with_(mode="torque", max_torque=0.25 * limit))   # at runtime
    rows = sim.advance(100, every=1).data
    assert np.all(rows[:, k.C_MOTOR_TORQUE] == 0.25 * limit)


def _jump(before: np.ndarray, after: np.ndarray, column: int) -> tuple[float, float]:
    """(largest step-to-step change over the rows before the switch, largest over the two
    steps across it)."""
    typical = np.max(np.abs(np.diff(before[:, column])))
    across = np.max(np.abs(np.diff([before[-1, column], after[0, column], after[1, column]])))
    return typical, across


@pytest.mark.parametrize("sequence", [("speed", "torque", "speed"),
                                      ("kinematic", "speed", "kinematic")])
def test_switching_modes_mid_run_leaves_no_jump(sequence: tuple[str, ...]) -> None:
    """The drive's speed and its motor torque change across a switch no more than from step
    to step anyway, plus what the setpoint ramp itself asks of the loop (kp * rate * dtau
    per step; the setpoint starts at the drive's speed). Without the carried-over integral
    the torque would jump by the whole string torque."""
    kp, rate, dtau = 200.0, 1.0, 1e-4
    drive = TopDrive(mode=sequence[0], inertia_ratio=14.0, kp=kp, ki=1000.0)
    sim = Simulator(FIG8A, SimConfig(dtau=dtau, omega_rate=rate), perturb_v=0.01,
                    top_drive=drive)
    sim.advance(sim.steps_for(30.0))
    for mode in sequence[1:]:
        before = sim.advance(200, every=1).data
        sim.set_top_drive_mode(mode)
        after = sim.advance(200, every=1).data
        assert sim.top_drive_mode == mode
        for column in (k.C_OMEGA_S, k.C_MOTOR_TORQUE):
            typical, across = _jump(before, after, column)
            allowed = 2.0 * typical + 2.0 * kp * rate * dtau
            if mode == "kinematic" and column == k.C_MOTOR_TORQUE:
                # the imposed speed returns to the setpoint at the ramp limit: that takes
                # j * rate more (or less) torque than the string's, at once (eq. 12 extended)
                accel = (after[1, k.C_OMEGA_S] - after[0, k.C_OMEGA_S]) / dtau
                assert abs(accel) == pytest.approx(rate)
                allowed += drive.inertia_ratio * rate * (1.0 + 1e-6)
            assert across <= allowed, (mode, column, typical, across)
        assert abs(before[-1, k.C_MOTOR_TORQUE]) > 10.0 * kp * rate * dtau   # not trivial
        sim.advance(sim.steps_for(10.0))


def test_si_commands_and_readings_use_the_scales_of_the_field_preset() -> None:
    preset = load_preset("field_8p5in_shale_lumped")
    sc = preset.scales
    motorless = preset.top_drive.with_(motor_lag=0.0, max_torque_rate=math.inf)  # m = command
    sim = Simulator(preset.params, SimConfig(dtau=preset.dtau), top_drive=motorless, scales=sc)
    assert sim.top_drive_mode == "speed"
    rpm60 = 2.0 * math.pi
    assert sim.drive_speed_rad_s == pytest.approx(rpm60)            # 60 rpm at the start
    t0_nm = an.trivial_solution(preset.params).torque * sc.torque_nm
    assert sim.string_torque_nm == pytest.approx(t0_nm)
    assert sim.motor_torque_nm == pytest.approx(t0_nm)
    sim.set_speed_setpoint_rad_s(0.5 * rpm60)
    assert sim.targets[0] == pytest.approx(0.5 * rpm60 * sc.time_s)
    sim.set_top_drive_mode("torque")
    sim.set_motor_torque_nm(4000.0)
    sim.advance(1)
    assert sim.motor_torque_nm == pytest.approx(4000.0)
    # J = 2900 kg m^2 referred to I = C t*^2
    assert preset.top_drive.inertia_ratio == pytest.approx(2900.0 / (sc.torque_nm
                                                                      * sc.time_s**2))


def test_preset_top_drive_sections_are_validated_and_scaled() -> None:
    groups = {"n": 6, "beta": 0.3, "lam": 5.0, "psi": 50.0, "w0": 7.0, "omega0": 5.0}
    dimless = {"dimensionless": groups, "top_drive": {"mode": "speed", "kp": 50.0}}
    drive = preset_from_dict("x", dimless).top_drive
    assert (drive.mode, drive.kp) == ("speed", 50.0)
    assert preset_from_dict("x", {"dimensionless": groups}).top_drive.mode == "kinematic"
    with pytest.raises(ParameterError, match="inertia_kg_m2"):   # SI key in scaled units
        preset_from_dict("x", {"dimensionless": groups, "top_drive": {"inertia_kg_m2": 1.0}})
    with pytest.raises(ParameterError, match=r"top_drive\.mode"):
        preset_from_dict("x", {"dimensionless": groups, "top_drive": {"mode": "position"}})
    with pytest.raises(ParameterError, match=r"top_drive\.max_torque"):
        TopDrive(max_torque=0.0)


def test_the_drive_scales_both_ways() -> None:
    preset = load_preset("field_8p5in_shale_lumped")
    si = preset.top_drive.physical(preset.scales)
    assert si.inertia_kg_m2 == pytest.approx(2900.0)
    assert (si.kp_nm_s, si.ki_nm, si.max_torque_nm) == pytest.approx((23200.0, 46400.0, 5e4))
    back = si.scaled(preset.scales)
    assert back.mode == preset.top_drive.mode == "speed"
    for name in ("inertia_ratio", "kp", "ki", "max_torque"):
        assert getattr(back, name) == pytest.approx(getattr(preset.top_drive, name)), name


@pytest.mark.parametrize("mode", ["speed", "torque"])
def test_inertial_drive_runs_are_chunking_invariant_and_resume_bit_for_bit(mode: str) -> None:
    """Lockstep needs the same bytes however the run is cut: one call, many calls, or a
    snapshot restored (the mode travels with the snapshot)."""
    drive = TopDrive(mode=mode, inertia_ratio=14.0, kp=200.0, ki=1000.0, max_torque=8.0)

    def fresh() -> Simulator:
        sim = Simulator(FIG8A, SimConfig(dtau=1e-4), perturb_v=0.01, top_drive=drive)
        sim.set_inputs(motor_torque=3.6)
        return sim
    whole = fresh().advance(60_000, every=10).data
    sim = fresh()
    parts = [sim.advance(n, every=10).data for n in (1, 9_999, 20_000, 30_000)]
    assert np.array_equal(np.vstack(parts), whole)
    sim = fresh()
    sim.advance(25_000)
    snap = sim.snapshot()
    sim.set_top_drive_mode("kinematic")
    sim.advance(5_000)
    sim.restore(snap)
    assert sim.top_drive_mode == mode
    rest = sim.advance(35_000, every=10).data
    assert np.array_equal(rest, whole[2500:])


# ---- the speed loop's anti-windup -------------------------------------------------------
WINDUP_DT_S = 1e-4
WINDUP_DRIVE = TopDrivePhysical()            # the field drive: J, kp, ki, a 50 kN m limit
WINDUP_REF_RAD_S = 120.0 / RPM_PER_RAD_S
DRILLING_NM = 20_000.0                        # the string's torque once it turns


def _speed_loop_step(omega_s: float, integral: float, t_string: float,
                     max_torque_nm: float) -> tuple[float, float]:
    """One step of the drive's own speed loop (SI, no lag, no rate limit, no ramp):
    (omega_s, integral)."""
    d = WINDUP_DRIVE
    omega_next, _, integral, _ = td.drive_step(
        td.TD_SPEED, omega_s, WINDUP_REF_RAD_S, integral, 0.0, t_string, WINDUP_REF_RAD_S,
        0.0, math.inf, d.inertia_kg_m2, d.kp_nm_s, d.ki_nm, max_torque_nm, 1.0, math.inf,
        WINDUP_DT_S)
    return omega_next, integral


def _plain_pi_step(omega_s: float, integral: float, t_string: float,
                   max_torque_nm: float) -> tuple[float, float]:
    """The same PI loop without anti-windup (the output clipped, the integral free)."""
    d = WINDUP_DRIVE
    err = WINDUP_REF_RAD_S - omega_s
    integral += d.ki_nm * err * WINDUP_DT_S
    motor = min(max(d.kp_nm_s * err + integral, -max_torque_nm), max_torque_nm)
    return omega_s + (motor - t_string) / d.inertia_kg_m2 * WINDUP_DT_S, integral


def _stuck_then_free(step, stuck_s: float, free_s: float) -> tuple[np.ndarray, np.ndarray]:
    """The drive at rest, its loop fresh (integral 0), the string stuck: it holds the drive
    with whatever torque the motor applies (so the drive stays at rest) for ``stuck_s``, then
    turns with the drilling torque for ``free_s``. The speed error and the integral after
    the release, one per step."""
    limit = WINDUP_DRIVE.max_torque_nm
    omega, integral = 0.0, 0.0
    for _ in range(round(stuck_s / WINDUP_DT_S)):
        omega, integral = step(omega, integral, limit, limit)    # saturated: motor = limit
    assert omega == 0.0
    errors, integrals = [], []
    for _ in range(round(free_s / WINDUP_DT_S)):
        errors.append(WINDUP_REF_RAD_S - omega)
        integrals.append(integral)
        omega, integral = step(omega, integral, DRILLING_NM, limit)
    return np.array(errors), np.array(integrals)


def _release_with_anti_windup(t_s: np.ndarray) -> np.ndarray:
    """The speed error after the release by physics, for a loop whose integral did not move
    while the motor was saturated (conditional integration): first the motor at its limit M
    against the drilling torque T (the error falls at (M - T) / J), until kp e = M; from
    there the linear loop J e' = -(kp e + x), x' = ki e with x = integral - T = -T. The field
    drive is critically damped (ki = kp^2 / 4J, rate w = kp / 2J), so
    e = (a + b t) exp(-w t), a = M / kp, b = -(M - T) / J + w a."""
    d = WINDUP_DRIVE
    m, j, kp = d.max_torque_nm, d.inertia_kg_m2, d.kp_nm_s
    assert d.ki_nm == pytest.approx(kp**2 / (4.0 * j), rel=1e-12)
    e_edge = m / kp
    t_edge = (WINDUP_REF_RAD_S - e_edge) * j / (m - DRILLING_NM)
    w = kp / (2.0 * j)
    a, b = e_edge, -(m - DRILLING_NM) / j + w * e_edge
    tl = np.maximum(t_s - t_edge, 0.0)
    linear = (a + b * tl) * np.exp(-w * tl)
    return np.where(t_s < t_edge, WINDUP_REF_RAD_S - (m - DRILLING_NM) / j * t_s, linear)


def test_anti_windup_a_stuck_string_leaves_no_windup_for_its_release() -> None:
    """3 s stuck against the full motor torque, then free: with anti-windup the integral
    stays within the torque limit and the release is the physics of a loop that did not
    wind up (no overshoot beyond the linear loop's); a plain PI loop winds up to
    ki wref 3 s (1.7 MN m) and more, and overshoots by more than the whole setpoint."""
    limit = WINDUP_DRIVE.max_torque_nm
    errors, integrals = _stuck_then_free(_speed_loop_step, 3.0, 6.0)
    assert np.all(np.abs(integrals) <= limit)
    t_s = WINDUP_DT_S * np.arange(len(errors))
    expected = _release_with_anti_windup(t_s)
    # within one step's change of the error, (M - T) dt / J = 0.001 rad/s
    np.testing.assert_allclose(errors, expected, rtol=0.0, atol=0.001)
    assert -errors.min() < 0.005                 # the overshoot, rad/s (0.05 rpm)
    assert abs(errors[-1]) < 1e-3                # back on the setpoint
    plain, wound = _stuck_then_free(_plain_pi_step, 3.0, 6.0)
    assert wound.max() > 20.0 * limit and -plain.min() > WINDUP_REF_RAD_S


def test_anti_windup_a_limit_lowered_at_run_time_bounds_the_integral() -> None:
    """Drilling, the integral holds the drilling torque and the drive runs a little below
    its setpoint (the string loading up); the limit drops below that torque (a runtime
    parameter) while the string keeps it: the drive slows, the motor saturates, and the
    integral is held within the new limit, never above it."""
    lower_nm = 0.5 * DRILLING_NM
    omega, integral = WINDUP_REF_RAD_S - 0.1, DRILLING_NM
    for _ in range(round(1.0 / WINDUP_DT_S)):
        omega, integral = _speed_loop_step(omega, integral, DRILLING_NM, lower_nm)
        assert abs(integral) <= lower_nm
    assert omega < WINDUP_REF_RAD_S - 1.0                          # it did saturate
