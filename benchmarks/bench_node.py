"""sim_node figures with a subscriber on every topic: prints them (no asserts).

(a) real time at 100 Hz: CPU % of one core (process CPU time / wall time, from
    /proc/<pid>/stat) against the reference measured in the same run: a bare rclpy process
    whose thread publishes sim_node's own payloads (the same bytes, topics and QoS: the 11
    sample topics, the typed telemetry twin, a string profile every 10 samples) every
    10 ms through ``Publisher.publish``; and the node's tick lateness p50/p99 (its
    /diagnostics). ``--pairs`` reference/node measurements alternate; the median ratio counts.
    With ``--floors``, each pair also measures two floors of any Python node on this model,
    as ratios to the same reference: the reference plus the simulator's compiled advance of
    each period, and plus ``SimSession.run(1)`` and the packing of the payloads it publishes;
(b0) the ceiling of a free run, measured the same way: the reference publishing the same
    payloads as fast as it can (no simulation), as a real-time factor at 100 Hz;
(b) free run (real_time_factor 0): achieved real-time factor (sim seconds per wall second),
    and as a fraction of (b0); (c) the same with in-process recording (record.path);
(d) (b0) and (b) again, first with the subscriber process idle (its subscriptions matched,
    so Fast DDS still delivers to it, but it takes nothing and leaves the second core to the
    publisher), then with no subscriber: what the subscriber costs on this 2-core machine.
(e) the string profiles (issue 35): free run of the distributed preset with its profiles as
    drill_sim_msgs/StringProfile (string.message typed, the default), as JointState
    (joint_state) and with none (string.rate_hz 0), and of its lumped twin, alternated
    ``--rounds`` times; each as x real time (median) and as a ratio to the lumped twin's.
Targets (issue 10): (a) sim_node <= 1.5x the reference, p99 <= 2 ms; (b) >= 100x, and with
recording >= a third of that; (issue 35) (e) typed >= 0.85x the lumped twin and >= 50x.
Usage: .venv/bin/python benchmarks/bench_node.py [--seconds 10] [--pairs 3] [--floors]
       [--preset field_8p5in_shale] [--rounds 2] [--strings-only] [--real-time-only]
"""

from __future__ import annotations

import argparse
import os
import random
import select
import signal
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

# Loopback DDS and a domain of our own, before rclpy is imported.
os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
os.environ.pop("ROS_LOCALHOST_ONLY", None)
os.environ.setdefault("ROS_DOMAIN_ID", str(random.randint(1, 101)))
os.environ.setdefault("AMENT_PREFIX_PATH", sys.prefix)

import numpy as np
import rclpy
from rclpy.node import Node
from rclpy.qos import QoSProfile, ReliabilityPolicy

from drill_sim_ros import topics
from drill_sim_ros.ros import typed
from drill_sim_ros.ros.messages import type_of

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))   # for tests.process_probes
from tests.process_probes import cpu_seconds

BIN = Path(sys.prefix) / "bin"
PUBLISHED = [t for t in topics.MSG_TYPES if t not in topics.COMMANDS]
if typed.AVAILABLE:                    # the typed telemetry twin, which sim_node publishes
    PUBLISHED.append(topics.TYPED_TELEMETRY)
if typed.PROFILE_AVAILABLE:            # (e): the typed profiles are subscribed too
    PUBLISHED.append(topics.TYPED_STRING_TORSION)
# (a) with --floors: the reference plus the simulation's work, by --reference-work
FLOORS = {"advance": "the reference + the compiled advance of a period",
          "session": "the reference + SimSession.run(1) and the packing of its payloads"}
# (e): (label, preset suffix, sim_node parameters)
STRING_CASES = (("distributed, typed profiles", "", ("string.message:=typed",)),
                ("distributed, JointState profiles", "", ("string.message:=joint_state",)),
                ("distributed, no profiles (string.rate_hz 0)", "", ("string.rate_hz:=0.0",)),
                ("lumped twin", "_lumped", ()))


