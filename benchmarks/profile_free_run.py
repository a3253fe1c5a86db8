"""Where a free run's time goes: sim_node's step path in one thread, timed and profiled.

The loop is the ticker's in free run, on sim_node's parameter defaults:
``SimSession.run(FREE_RUN_BATCH)``, then every payload of the block published through
``SampleSinks`` (the sample topics, /clock, the typed telemetry) and the string profiles
through their sink, on loopback DDS with no subscriber.
Prints the real-time factor, the wall time split into the session (the compiled kernel and
the SI rows), the packing and the publishing, then cProfile's top functions by own time
(the profiler slows the small calls most: its figures rank, the split measures).
With ``--cold N`` it measures instead what one tick costs at real time: N ticks of one
period, each after a sleep of about a period (so it starts on caches gone cold, as sim_node's
ticker does at 100 Hz), the thread CPU of the session and of the publishing (packing
included) per tick, and of the simulator's compiled advance alone, mean and median; then
the same N back to back (warm).
Usage: .venv/bin/python benchmarks/profile_free_run.py [--preset field_8p5in_shale]
       [--seconds 10] [--string-rate-hz 0] [--string-message typed] [--top 15] [--cold N]
"""

from __future__ import annotations

import argparse
import cProfile
import os
import pstats
import random
import sys
import time

import numpy as np

os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
os.environ.pop("ROS_LOCALHOST_ONLY", None)
os.environ.setdefault("ROS_DOMAIN_ID", str(random.randint(1, 101)))
os.environ.setdefault("AMENT_PREFIX_PATH", sys.prefix)

import rclpy
from rclpy.node import Node
from rclpy.parameter import Parameter

from drill_sim_ros import topics
from drill_sim_ros.model import kernel
from drill_sim_ros.model.presets import load_preset
from drill_sim_ros.model.session import SimSession
from drill_sim_ros.ros import typed
from drill_sim_ros.ros.messages import type_of
from drill_sim_ros.ros.parameters import declare_all
from drill_sim_ros.ros.sim_node import CLOCK_QOS, DATA_QOS, FREE_RUN_BATCH, session_config
from drill_sim_ros.ros.sinks import SampleSinks, TypedTelemetry
from drill_sim_ros.ros.string_sink import (
    MESSAGES,
    StringProfileSink,
    profile_packer,
    string_message,
    string_topics,
)

PERIOD_S = 0.01          # publish_rate_hz 100


class Loop:
    """The free run's step path, with the time of each part summed (perf_counter s)."""

    def __init__(self, node: Node) -> None:
        loaded, values = declare_all(node, load_preset)      # sim_node's parameters
        self.session = SimSession(session_config(values, loaded))
        chosen = string_topics(loaded, values, typed.PROFILE_AVAILABLE)
        names = (*topics.MSG_TYPES.keys() - set(topics.COMMANDS) - set(topics.PROFILE_TOPICS),
                 *chosen)
        pubs = {t: node.create_publisher(type_of(t), topics.node_relative(t),
                                         CLOCK_QOS if t == topics.CLOCK else DATA_QOS)
                for t in names}
        self.sinks = SampleSinks(pubs)
        if typed.AVAILABLE:
            self.sinks.typed = TypedTelemetry(
                node.create_publisher(typed.Telemetry, "drill/typed/telemetry", DATA_QOS),
                typed.TelemetryPacker("drill_sim_ros"))
        self.sinks.clock_period_ns = 10_000_000
        message = string_message(values, typed.PROFILE_AVAILABLE)
        self.strings = StringProfileSink(self.sinks, chosen[0], pubs, profile_packer(
            message, self.session.string_depths_m, self.session.string_names,
            "drill_sim_ros")) if chosen else None
        self.sinks.warm_up()
        self.seconds = {"session": 0.0, "publish": 0.0, "profiles": 0.0}
        self.periods = 0

    def turn(self) -> None:
        t0 = time.perf_counter()
        block = self.session.run(FREE_RUN_BATCH)
        t1 = time.perf_counter()
        self.sinks.emit(block, True)
        t2 = time.perf_counter()
        if block.strings and self.strings is not None:
            self.strings.emit(block.strings)
        t3 = time.perf_counter()
        self.seconds["session"] += t1 - t0
        self.seconds["publish"] += t2 - t1
        self.seconds["profiles"] += t3 - t2
        self.periods += FREE_RUN_BATCH


