"""Shared set-up for the model tests: the paper's cases and small run helpers."""

from __future__ import annotations

import numpy as np

from drill_sim_ros.model import analysis as an
from drill_sim_ros.model import kernel as k
from drill_sim_ros.model.params import DimensionlessParams
from drill_sim_ros.model.simulator import SimConfig, Simulator

FIG8A = DimensionlessParams(n=6, psi=50.0, beta=0.3, lam=5.0, w0=7.0, omega0=5.0)
FIG8B = FIG8A.with_(beta=1.3)


def run(params: DimensionlessParams, tau_end: float, dtau: float = 1e-4,
        every: int = 0, **kwargs) -> tuple[Simulator, np.ndarray]:
    """Run from tau = 0 to ``tau_end``; return the simulator and the sample rows."""
    config_keys = {"n_nodes", "method", "tau_avg", "omega_rate", "w_rate"}
    config = SimConfig(dtau=dtau, **{key: kwargs.pop(key) for key in list(kwargs)
                                     if key in config_keys})
    sim = Simulator(params, config, **kwargs)
    samples = sim.advance(sim.steps_for(tau_end), every=every)
    return sim, samples.data


def advance_to_stick_onset(sim: Simulator, limit_tau: float, chunk: int = 200) -> bool:
    """Step until the bit enters a stick phase (the sample of a step is stuck and the
    previous was not); stop right at that step. A stick phase under way when called is
    not an onset. False if ``limit_tau`` passes first."""
    last_mode = float(k.MODE_STUCK) if sim.state[k.S_STUCK] else -1.0
    while sim.tau < limit_tau:
        snap = sim.snapshot()
        rows = sim.advance(chunk, every=1).data
        modes = rows[:, k.C_MODE]
        prev = np.concatenate(([last_mode], modes[:-1]))
        onset = np.flatnonzero((modes == k.MODE_STUCK) & (prev != k.MODE_STUCK))
        if onset.size:
            sim.restore(snap)
            sim.advance(int(onset[0]))
            return True
        last_mode = modes[-1]
    return False


def whole_cycle_averages(p: DimensionlessParams, cycles: int, settle_tau: float = 300.0,
                         dtau: float = 1e-4) -> an.CycleAverages:
    """Averages over whole stick-slip cycles: from one stick onset to another, after
    ``settle_tau`` of transient."""
    sim = Simulator(p, SimConfig(dtau=dtau), perturb_v=0.01)
    sim.advance(sim.steps_for(settle_tau))
    assert advance_to_stick_onset(sim, settle_tau + 100.0)
    sim.reset_statistics()
    for _ in range(cycles):
        assert advance_to_stick_onset(sim, sim.tau + 50.0)
    return an.cycle_averages(p, sim.accumulators)


# A small deviated well for the start-up (a run of 10 s takes about a second): 900 m of
# 5-in pipe on 100 m of 6.75-in collars, vertical to 200 m, built at a constant rate to
# 60 deg at 700 m and held; mud of 1200 kg/m^3; side friction 0.35 static, 0.25 dynamic;
# the wave step 16 x 37 us = 0.59 ms (the wall's cells 1.9 m).
SMALL_DEVIATED = """\
description: 900 m of 5-in pipe on 100 m of collars, a well built to 60 deg
physical: {density_kg_m3: 7850.0, shear_modulus_pa: 79.3e9, youngs_modulus_pa: 206.0e9,
  bit_radius_m: 0.108, n_blades: 6, intrinsic_specific_energy_pa: 230.0e6, zeta: 0.729,
  mu_gamma: 0.48, contact_stress_times_wearflat_n_per_m: 1.0e5, applied_wob_n: 60000.0,
  surface_rpm: 35.0}
string:
  model: distributed
  sections:
    - {outer_radius_m: 0.0635, inner_radius_m: 0.0543, length_m: 900.0}
    - {outer_radius_m: 0.0857, inner_radius_m: 0.0357, length_m: 100.0}
  bit_inertia_kg_m2: 0.3
  bit_substeps: 16
well:
  survey: [{md_m: 0, inclination_deg: 0}, {md_m: 200, inclination_deg: 0},
           {md_m: 700, inclination_deg: 60}]
  mud_density_kg_m3: 1200
  side_friction: {static: 0.35, dynamic: 0.25, stick_speed_rad_s: 0.05}
top_drive: {mode: speed, inertia_kg_m2: 2900.0, kp_nm_s: 23200.0, ki_nm: 46400.0,
  max_torque_nm: 50000.0}
numerics: {dtau: 5.0e-5}
"""
