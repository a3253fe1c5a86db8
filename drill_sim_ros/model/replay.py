"""A start-up replayed from a log: the top drive follows a recorded surface speed.

ROS-free, SI in and out. The string starts at rest, untwisted and off bottom, the hook fixed
(:meth:`Simulator.start_at_rest`, as ``drill_sim startup`` starts it); the drive is
*kinematic* (the paper's imposed speed, ``top_drive.TD_KINEMATIC``), its speed prescribed by
a time series: between two samples it goes linearly from one recorded speed to the next
(each interval sets the target and the ramp rate that reaches it at the interval's end,
:meth:`Simulator.set_speed_ramp`), so the string is turned exactly as the rig turned it and
the motor torque is what that takes. The drive turns one way: a negative recorded speed (a
speed sensor's noise about rest) is taken as 0.

``follow="setpoint"``: the series is the drive's *setpoint* instead, followed through the
preset's own speed loop (the drive in speed mode, as ``drill_sim startup`` runs it): the
replayed speed then carries no sensor noise, whose integral would move the wind-up
(docs/fit.md), but the preset's drive (its loop gains and inertia) must be the rig's.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from drill_sim_ros.model import kernel as k
from drill_sim_ros.model.errors import ParameterError
from drill_sim_ros.model.presets import Preset
from drill_sim_ros.model.simulator import Samples, SimConfig, Simulator
from drill_sim_ros.model.startup import StartupRun, require_startup_preset, startup_series

PROGRESS_EVERY = 1000      # samples between progress reports
FOLLOW = ("speed", "setpoint")   # what a replay's drive follows (module doc)


def replay_simulator(preset: Preset, follow: str = "speed") -> Simulator:
    """``preset``'s string at rest off bottom under a kinematic drive, or under its own
    speed loop to follow a setpoint (module doc)."""
    require_startup_preset(preset)
    if follow not in FOLLOW:
        raise ParameterError(f"follow {follow!r}: must be one of {', '.join(FOLLOW)}")
    drive = preset.top_drive.with_(mode="kinematic" if follow == "speed" else "speed")
    sim = Simulator(preset.params, SimConfig(dtau=preset.dtau, n_nodes=64), top_drive=drive,
                    scales=preset.scales, string=preset.kernel_string, bit_law=preset.bit_law)
    sim.start_at_rest()
    return sim


def sample_steps(preset: Preset, t_s: np.ndarray) -> np.ndarray:
    """The simulator's step count at each sample time (from the first), shape (samples,);
    ParameterError unless the times increase by at least one step each."""
    t_s = np.asarray(t_s, dtype=float)
    if t_s.ndim != 1 or t_s.size < 2 or not np.all(np.isfinite(t_s)):
        raise ParameterError("a replay needs at least two finite sample times")
    steps = np.rint((t_s - t_s[0]) / (preset.dtau * preset.scales.time_s)).astype(np.int64)
    if np.any(np.diff(steps) < 1):
        raise ParameterError("the sample times must increase by at least one simulator step "
                             f"({preset.dtau * preset.scales.time_s:.3g} s)")
    return steps


def replay_speed(preset: Preset, t_s: np.ndarray, speed_rad_s: np.ndarray,
                 on_progress: Callable[[float], None] | None = None,
                 follow: str = "speed") -> StartupRun:
    """Turn ``preset``'s string from rest with the drive speed ``speed_rad_s`` (rad/s) at the
    times ``t_s`` (s, increasing), linear between them (module doc); the run sampled at
    those times (t from 0). ``follow="setpoint"``: ``speed_rad_s`` is the setpoint of the
    preset's speed loop."""
    speed = np.maximum(np.asarray(speed_rad_s, dtype=float), 0.0)
    if speed.shape != np.shape(t_s) or not np.all(np.isfinite(speed)):
        raise ParameterError("the speeds must be finite, one per sample time")
    steps = sample_steps(preset, t_s)
    sim = replay_simulator(preset, follow)
    target = speed * preset.scales.time_s            # kernel units: rad per t*
    rows = np.empty((steps.size, k.N_COLS))
    sim.set_inputs(omega_s=float(target[0]))
    sim.sample_into(rows[0])
    offsets = np.zeros((steps.size, 2))
    offsets[0] = sim.offsets
    for i in range(1, steps.size):
        n = int(steps[i] - steps[i - 1])
        change = abs(float(target[i] - target[i - 1]))
        sim.set_speed_ramp(change / (n * preset.dtau) if change > 0.0 else math.inf)
        sim.set_inputs(omega_s=float(target[i]))
        sim.advance_into(rows[i:i + 1], n, 0, sample_end=True)
        offsets[i] = sim.offsets
        if on_progress is not None and i % PROGRESS_EVERY == 0:
            on_progress(i / (steps.size - 1))
    rows[:, k.C_U] += offsets[:, 0]
    rows[:, k.C_PHI] += offsets[:, 1]
    rows[:, k.C_PHI_S] += offsets[:, 1]
    rows[:, k.C_TAU] -= rows[0, k.C_TAU]
    return startup_series([Samples(rows)], preset)
