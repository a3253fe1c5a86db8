"""The control loop over real DDS: sim_node in its own process, driven in command-triggered
lockstep by a controller node in this one (issue 11).

- Timing: sample k is the state at the end of period k, stamped (k + 1) periods; it echoes
  the stamp of the command that acted over period k, which reacted to sample k - 1: exactly
  one period of latency, and the command's effect is in the very next sample.
- No command is lost in 10 000 periods, and the same commands give the same bytes twice.
- The in-process recording holds every command as received, logged at the sim time it took
  effect.
- Two sims side by side in two namespaces.
"""

from __future__ import annotations

import math
import signal
from pathlib import Path

import numpy as np
import pytest
from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory

from drill_sim_ros import topics
from drill_sim_ros.model.params import RPM_PER_RAD_S
from drill_sim_ros.model.presets import load_preset
from drill_sim_ros.ros.lockstep_driver import Command, LockstepDriver
from tests.archive.helpers import running, stop
from tests.ros.harness import ros_context

pytestmark = pytest.mark.ros
F = topics.TELEMETRY_INDEX
PERIOD_S = 0.01
PRESET = load_preset("field_8p5in_shale_lumped")
RPM0 = PRESET.physical.surface_rpm
WOB0 = PRESET.physical.applied_wob_n


def sim_command(*params: str, namespace: str = "") -> list[str]:
    args = ["lockstep:=true", "lockstep_trigger:=command", "status_line:=false",
            "publish_clock:=false", "top_drive.mode:=kinematic", *params]
    remap = ["-r", f"__ns:={namespace}"] if namespace else []
    return ["sim_node", "--ros-args", *remap, *[a for p in args for a in ("-p", p)]]


def speed_schedule(row: np.ndarray | None) -> Command:
    """A deterministic policy of the sample it sees: the surface speed steps with time, and
    the WOB follows the bit speed (a controller-like dependence on the state)."""
    t_s = 0.0 if row is None else row[F["sim_time_s"]]
    rpm = RPM0 + (20.0 if math.floor(t_s / 0.5) % 2 else 0.0)
    wob = None if row is None else WOB0 * (1.0 + 0.001 * (row[F["bit_rpm"]] - RPM0))
    return Command(speed_rad_s=rpm / RPM_PER_RAD_S, wob_n=wob)


MAX_TORQUE_NM = 30_000.0


def torque_schedule(row: np.ndarray | None) -> Command:
    """Motor torque steps, one of them beyond the drive's limit of MAX_TORQUE_NM."""
    t_s = 0.0 if row is None else row[F["sim_time_s"]]
    return Command(motor_torque_nm=(8_000.0, 12_000.0, 45_000.0)[int(t_s / 0.2) % 3])


def drive(periods: int, timeout_s: float, namespace: str = "",
          policy=speed_schedule) -> LockstepDriver:
    with ros_context() as ros:
        driver = ros.add(LockstepDriver(policy, periods, context=ros.context,
                                        namespace=namespace or None))
        assert ros.spin_until(lambda: driver.done, timeout_s), (len(driver.rows), driver.sent)
        return driver


def run_sim(tmp_path: Path, name: str, periods: int, timeout_s: float,
            *params: str, policy=speed_schedule) -> LockstepDriver:
    log = tmp_path / f"{name}.log"
    with running(sim_command(*params), log) as sim:
        driver = drive(periods, timeout_s, policy=policy)
        assert stop(sim, signal.SIGINT) == 0, log.read_text()
    return driver


def test_one_period_of_latency_and_identical_bytes_run_after_run(tmp_path):
    periods = 300
    first = run_sim(tmp_path, "a", periods, 60.0)
    second = run_sim(tmp_path, "b", periods, 60.0)
    assert first.payloads == second.payloads
    rows = np.array(first.rows)
    times = rows[:, F["sim_time_s"]]
    np.testing.assert_allclose(times, PERIOD_S * np.arange(1, periods + 1), atol=1e-12)
    # sample k ran under the command that reacted to sample k - 1 (the first: t = 0)
    np.testing.assert_allclose(rows[:, F["command_stamp_s"]], times - PERIOD_S, atol=1e-12)
    # ... and already shows its effect: the surface speed commanded from the previous sample
    commands = [speed_schedule(first.first_sample)] + [speed_schedule(r) for r in rows[:-1]]
    np.testing.assert_allclose(rows[:, F["surface_rpm"]],
                               np.array([c.speed_rad_s for c in commands]) * RPM_PER_RAD_S,
                               rtol=1e-12)
    commanded_wob = [c.wob_n for c in commands]
    np.testing.assert_allclose(rows[:, F["applied_wob_n"]], commanded_wob, rtol=1e-12)