class Listener(Node):
    """One subscription per published topic (none with ``telemetry=False``: /diagnostics
    only); keeps the last /diagnostics values."""

    def __init__(self, telemetry: bool = True) -> None:
        super().__init__("bench_listener" if telemetry else "bench_watcher")
        self.count = 0
        self.diagnostics: dict[str, str] = {}
        # (wall s at receipt, the node's real_time_factor_achieved over its last second)
        self.rates: list[tuple[float, float]] = []
        qos = QoSProfile(depth=100, reliability=ReliabilityPolicy.RELIABLE)
        for topic in PUBLISHED if telemetry else ():
            self.create_subscription(type_of(topic), topic, self._on_message, qos)
        self.create_subscription(type_of(topics.DIAGNOSTICS), topics.DIAGNOSTICS,
                                 self._on_diagnostics, qos)

    def _on_message(self, _msg: object) -> None:
        self.count += 1

    def _on_diagnostics(self, msg) -> None:
        self.diagnostics = {kv.key: kv.value for s in msg.status for kv in s.values}
        if "real_time_factor_achieved" in self.diagnostics:
            self.rates.append((time.monotonic(),
                               float(self.diagnostics["real_time_factor_achieved"])))


def sim_rate(rates: list[tuple[float, float]], start: float, end: float) -> float:
    """Simulated seconds per wall second: the mean of the node's own once-a-second figures
    (sim time advanced over the wall time between two /diagnostics, both read in the node)
    received in [start, end]. Receipt times cannot serve: in free run the listener falls
    behind and /diagnostics waits behind the telemetry, so its arrivals bunch up."""
    inside = [rate for wall, rate in rates if start <= wall <= end]
    return float(np.mean(inside)) if inside else float("nan")


def spin_for(node: Node, seconds: float) -> None:
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        rclpy.spin_once(node, timeout_sec=0.05)


def start_node(preset: str, factor: float, record_path: str = "",
               params: tuple[str, ...] = ()) -> subprocess.Popen:
    command = [str(BIN / "sim_node"), "--ros-args", "-p", f"model.preset:={preset}",
               "-p", f"real_time_factor:={factor}", "-p", "status_line:=false"]
    if record_path:
        command += ["-p", f"record.path:={record_path}"]
    for param in params:
        command += ["-p", param]
    return subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)


def start_reference(preset: str, period_s: float = 0.01, work: str = "none") -> subprocess.Popen:
    return subprocess.Popen([sys.executable, __file__, "--reference-publisher", preset,
                             "--reference-period", str(period_s), "--reference-work", work],
                            stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)