def run_for(loop: Loop, seconds: float) -> float:
    """Turns for ``seconds`` of wall time; returns the wall time taken."""
    start = time.perf_counter()
    while time.perf_counter() - start < seconds:
        loop.turn()
    return time.perf_counter() - start


def cold_ticks(loop: Loop, ticks: int) -> None:
    """Thread CPU per part of a one-period tick, after a sleep (cold) and back to back: the
    session and the packing with publishing, then the compiled advance alone
    (``Simulator.advance_into``, the kernel and its Python wrapper: what no restructuring
    of the Python around it removes)."""
    sim, steps = loop.session.sim, loop.session.steps
    rows = np.empty((2, kernel.N_COLS))
    for label, sleep_s in (("after a sleep of a period (cold)", 0.97 * PERIOD_S),
                           ("back to back (warm)", 0.0)):
        parts_ns = np.zeros((ticks, 3))
        for i in range(ticks):
            if sleep_s:
                time.sleep(sleep_s)
            start = time.thread_time_ns()
            block = loop.session.run(1)
            ran = time.thread_time_ns()
            loop.sinks.emit(block, True)
            parts_ns[i, :2] = (ran - start, time.thread_time_ns() - ran)
        for i in range(ticks):
            if sleep_s:
                time.sleep(sleep_s)
            start = time.thread_time_ns()
            sim.advance_into(rows, steps, steps, sample_end=True)
            parts_ns[i, 2] = time.thread_time_ns() - start
        mean, median = parts_ns.mean(axis=0) / 1e3, np.median(parts_ns, axis=0) / 1e3
        print(f"{ticks} ticks {label}, us of thread CPU, mean (median): SimSession.run(1) "
              f"{mean[0]:.1f} ({median[0]:.1f}), packing and publishing {mean[1]:.1f} "
              f"({median[1]:.1f}); the compiled advance alone {mean[2]:.1f} "
              f"({median[2]:.1f})", flush=True)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--preset", default="field_8p5in_shale")
    parser.add_argument("--seconds", type=float, default=10.0)
    parser.add_argument("--string-rate-hz", type=float, default=0.0)
    parser.add_argument("--string-message", default="typed", choices=MESSAGES)
    parser.add_argument("--top", type=int, default=15)
    parser.add_argument("--cold", type=int, metavar="N", help="time N one-period ticks, "
                        "each after a sleep of a period, then N back to back")
    args = parser.parse_args()
    rclpy.init()
    node = Node("profile_free_run", parameter_overrides=[
        Parameter("model.preset", value=args.preset),
        Parameter("string.rate_hz", value=args.string_rate_hz),
        Parameter("string.message", value=args.string_message)])
    try:
        loop = Loop(node)
        run_for(loop, 1.0)                                  # compiled, caches warm
        if args.cold:
            cold_ticks(loop, args.cold)
            return
        loop.seconds = dict.fromkeys(loop.seconds, 0.0)
        loop.periods = 0
        wall = run_for(loop, args.seconds)
        rtf = loop.periods * PERIOD_S / wall
        split = ", ".join(f"{part} {100 * s / wall:.1f} %" for part, s in loop.seconds.items())
        print(f"{args.preset}, string.rate_hz {args.string_rate_hz:g} "
              f"({args.string_message}), {loop.session.steps} steps a period: {rtf:.1f}x "
              "real time "
              f"in one thread, no subscriber; wall time: {split}; "
              f"{1e6 * loop.seconds['session'] / loop.periods:.1f} us/period in the session, "
              f"{1e6 * loop.seconds['publish'] / loop.periods:.1f} us/period publishing",
              flush=True)
        profiler = cProfile.Profile()
        profiler.runcall(run_for, loop, args.seconds)
        stats = pstats.Stats(profiler)
        stats.sort_stats("tottime").print_stats(args.top)
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


if __name__ == "__main__":
    main()