def test_torque_mode_applies_the_commanded_motor_torque_within_the_limit(tmp_path):
    periods = 100
    # no motor (no lag, no rate limit): each sample shows its period's torque as commanded
    driver = run_sim(tmp_path, "torque", periods, 60.0, "top_drive.mode:=torque",
                     f"top_drive.max_torque_nm:={MAX_TORQUE_NM}", "top_drive.motor_lag_s:=0.0",
                     "top_drive.max_torque_rate_nm_s:=0.0", policy=torque_schedule)
    rows = np.array(driver.rows)
    commanded = np.array([torque_schedule(driver.first_sample).motor_torque_nm]
                         + [torque_schedule(r).motor_torque_nm for r in rows[:-1]])
    np.testing.assert_allclose(rows[:, F["motor_torque_nm"]],
                               np.minimum(commanded, MAX_TORQUE_NM), rtol=1e-12)
    assert (commanded > MAX_TORQUE_NM).any() and (commanded < MAX_TORQUE_NM).any()
    # the drive is an inertia: its speed changes, as J dOmega/dt = motor - string torque says
    j_kg_m2 = PRESET.top_drive.physical(PRESET.scales).inertia_kg_m2
    speed = rows[:, F["surface_rpm"]] / RPM_PER_RAD_S
    net = rows[1:, F["motor_torque_nm"]] - 0.5 * (rows[1:, F["surface_torque_nm"]]
                                                   + rows[:-1, F["surface_torque_nm"]])
    np.testing.assert_allclose(np.diff(speed) * j_kg_m2 / PERIOD_S, net, rtol=0.05,
                               atol=0.02 * MAX_TORQUE_NM)


def test_ten_thousand_periods_lose_no_command_and_the_recording_holds_them(tmp_path):
    periods = 10_000
    path = tmp_path / "run.mcap"
    driver = run_sim(tmp_path, "long", periods, 240.0, f"record.path:={path}")
    rows = np.array(driver.rows)
    assert len(rows) == periods == driver.sent
    np.testing.assert_allclose(rows[:, F["command_stamp_s"]],
                               rows[:, F["sim_time_s"]] - PERIOD_S, atol=1e-9)
    commands = []
    with open(path, "rb") as stream:
        reader = make_reader(stream, decoder_factories=[DecoderFactory()])
        for _, _channel, message, msg in reader.iter_decoded_messages(
                topics=[topics.CMD_TOP_DRIVE]):
            commands.append((message.log_time, msg.header.stamp.sec * 10**9
                             + msg.header.stamp.nanosec, list(msg.velocity)))
    assert len(commands) == periods
    origin_ns = commands[0][0]          # log time: the run's wall-clock start + sim time
    for k, (log_ns, stamp_ns, velocity) in enumerate(commands):
        # command k reacted to the state at k periods and took effect there
        assert stamp_ns == log_ns - origin_ns == k * 10_000_000
        assert velocity[0] == pytest.approx(rows[k, F["surface_rpm"]] / RPM_PER_RAD_S,
                                            rel=1e-12)


def test_two_sims_side_by_side_in_two_namespaces(tmp_path):
    with running(sim_command(namespace="/rig1"), tmp_path / "rig1.log") as rig1, \
            running(sim_command("model.surface_rpm:=90.0", namespace="/rig2"),
                    tmp_path / "rig2.log") as rig2:
        one = drive(20, 60.0, namespace="/rig1")
        two = drive(20, 60.0, namespace="/rig2")
        assert stop(rig1, signal.SIGINT) == 0
        assert stop(rig2, signal.SIGINT) == 0
    # each driver drove its own sim: the same schedule, from each sim's own initial state
    first_one, first_two = np.array(one.rows[0]), np.array(two.rows[0])
    assert first_one[F["sim_time_s"]] == first_two[F["sim_time_s"]] == PERIOD_S
    assert first_one[F["bit_rpm"]] != first_two[F["bit_rpm"]]   # 90 rpm at start in rig2