def reference_publisher(preset: str, period_s: float, work: str = "none") -> None:
    """The reference: a thread publishing sim_node's payloads of one block every
    ``period_s``; with 0, as fast as it can in batches of FREE_RUN_BATCH samples (the
    ceiling of a free run), printing ``monotonic_s samples`` once a second. The payloads are
    the node's at its defaults: the 11 sample topics, the typed telemetry twin (when
    drill_sim_msgs is installed) and, on a distributed string, one typed string profile
    every 10 samples (string.rate_hz 10).

    ``work`` (the floors of a Python node, with none of sim_node's lock, pacer, handshake or
    executor entities) adds the simulation to each sample: ``advance``, the simulator's
    compiled advance of one period alone (the payloads stay the prepared ones); ``session``,
    ``SimSession.run(1)`` and the packing of its sample (and its profile when one is due),
    whose payloads are the ones published."""
    from drill_sim_ros.model import kernel
    from drill_sim_ros.model.presets import load_preset
    from drill_sim_ros.model.session import SimSession
    from drill_sim_ros.ros.frame import SampleFrame
    from drill_sim_ros.ros.parameters import yaml_defaults
    from drill_sim_ros.ros.sim_node import FREE_RUN_BATCH, session_config, topic_qos
    from drill_sim_ros.ros.string_sink import TYPED, profile_packer

    rclpy.init()
    node = Node("bench_reference")
    frame = SampleFrame(with_clock=True)
    pubs = [node.create_publisher(type_of(t), t, topic_qos(t)) for t in frame.topics]
    loaded = load_preset(preset)
    session = SimSession(session_config(yaml_defaults(loaded), loaded))
    block = session.run(100)
    payloads = frame.pack(block.rows, block.stamps_ns)
    twin_packer = typed.TelemetryPacker("drill_sim") if typed.AVAILABLE else None
    if twin_packer is not None:
        pubs.append(node.create_publisher(typed.Telemetry, topics.TYPED_TELEMETRY,
                                          topic_qos(topics.TYPED_TELEMETRY)))
        twins = twin_packer.pack(block.rows, block.stamps_ns)
        payloads = [[*row, twin] for row, twin in zip(payloads, twins, strict=True)]
    profiles: list[bytes] = []
    if block.strings and typed.PROFILE_AVAILABLE:
        profile_pub = node.create_publisher(typed.StringProfile, topics.TYPED_STRING_TORSION,
                                            topic_qos(topics.TYPED_STRING_TORSION))
        packer = profile_packer(TYPED, session.string_depths_m, session.string_names,
                                "drill_sim")
        profiles = [packer.pack(sample) for sample in block.strings]
    stop_event = threading.Event()
    sim, steps = session.sim, session.steps
    rows = np.empty((2, kernel.N_COLS))

    def sample_payloads(i: int) -> tuple[list[bytes], bytes | None]:
        """The payloads of sample ``i`` and its profile (None when none is due)."""
        if work == "session":
            block = session.run(1)
            fresh = frame.pack(block.rows, block.stamps_ns)[0]
            if twin_packer is not None:
                fresh = [*fresh, twin_packer.pack(block.rows, block.stamps_ns)[0]]
            profile = packer.pack(block.strings[0]) if profiles and block.strings else None
            return fresh, profile
        if work == "advance":
            sim.advance_into(rows, steps, steps, sample_end=True)
        profile = profiles[(i // 10) % len(profiles)] if profiles and i % 10 == 0 else None
        return payloads[i % len(payloads)], profile

    def publish_every_10_ms() -> None:
        deadline = next_report = time.monotonic()
        i = 0
        while not stop_event.is_set():
            sample, profile = sample_payloads(i)
            for pub, payload in zip(pubs, sample, strict=True):
                pub.publish(payload)
            if profile is not None:
                profile_pub.publish(profile)
            i += 1
            if period_s > 0:
                deadline += period_s
                time.sleep(max(0.0, deadline - time.monotonic()))
            elif i % FREE_RUN_BATCH == 0:
                time.sleep(0.0)                  # like sim_node's ticker: yield the GIL
                if (now := time.monotonic()) >= next_report:
                    print(f"{now} {i}", flush=True)
                    next_report = now + 1.0

    thread = threading.Thread(target=publish_every_10_ms, daemon=True)
    thread.start()
    try:
        rclpy.spin(node)
    except KeyboardInterrupt:
        pass
    finally:
        stop_event.set()
        thread.join(1.0)
        node.destroy_node()
        rclpy.try_shutdown()


def reported_rate(proc: subprocess.Popen, window: tuple[float, float]) -> float:
    """Samples per second of a stopped ceiling publisher over ``window`` (monotonic s), from
    its ``monotonic_s samples`` lines (the monotonic clock is one for all processes)."""
    lines = [line.split() for line in proc.stdout.read().splitlines()]
    points = [(float(t), int(n)) for t, n in lines if window[0] <= float(t) <= window[1]]
    if len(points) < 2:
        return float("nan")
    (t0, n0), (t1, n1) = points[0], points[-1]
    return (n1 - n0) / (t1 - t0)


def printed(proc: subprocess.Popen) -> bool:
    """A ceiling publisher has printed its first figure (it is publishing)."""
    return proc.stdout is not None and bool(select.select([proc.stdout], [], [], 0)[0])


def stop(proc: subprocess.Popen) -> None:
    proc.send_signal(signal.SIGINT)
    try:
        proc.wait(timeout=10)
    except subprocess.TimeoutExpired:
        proc.kill()
        proc.wait()


def measure(listener: Listener, proc: subprocess.Popen, seconds: float,
            watcher: Listener | None = None) -> dict[str, float]:
    """CPU %, message rate and diagnostics of one running process over a steady window. With
    a ``watcher``, only it is spun during the window: the listener's subscriptions stay
    matched (Fast DDS still delivers to them) but nothing takes their messages."""
    spun = listener if watcher is None else watcher
    try:
        # start-up (numba compiles on a cold cache: tens of seconds), discovery, then 3 s
        first, reports = listener.count, len(spun.rates)
        end = time.monotonic() + 120.0
        while not (listener.count > first or len(spun.rates) > reports
                   or printed(proc)) and time.monotonic() < end:
            rclpy.spin_once(listener, timeout_sec=0.025)
            rclpy.spin_once(spun, timeout_sec=0.025)
        spin_for(spun, 3.0)
        cpu0, wall0, n0 = cpu_seconds(proc.pid), time.monotonic(), listener.count
        spin_for(spun, seconds)
        cpu1, wall1, n1 = cpu_seconds(proc.pid), time.monotonic(), listener.count
        spin_for(spun, 1.1)                           # the next /diagnostics
        diag = dict(spun.diagnostics)
    finally:
        stop(proc)
    wall = wall1 - wall0
    return {"window": (wall0, wall1), "cpu_percent": 100.0 * (cpu1 - cpu0) / wall,
            "received_per_s": (n1 - n0) / wall,
            "p50_ms": float(diag.get("tick_lateness_p50_ms", "nan")),
            "p99_ms": float(diag.get("tick_lateness_p99_ms", "nan")),
            "overruns": float(diag.get("overruns", "nan")),
            "sim_rate": sim_rate(spun.rates, wall0, wall1),
            "rtf_reported": float(diag.get("real_time_factor_achieved", "nan"))}


def string_profiles(listener: Listener, preset: str, seconds: float, rounds: int) -> None:
    """(e): the free run of each of STRING_CASES, alternated ``rounds`` times; medians, and
    their ratios to the lumped twin's."""
    rates: dict[str, list[float]] = {label: [] for label, _, _ in STRING_CASES}
    for round_index in range(1, rounds + 1):
        for label, suffix, params in STRING_CASES:
            run = measure(listener, start_node(preset + suffix, 0.0, params=params), seconds)
            rates[label].append(run["sim_rate"])
            print(f"(e) round {round_index}: {label}: {run['sim_rate']:.1f}x real time; CPU "
                  f"{run['cpu_percent']:.0f} %; {run['received_per_s']:.0f} msg/s received",
                  flush=True)
    lumped = float(np.median(rates[STRING_CASES[-1][0]]))
    for label, _, _ in STRING_CASES:
        median = float(np.median(rates[label]))
        print(f"(e) {label}: {median:.1f}x real time (median of {rounds}; "
              f"{min(rates[label]):.1f}-{max(rates[label]):.1f}) = {median / lumped:.2f} of "
              f"the lumped twin's", flush=True)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=10.0)
    parser.add_argument("--pairs", type=int, default=3,
                        help="(a) reference/sim_node measurements, alternated")
    parser.add_argument("--real-time-only", action="store_true", help="(a) only")
    parser.add_argument("--preset", default="field_8p5in_shale")
    parser.add_argument("--rounds", type=int, default=2,
                        help="(e) rounds of the string profile cases, alternated (0: skip "
                        "them, e.g. on a lumped preset)")
    parser.add_argument("--strings-only", action="store_true", help="(e) only")
    parser.add_argument("--reference-publisher", metavar="PRESET", help=argparse.SUPPRESS)
    parser.add_argument("--reference-period", type=float, default=0.01, help=argparse.SUPPRESS)
    parser.add_argument("--reference-work", default="none", choices=("none", *FLOORS),
                        help=argparse.SUPPRESS)
    parser.add_argument("--floors", action="store_true",
                        help="(a) also the floors of a Python node: the reference with the "
                        "simulation's compiled advance, and with SimSession.run and packing")
    args = parser.parse_args()
    if args.reference_publisher:
        reference_publisher(args.reference_publisher, args.reference_period,
                            args.reference_work)
        return
    rclpy.init()
    listener = Listener()
    try:
        if args.strings_only:
            string_profiles(listener, args.preset, args.seconds, args.rounds)
            return
        ratios = []
        floors: dict[str, list[float]] = {work: [] for work in FLOORS} if args.floors else {}
        for pair in range(1, args.pairs + 1):      # alternated: drift hits both alike
            ref = measure(listener, start_reference(args.preset), args.seconds)
            for work, label in FLOORS.items() if args.floors else ():
                floor = measure(listener, start_reference(args.preset, work=work), args.seconds)
                floors[work].append(floor["cpu_percent"] / ref["cpu_percent"])
                print(f"(a) pair {pair}: the floor of a Python node, {label}: CPU "
                      f"{floor['cpu_percent']:.1f} % = {floors[work][-1]:.2f}x the reference",
                      flush=True)
            rt = measure(listener, start_node(args.preset, 1.0), args.seconds)
            ratios.append(rt["cpu_percent"] / ref["cpu_percent"])
            print(f"(a) pair {pair}: real time, 100 Hz, {len(PUBLISHED)} topics subscribed: "
                  f"sim_node CPU {rt['cpu_percent']:.1f} % of one core, reference publisher "
                  f"{ref['cpu_percent']:.1f} %: ratio {ratios[-1]:.2f}x; tick lateness p50 "
                  f"{rt['p50_ms']:.3f} ms, p99 {rt['p99_ms']:.3f} ms; overruns "
                  f"{rt['overruns']:g}; {rt['received_per_s']:.0f} msg/s received "
                  f"(reference {ref['received_per_s']:.0f})", flush=True)
        print(f"(a) CPU ratio, median of {len(ratios)} pairs: {float(np.median(ratios)):.2f}x "
              f"(range {min(ratios):.2f}-{max(ratios):.2f})", flush=True)
        for work, values in floors.items():
            print(f"(a) the floor of a Python node, {FLOORS[work]}, median of {len(values)} "
                  f"pairs: {float(np.median(values)):.2f}x (range {min(values):.2f}-"
                  f"{max(values):.2f})", flush=True)
        if args.real_time_only:
            return
        ceiling_proc = start_reference(args.preset, period_s=0.0)
        ceiling = measure(listener, ceiling_proc, args.seconds)
        ceiling_rtf = reported_rate(ceiling_proc, ceiling["window"]) / 100.0
        print(f"(b0) ceiling of a free run: the reference publishing as fast as it can, "
              f"{ceiling_rtf:.1f}x real time at 100 Hz; CPU {ceiling['cpu_percent']:.0f} %; "
              f"{ceiling['received_per_s']:.0f} msg/s received", flush=True)
        free = measure(listener, start_node(args.preset, 0.0), args.seconds)
        print(f"(b) free run: achieved real-time factor {free['sim_rate']:.1f}x = "
              f"{free['sim_rate'] / ceiling_rtf:.2f} of (b0) (mean of the node's once-a-second "
              f"figures; the last {free['rtf_reported']:.1f}x); CPU "
              f"{free['cpu_percent']:.0f} %; {free['received_per_s']:.0f} msg/s received",
              flush=True)
        with tempfile.TemporaryDirectory() as tmp:
            path = str(Path(tmp) / "free.mcap")
            rec = measure(listener, start_node(args.preset, 0.0, path), args.seconds)
        print(f"(c) free run, recording in process: achieved real-time factor "
              f"{rec['sim_rate']:.1f}x = {rec['sim_rate'] / free['sim_rate']:.2f} of (b); "
              f"CPU {rec['cpu_percent']:.0f} %")
        if args.rounds > 0:
            string_profiles(listener, args.preset, args.seconds, args.rounds)
        watcher = Listener(telemetry=False)
        for case, spun in (("the subscriber process idle (its subscriptions matched, "
                            "nothing taken)", watcher), ("no subscriber", None)):
            if spun is None:                      # no telemetry subscription at all
                listener.destroy_node()
                listener = spun = watcher
            top_proc = start_reference(args.preset, period_s=0.0)
            top = measure(listener, top_proc, args.seconds, watcher=spun)
            top_rtf = reported_rate(top_proc, top["window"]) / 100.0
            run = measure(listener, start_node(args.preset, 0.0), args.seconds, watcher=spun)
            print(f"(d) with {case}: ceiling {top_rtf:.1f}x, free run {run['sim_rate']:.1f}x "
                  f"= {run['sim_rate'] / top_rtf:.2f} of it; CPU reference "
                  f"{top['cpu_percent']:.0f} %, sim_node {run['cpu_percent']:.0f} %", flush=True)
    finally:
        listener.destroy_node()
        rclpy.try_shutdown()


if __name__ == "__main__":
    main()
