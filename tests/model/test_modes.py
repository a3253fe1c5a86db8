"""The four bit-rock modes: cutting, lost contact (eq. 31), stick/slip (eqs. 32-33),
off bottom and bit bouncing with the rock re-cut afterwards."""

from __future__ import annotations

import numpy as np
import pytest

from drill_sim_ros.model import analysis as an
from drill_sim_ros.model import kernel as k
from drill_sim_ros.model.params import DimensionlessParams
from drill_sim_ros.model.simulator import SimConfig, Simulator
from tests.model.helpers import FIG8A, run

# Sharp bit, large W0/lam and psi: past the bouncing limit of Figs. 13-14.
BOUNCING = DimensionlessParams(n=6, psi=330.0, beta=0.35, lam=3.2, w0=7.9, omega0=4.65)


def _stick_phases(mode: np.ndarray) -> list[tuple[int, int]]:
    """(first stuck row, first row after) of every complete stick phase."""
    stuck = (mode == k.MODE_STUCK).astype(int)
    edges = np.diff(stuck)
    starts, ends = np.flatnonzero(edges == 1) + 1, np.flatnonzero(edges == -1) + 1
    if ends.size and starts.size and ends[0] < starts[0]:
        ends = ends[1:]
    return list(zip(starts, ends, strict=False))


def test_force_laws_in_cutting_and_lost_contact() -> None:
    """Eqs. (29)-(31): W = delta + W_f, T = delta + beta W_f; W_f = lam when V > 0 and 0
    when V < 0 (the sample's V is the velocity the step ends with, see _wearflat_contact)."""
    _, rows = run(FIG8A, 120.0, every=7, perturb_v=0.01)
    slipping = rows[rows[:, k.C_MODE] != k.MODE_STUCK]
    slipping = slipping[slipping[:, k.C_MODE] != k.MODE_OFF_BOTTOM]
    p = FIG8A
    doc, wf = slipping[:, k.C_DOC], slipping[:, k.C_WF]
    assert np.allclose(slipping[:, k.C_WOB], doc + wf)
    assert np.allclose(slipping[:, k.C_TOB], doc + p.beta * wf)
    assert np.all((wf >= 0.0) & (wf <= p.lam))
    cutting = slipping[:, k.C_MODE] == k.MODE_CUTTING
    assert np.all(wf[cutting] == p.lam)
    assert np.any(wf < p.lam)                 # contact is lost in this limit cycle


def test_contact_is_set_valued_at_zero_velocity_without_chattering() -> None:
    """W0 < lam: the wearflat carries the weight with V = 0 exactly (eq. 31, last line)."""
    p = FIG8A.with_(w0=3.0)
    _, rows = run(p, 20.0, every=1, perturb_v=0.5)     # thrown downwards, then caught
    late = rows[rows[:, k.C_TAU] > 5.0]
    assert np.all(late[:, k.C_V] == 0.0)
    assert np.allclose(late[:, k.C_WF], p.w0 - late[:, k.C_DOC])
    assert np.all(late[:, k.C_WF] <= p.lam)


def test_no_backward_rotation() -> None:
    _, rows = run(FIG8A, 200.0, every=3, perturb_v=0.01)
    assert rows[:, k.C_OMEGA].min() == 0.0


def test_slip_when_pipe_torque_reaches_cutting_plus_friction_torque() -> None:
    """Eqs. (14), (33): the bit stays stuck while PHI_S - PHI <= delta_k + beta lam, slips at
    the first step beyond, and the stick lasts (delta_k + beta lam - T_pipe(k)) / omega0."""
    p, dtau = FIG8A, 1e-4
    _, rows = run(p, 150.0, dtau=dtau, every=1, perturb_v=0.01)
    phases = _stick_phases(rows[:, k.C_MODE])
    assert len(phases) >= 5
    for start, end in phases:
        stuck = rows[start:end]
        threshold = stuck[0, k.C_DOC] + p.beta * p.lam
        assert np.all(stuck[:, k.C_DOC] == stuck[0, k.C_DOC])   # the step in front is fixed
        assert np.all(stuck[:, k.C_T_PIPE] <= threshold)
        assert rows[end, k.C_T_PIPE] > threshold
        predicted = (threshold - rows[start, k.C_T_PIPE]) / p.omega0     # eq. (33)
        duration = rows[end, k.C_TAU] - rows[start, k.C_TAU]
        assert duration == pytest.approx(predicted, abs=1.5 * dtau)
        assert np.all(stuck[:, k.C_V] == 0.0) and np.all(stuck[:, k.C_OMEGA] == 0.0)


