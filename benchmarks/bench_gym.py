"""Steps per second of DrillStickSlip-v0 on every shipped scenario (issues 23, 35; prints,
no asserts).

One step is one 10 ms control period of the bench. For each scenario of config/scenarios,
the environment is stepped with random actions (drawn from its action space, seeded, before
the clock starts, so the figure is the environment's and not the sampler's) two ways: alone
(``env.unwrapped``) and through ``gymnasium.make``'s wrappers (order enforcing, passive
checker, as a user gets it), per wall second and per CPU second of the process (which moves
less when other jobs share the cores). An episode that ends is reset inside the timed loop. Beside
them, the floors they stand on: the session alone stepped one period per call (what any
bench costs at least) and the simulator alone (the compiled kernel's period with its end
sample, what the model costs). Target (issue 35): >= 20 000 steps/s on every scenario.
Usage: .venv/bin/python benchmarks/bench_gym.py [--steps 18000] [--repeats 1]
                                                [--scenario NAME ...]
"""

from __future__ import annotations

import argparse
import time

import gymnasium
import numpy as np

import drill_sim_ros.gym as drill_gym
from drill_sim_ros.control.bench import session_config
from drill_sim_ros.control.scenario import Scenario, scenario_dir
from drill_sim_ros.model import kernel as k
from drill_sim_ros.model.session import SimSession

TARGET_STEPS_S = 20_000


def random_actions(env: gymnasium.Env, steps: int, seed: int = 0) -> list[np.ndarray]:
    """``steps`` actions sampled from ``env``'s action space (seeded)."""
    env.action_space.seed(seed)
    return [env.action_space.sample() for _ in range(steps)]


def steps_per_s(env: gymnasium.Env, actions: list[np.ndarray]) -> tuple[float, float]:
    """Steps per wall second and per CPU second of this process, of ``env`` under
    ``actions``, resets of ended episodes in (the CPU figure moves less with other jobs)."""
    env.reset(seed=0)
    start, start_cpu = time.perf_counter(), time.process_time()
    for action in actions:
        _, _, terminated, truncated, _ = env.step(action)
        if terminated or truncated:
            env.reset()
    return (len(actions) / (time.perf_counter() - start),
            len(actions) / (time.process_time() - start_cpu))


def session_floor(scenario: Scenario, steps: int) -> tuple[float, float, int]:
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


def bench_scenario(name: str, steps: int, repeats: int) -> float:
    """Print one scenario's line; its slowest figure (steps/s)."""
    scenario = drill_gym.resolve_scenario(name)
    wrapped = gymnasium.make(drill_gym.ENV_ID, scenario=scenario)
    bare = wrapped.unwrapped
    actions = random_actions(bare, steps)
    steps_per_s(bare, actions[:100])                       # compile, warm up
    raw, raw_cpu = max(steps_per_s(bare, actions) for _ in range(repeats))
    made, made_cpu = max(steps_per_s(wrapped, actions) for _ in range(repeats))
    floor, model, per_period = session_floor(scenario, steps)
    print(f"{name:22s} {raw:7,.0f} bare ({raw_cpu:7,.0f} per CPU s) {made:7,.0f} make "
          f"({made_cpu:7,.0f}) | session {floor:7,.0f} periods/s (env "
          f"+{1e6 / raw - 1e6 / floor:5.1f} us/step) | simulator {model:7,.0f} periods/s "
          f"of {per_period} kernel steps ({1e9 / model / per_period:.0f} ns/step)")
    return min(raw, made)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=18_000)
    parser.add_argument("--repeats", type=int, default=1)
    parser.add_argument("--scenario", nargs="*", help="names (default: every shipped one)")
    args = parser.parse_args()
    names = args.scenario or sorted(p.stem for p in scenario_dir().glob("*.yaml"))
    print(f"DrillStickSlip-v0, random actions, {args.steps:,} steps (10 ms each) per figure, "
          f"best of {args.repeats}; steps/s:")
    slowest = min(bench_scenario(name, args.steps, args.repeats) for name in names)
    verdict = "holds" if slowest >= TARGET_STEPS_S else "fails"
    print(f"slowest: {slowest:,.0f} steps/s; the bar of {TARGET_STEPS_S:,} steps/s {verdict}")


if __name__ == "__main__":
    main()
