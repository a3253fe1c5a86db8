"""Plain-rclpy controllers of the kinds a user writes (issue 22), run as processes by
tests/ros/test_controller_handshake.py; only rclpy and the law of
examples/lockstep_controller.py, no helper of this package.

    python tests/ros/plain_controllers.py --report PATH [--kind a|b|c] [--kickoff-stamp
        now|zero] [--stop-at-s 30] [--die-at-s T] [--extras] [--flood N [--depth D]]
        [--go-file PATH]

- a: answers every sample of drill/surface/measured, stamped with the sample's stamp, once
  its publisher has matched (an answer sent before is lost: docs/control-loop.md);
- b: also sends one command at start-up, at once; c: sends one kick-off command once its
  publisher has matched (both stamped with the node's clock, or 0 with --kickoff-stamp zero);
- --extras: around every fifth answer, commands that must not count: one stamped a period
  older, one at -1 s and one at 1e9 s before it, and a second answer after it (0 rpm, all);
- --die-at-s: SIGKILL itself on receiving the sample of that stamp, before answering;
- --flood N: answers nothing; once the run passes 1 s, sends N commands stamped -1 s and
  1e9 s (0 rpm) as fast as it can;
- --depth D: its publisher keeps the last D commands (10, rclpy's usual; 0: all of them, so
  DDS delivers every one and none is lost; the flood then waits for the sim to acknowledge
  every KEPT_BURST commands, as a writer keeping all refuses more once full).
- --go-file: answers nothing until PATH exists; once its publisher has matched and it holds
  a sample (the sim's latest, kept for late joiners), it writes PATH.ready-<pid> (the test's
  start signal, so that two controllers begin together);
On the first sample stamped --stop-at-s or later it answers nothing more, writes one JSON
object (commands sent, extras, answers) to --report and spins until SIGINT.
"""

from __future__ import annotations

import argparse
import json
import os
import signal
import sys
from pathlib import Path

import rclpy
from builtin_interfaces.msg import Time
from rclpy.duration import Duration
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from rclpy.qos import HistoryPolicy, QoSProfile
from sensor_msgs.msg import JointState

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "examples"))
from lockstep_controller import LATEST_SAMPLE, speed_setpoint_rad_s

PERIOD_NS = 10_000_000
WRONG_STAMPS_NS = (-10**9, 10**18)
EXTRAS_EVERY = 5
KEPT_BURST = 2000


def stamp(time_ns: int) -> Time:
    sec, nanosec = divmod(time_ns, 10**9)
    return Time(sec=sec, nanosec=nanosec)


class PlainController(Node):
    def __init__(self, args: argparse.Namespace) -> None:
        super().__init__(f"plain_controller_{os.getpid()}")
        self.args = args
        self.sent = self.extras = self.answers = 0
        self.done = False
        depth = QoSProfile(history=HistoryPolicy.KEEP_ALL) if args.depth == 0 else args.depth
        self.pub = self.create_publisher(JointState, "drill/cmd/top_drive", depth)
        self.create_subscription(JointState, "drill/surface/measured", self.on_sample,
                                 LATEST_SAMPLE)
        self.held: JointState | None = None          # a sample to answer once sim_node listens
        self.create_timer(0.01, self.answer_held)
        if args.kind == "b":
            self.kick_off()
        elif args.kind == "c":
            self.wait_for_match = self.create_timer(0.01, self.kick_off_once_matched)

    def send(self, speed_rad_s: float, time_ns: int) -> None:
        command = JointState(name=["top_drive"], velocity=[speed_rad_s])
        command.header.stamp = stamp(time_ns)
        self.pub.publish(command)
        self.sent += 1

    def kick_off(self) -> None:
        now_ns = self.get_clock().now().nanoseconds
        self.send(0.0, 0 if self.args.kickoff_stamp == "zero" else now_ns)

    def kick_off_once_matched(self) -> None:
        if self.pub.get_subscription_count() > 0:
            self.destroy_timer(self.wait_for_match)
            self.kick_off()

    def answer_held(self) -> None:
        if self.held is not None and self.pub.get_subscription_count() > 0:
            if not self.going():
                return self.say_ready()
            sample, self.held = self.held, None
            self.on_sample(sample)

    def going(self) -> bool:
        return self.args.go_file is None or Path(self.args.go_file).exists()

    def say_ready(self) -> None:
        Path(f"{self.args.go_file}.ready-{os.getpid()}").touch()

    def on_sample(self, sample: JointState) -> None:
        if self.pub.get_subscription_count() == 0 or not self.going():
            self.held = sample                       # an answer now would be lost
            return                                   # (docs/control-loop.md), or early
        time_ns = sample.header.stamp.sec * 10**9 + sample.header.stamp.nanosec
        if self.done:
            return
        if time_ns >= round(self.args.stop_at_s * 1e9):
            return self.report()
        if self.args.die_at_s is not None and time_ns == round(self.args.die_at_s * 1e9):
            os.kill(os.getpid(), signal.SIGKILL)
        if self.args.flood:
            return self.flood(time_ns)
        extras = self.args.extras and self.answers % EXTRAS_EVERY == 0
        if extras:
            for wrong_ns in (time_ns - PERIOD_NS, *WRONG_STAMPS_NS):
                self.send(0.0, wrong_ns)
        self.send(speed_setpoint_rad_s(sample.effort[1]), time_ns)
        self.answers += 1
        if extras:
            self.send(0.0, time_ns)                  # a second answer
            self.extras += 4

    def flood(self, time_ns: int) -> None:
        if time_ns < 10**9:
            return
        for i in range(self.args.flood):
            self.send(0.0, WRONG_STAMPS_NS[i % 2])
            if self.args.depth == 0 and i % KEPT_BURST == KEPT_BURST - 1:
                # a writer keeping all refuses a command once full: let the sim catch up
                assert self.pub.wait_for_all_acked(Duration(seconds=30))
        self.extras = self.args.flood
        self.report()

    def report(self) -> None:
        self.done = True
        text = json.dumps({"sent": self.sent, "extras": self.extras, "answers": self.answers})
        Path(self.args.report + ".tmp").write_text(text)
        os.replace(self.args.report + ".tmp", self.args.report)


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--report", required=True)
    parser.add_argument("--kind", choices=("a", "b", "c"), default="a")
    parser.add_argument("--kickoff-stamp", choices=("now", "zero"), default="now")
    parser.add_argument("--stop-at-s", type=float, default=30.0)
    parser.add_argument("--die-at-s", type=float)
    parser.add_argument("--extras", action="store_true")
    parser.add_argument("--flood", type=int, default=0)
    parser.add_argument("--depth", type=int, default=10)
    parser.add_argument("--go-file")
    args = parser.parse_args()
    rclpy.init()
    node = PlainController(args)
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


if __name__ == "__main__":
    main()
