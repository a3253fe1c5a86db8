"""Why ``drill_sim fit`` missed the static coefficient: the replay's own bias, and the misfit
along the static coefficient (issue 51; prints figures, no asserts).

1. A start-up of field_8p5in_deviated (30 rpm in 10 s, 60 s; ``--substeps`` sets the wave
   step, 54: 2.0 ms, the tests' step) run by the drive's speed loop is replayed (the drive
   kinematic, fit.engine.simulate) following (a) its own speed, (b) that speed plus the
   noisy_delayed_sensors scenario's speed noise (0.02 rad/s white at 100 Hz), as a replay
   of a raw log follows it, (c) the same low-passed at the string's cut-off, as the fit
   replays a log since 2026-12-06. Printed: the first slip's time and the peak torque
   before it, per draw and against the run (how many later, how many higher).
2. The misfit of fit.engine's Evaluator on a log of that run (the sensors seeded 1), along
   the static coefficient at the others' true values, the weights measured at the truth:
   where its minimum lies, for ``--replays`` replays averaged per point.

Usage: .venv/bin/python benchmarks/fit_replay_bias.py [--draws 8] [--replays 12]
       [--factors 0.9,0.95,1,1.05,1.1] [--substeps 54] [--skip-bias]
"""

from __future__ import annotations

import argparse

import numpy as np

from drill_sim_ros.fit import engine, objective, synthetic
from drill_sim_ros.fit.params import parse_fit
from drill_sim_ros.model.presets import preset_from_dict, preset_path
from drill_sim_ros.model.startup import RPM_PER_RAD_S, run_startup
from drill_sim_ros.model.validate_input import read_preset_file

PRESET = "field_8p5in_deviated"
STATIC = "well.side_friction.static"
SPEED_NOISE_RAD_S = 0.02          # noisy_delayed_sensors' drive_speed_rad_s noise_std


def slip_and_peak(target: objective.Target, torque_nm: np.ndarray) -> tuple[float, float]:
    """The first slip (s from the start) and the peak torque before it, low-passed."""
    lp = target.model_torque(torque_nm)
    slip = objective.first_slip_index(lp)
    return (np.nan if slip is None else slip * target.log.sample_s,
            float(objective.breakaway_features(lp, target.log.sample_s)[0]))


def bias(data: dict, draws: int) -> None:
    preset = preset_from_dict(PRESET, data)
    run = run_startup(preset, 30.0, 10.0, 60.0)
    speed = run.drive_rpm / RPM_PER_RAD_S
    log = synthetic.measured_log(run, synthetic.scenario_sensors(1), 0.0, "run")
    target = objective.make_target(log, preset)
    own = engine.simulate(data, {}, run.t_s, speed)
    truth = slip_and_peak(target, run.surface_torque_nm)
    print(f"the run: first slip {truth[0]:.2f} s, peak before it {truth[1]:.0f} N m; "
          "replayed with its own speed: {:.2f} s, {:.0f} N m".format(
              *slip_and_peak(target, own[0])))
    for name, cutoff in (("raw noise", np.inf), ("low-passed", target.cutoff_hz)):
        rows = np.array([slip_and_peak(target, engine.simulate(
            data, {}, run.t_s, speed, (seed, SPEED_NOISE_RAD_S), cutoff)[0])
            for seed in range(draws)])
        print(f"{name:11s}: slip {np.array2string(rows[:, 0], precision=2)} s (later than "
              f"the run {int(np.sum(rows[:, 0] > truth[0]))}/{draws}), peak mean "
              f"{np.mean(rows[:, 1]):.0f} N m ({100 * (np.mean(rows[:, 1]) / truth[1] - 1):+.1f} "
              f"%, higher {int(np.sum(rows[:, 1] > truth[1]))}/{draws})", flush=True)


def profile(data: dict, factors: list[float]) -> None:
    preset = preset_from_dict(PRESET, data)
    log = synthetic.synthetic_log(preset, 30.0, 10.0, 60.0, synthetic.scenario_sensors(1))
    target = objective.make_target(log, preset)
    evaluator = engine.Evaluator(data, parse_fit(STATIC, data), [target])
    truth = float(data["well"]["side_friction"]["static"])
    evaluator.measure_sensitivity(np.array([truth]))
    print(f"misfit along {STATIC} (truth {truth}), {engine.REPLAYS_PER_POINT} replays a point:")
    for f in factors:
        e = evaluator.evaluate([np.array([truth * f])])[0]
        print(f"  x {f:.3f}: misfit {e.misfit:.3f}, break-away residual "
              f"{e.residuals[-1]:+.2f}", flush=True)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--draws", type=int, default=8)
    ap.add_argument("--replays", type=int, default=engine.REPLAYS_PER_POINT)
    ap.add_argument("--factors", default="0.9,0.95,0.98,1,1.02,1.05,1.1")
    ap.add_argument("--substeps", type=int, default=54)
    ap.add_argument("--skip-bias", action="store_true")
    args = ap.parse_args()
    data = read_preset_file(preset_path(PRESET))
    data["string"]["bit_substeps"] = args.substeps
    engine.REPLAYS_PER_POINT = args.replays
    if not args.skip_bias:
        bias(data, args.draws)
    profile(data, [float(f) for f in args.factors.split(",")])


if __name__ == "__main__":
    main()
