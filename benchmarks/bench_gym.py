"""Steps per second of DrillStickSlip-v0 on the field preset (issue 23; prints, no asserts).

One step is one 10 ms control period of the bench. Measured four ways, each beside the
floor it stands on: the environment alone (``env.unwrapped``, constant action), through
``gymnasium.make``'s wrappers (order enforcing, passive checker, as a user gets it), the
session alone stepped one period per call (what any bench costs at least), and the
simulator alone (the compiled kernel's period with its end sample, what the model costs).
Target: >= 20 000 steps/s.
Usage: .venv/bin/python benchmarks/bench_gym.py [--steps 18000] [--repeats 3]
"""

from __future__ import annotations

import argparse
import time

import gymnasium
import numpy as np

import drill_sim_ros.gym as drill_gym
from drill_sim_ros.control.bench import session_config
from drill_sim_ros.model import kernel as k
from drill_sim_ros.model.session import SimSession


def steps_per_s(env: gymnasium.Env, steps: int) -> float:
    env.reset(seed=0)
    action = np.array([2 * np.pi])                         # 60 rpm, the field setpoint
    start = time.perf_counter()
    for _ in range(steps):
        _, _, terminated, truncated, _ = env.step(action)
        if terminated or truncated:
            env.reset()
    return steps / (time.perf_counter() - start)


def session_floor(scenario: object, steps: int) -> tuple[float, float, int]:
    """(session periods/s, simulator periods/s, kernel steps per period)."""
    session = SimSession(session_config(scenario, scenario.load_preset()))
    start = time.perf_counter()
    for _ in range(steps):
        session.run(1)
    session_rate = steps / (time.perf_counter() - start)
    sim, per_period, out = session.sim, session.steps, np.empty((2, k.N_COLS))
    start = time.perf_counter()
    for _ in range(steps):
        sim.advance_into(out, per_period, per_period, sample_end=True)
    return session_rate, steps / (time.perf_counter() - start), per_period


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=18_000)
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    scenario = drill_gym.resolve_scenario("field_60rpm")
    wrapped = gymnasium.make(drill_gym.ENV_ID, scenario=scenario)
    bare = wrapped.unwrapped
    steps_per_s(bare, 100)                                 # compile, warm up
    for _ in range(args.repeats):
        raw, made = steps_per_s(bare, args.steps), steps_per_s(wrapped, args.steps)
        floor, model, per_period = session_floor(scenario, args.steps)
        print(f"DrillStickSlip-v0 (field_8p5in_shale, 10 ms steps): {raw:,.0f} steps/s "
              f"bare, {made:,.0f} steps/s through gymnasium.make; session alone "
              f"{floor:,.0f} periods/s (the env costs {1e6 / raw - 1e6 / floor:.1f} us per "
              f"step over it); simulator alone {model:,.0f} periods/s of {per_period} kernel "
              f"steps ({1e9 / model / per_period:.0f} ns a step, the call included)")


if __name__ == "__main__":
    main()
