"""Surface inputs: setpoints at the next step, ramp limits, validation."""

from __future__ import annotations

import numpy as np
import pytest

from drill_sim_ros.model import kernel as k
from drill_sim_ros.model.errors import NumericalFault, ParameterError
from drill_sim_ros.model.simulator import SimConfig, Simulator
from tests.model.helpers import FIG8B


def test_ramp_limits_bound_the_surface_rates() -> None:
    rate = 2.0
    sim = Simulator(FIG8B, SimConfig(dtau=1e-3, omega_rate=rate, w_rate=rate))
    sim.set_inputs(omega_s=FIG8B.omega0 + 3.0, w_app=FIG8B.w0 - 1.0)
    rows = sim.advance(3000, every=1).data
    tau = rows[:, k.C_TAU]
    # the command acts from the step after it was given: omega_s(tau) = omega0 + rate * tau
    expected_omega = np.minimum(FIG8B.omega0 + rate * tau, FIG8B.omega0 + 3.0)
    expected_w = np.maximum(FIG8B.w0 - rate * tau, FIG8B.w0 - 1.0)
    assert np.allclose(rows[:, k.C_OMEGA_S], expected_omega, atol=1e-9)
    assert np.allclose(rows[:, k.C_W_APP], expected_w, atol=1e-9)


def test_commands_act_at_the_next_step_without_ramp() -> None:
    sim = Simulator(FIG8B, SimConfig(dtau=1e-3))
    sim.set_inputs(omega_s=1.0)
    rows = sim.advance(2, every=1).data
    assert rows[0, k.C_OMEGA_S] == FIG8B.omega0 and rows[1, k.C_OMEGA_S] == 1.0


@pytest.mark.parametrize(("name", "value"), [("omega_s", float("nan")), ("w_app", -1.0),
                                             ("omega_s", float("inf"))])
def test_bad_inputs_are_rejected_and_named(name: str, value: float) -> None:
    sim = Simulator(FIG8B)
    before = sim.targets
    with pytest.raises(ParameterError, match=name):
        sim.set_inputs(**{name: value})
    assert sim.targets == before


def test_numerical_fault_is_reported_and_reset_recovers() -> None:
    sim = Simulator(FIG8B, SimConfig(dtau=1e-4))
    sim._state[k.S_V] = np.nan            # inject a fault as a corrupted state would
    with pytest.raises(NumericalFault):
        sim.advance(10)
    with pytest.raises(NumericalFault):
        sim.advance(10)                   # stays faulted until reset
    sim.reset()
    assert sim.advance(10, every=1).data.shape == (10, k.N_COLS)