def test_slip_follows_a_varying_top_drive_speed() -> None:
    """Generalised eq. (33): with the top drive at a different speed the stick ends when
    the pipe torque, now growing at the new speed, reaches the same threshold."""
    p, dtau = FIG8A, 1e-4
    sim = Simulator(p, SimConfig(dtau=dtau), perturb_v=0.01)
    sim.advance(sim.steps_for(60.0))
    from tests.model.helpers import advance_to_stick_onset
    assert advance_to_stick_onset(sim, 200.0)
    sim.set_inputs(omega_s=2.0 * p.omega0)
    rows = sim.advance(sim.steps_for(5.0), every=1).data
    start, end = 0, int(np.argmax(rows[:, k.C_MODE] != k.MODE_STUCK))
    threshold = rows[start, k.C_DOC] + p.beta * p.lam
    # the first step still runs at the old speed (commands act at the next step)
    predicted = dtau + (threshold - rows[start, k.C_T_PIPE] - p.omega0 * dtau) / (2 * p.omega0)
    assert rows[end, k.C_TAU] - rows[start, k.C_TAU] == pytest.approx(predicted, abs=1.5 * dtau)


def test_bit_bouncing_continues_and_the_rock_is_recut() -> None:
    sim = Simulator(BOUNCING, SimConfig(dtau=5e-5, n_nodes=512), perturb_v=0.01)
    rows = sim.advance(sim.steps_for(6.0), every=1).data
    _, bounce = an.first_event_tau(sim.accumulators)
    assert bounce is not None
    assert np.all(np.isfinite(rows)) and sim.fault is None
    off = rows[:, k.C_MODE] == k.MODE_OFF_BOTTOM
    assert np.all(rows[off, k.C_WOB] == 0.0) and np.all(rows[off, k.C_TOB] == 0.0)
    landed = np.flatnonzero(off[:-1] & ~off[1:]) + 1
    assert landed.size > 0 and np.any(rows[landed[-1]:, k.C_MODE] == k.MODE_CUTTING)
    _assert_profile_is_the_deepest_cut(sim, rows, BOUNCING.n)


def _assert_profile_is_the_deepest_cut(sim: Simulator, rows: np.ndarray, n: int) -> None:
    """Independent path: the rock height at each node is the deepest bit position at which
    any blade passed that angle (max rule), from the recorded trajectory."""
    nodes = sim.profile.size
    spacing = 2 * np.pi / n / nodes
    phi = np.append(rows[:, k.C_PHI], sim.state[k.S_PHI])      # rows are pre-step states
    u = np.append(rows[:, k.C_U], sim.state[k.S_U])
    # node j of the sector sits at angle j * spacing (mod 2 pi / n); crossings of the bit
    crossed = np.floor(phi / spacing)
    expected = np.full(nodes, -np.inf)
    for i in np.flatnonzero(np.diff(crossed) > 0):
        for m in range(int(crossed[i]) + 1, int(crossed[i + 1]) + 1):
            w = (m * spacing - phi[i]) / (phi[i + 1] - phi[i])
            j = m % nodes
            expected[j] = max(expected[j], u[i] + w * (u[i + 1] - u[i]))
    visited = np.isfinite(expected)
    assert visited.all()
    assert np.allclose(sim.profile[visited], expected[visited], rtol=0, atol=1e-9)
