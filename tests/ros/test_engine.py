"""The compiled tick loop (engine.py) and the compiled publishing of frame.py, over loopback
DDS: the bytes on the wire are those of the Python path (SimSession.run + SampleFrame.pack),
a waiting callback gets the node's lock in the slack before a deadline, and rcl's refusal of
a payload is an error that names the topic."""

from __future__ import annotations

import os
import threading
import time

import pytest
import rclpy
from rclpy.context import Context
from rclpy.node import Node

from drill_sim_ros import topics
from drill_sim_ros.model.presets import load_preset
from drill_sim_ros.ros import frame as frame_module
from drill_sim_ros.ros.engine import EXIT_BUDGET, EXIT_WAKE, R_SAMPLES, TickLoop
from drill_sim_ros.ros.frame import FramePublisher, PublishError, SampleFrame
from drill_sim_ros.ros.messages import type_of
from drill_sim_ros.ros.pacing import Pacer
from drill_sim_ros.ros.session import SessionConfig, SimSession
from drill_sim_ros.ros.sim_node import DATA_QOS
from drill_sim_ros.ros.ticker import HandoffLock
from tests.ros.harness import Probe, Ros, ros_context

pytestmark = pytest.mark.ros
PRESET = load_preset("field_8p5in_shale")
SUBMERGED_N = 1.9e6
SAMPLES = 130                   # two runs of the loop: 100 samples (5 batches of 20), 30


@pytest.fixture
def ros():
    with ros_context() as r:
        yield r


def session() -> SimSession:
    # a 20 s window: a snapshot every 100 samples ends a compiled run
    return SimSession(SessionConfig(preset=PRESET, window_s=20.0))


def frame_publisher(ros: Ros) -> tuple[FramePublisher, Probe]:
    """A frame with /clock, its publishers, and a raw probe matched to all of them."""
    frame = SampleFrame(PRESET.scales, with_clock=True)
    node = ros.add(Node("engine_test", context=ros.context))
    publishers = [node.create_publisher(type_of(t), t, DATA_QOS) for t in frame.topics]
    probe = ros.add(Probe(ros.context, frame.topics, raw=True))
    assert ros.spin_until(lambda: all(p.get_subscription_count() for p in publishers), 10.0)
    return FramePublisher(frame, publishers), probe


def python_path_payloads(periods: int) -> dict[str, list[bytes]]:
    """The payloads of a twin session, advanced and packed by the Python path."""
    twin = session()
    frame = SampleFrame(PRESET.scales, with_clock=True)
    time_ns, count = twin.run(periods)
    out: dict[str, list[bytes]] = {topic: [] for topic in frame.topics}
    for i in range(count):
        payloads = frame.pack(twin.samples, i, twin.sim.offsets, time_ns + i * twin.period_ns,
                              SUBMERGED_N)
        for topic, payload in zip(frame.topics, payloads, strict=True):
            out[topic].append(payload)
    return out


def received(ros: Ros, probe: Probe, topic_names: tuple[str, ...], count: int
             ) -> dict[str, list[bytes]]:
    assert ros.spin_until(lambda: all(probe.count(t) >= count for t in topic_names), 20.0)
    return {topic: [bytes(msg) for msg in probe.messages(topic)] for topic in topic_names}


def test_compiled_free_run_puts_the_bytes_of_the_python_path_on_the_wire(ros):
    publisher, probe = frame_publisher(ros)
    assert publisher.compiled
    lock = HandoffLock()
    wake_fd = os.eventfd(0, os.EFD_NONBLOCK | os.EFD_CLOEXEC)
    try:
        loop = TickLoop(lock.requests, wake_fd, catch_up=50, batch=20, short_wait_ns=20_000_000)
        sim = session()
        runs = 0
        while sim.next_index < SAMPLES:
            reason = loop.run(sim, publisher, None, SAMPLES - sim.next_index, SUBMERGED_N)
            assert reason == EXIT_BUDGET and loop.result[R_SAMPLES] > 0
            runs += 1
    finally:
        os.close(wake_fd)
    assert runs == 2                          # stopped at the window's snapshot
    assert sim.next_index == SAMPLES
    topic_names = publisher.frame.topics
    assert received(ros, probe, topic_names, SAMPLES) == python_path_payloads(SAMPLES)


def test_without_rcls_c_call_the_same_bytes_go_through_rclpy(ros, monkeypatch):
    def unavailable():
        raise OSError("librcl.so: cannot open shared object file")
    monkeypatch.setattr(frame_module, "rcl_publish_serialized", unavailable)
    publisher, probe = frame_publisher(ros)
    assert not publisher.compiled
    sim = session()
    time_ns, count = sim.run(40)
    publisher.publish(sim.samples, 0, count, sim.sim.offsets, time_ns, sim.period_ns,
                      SUBMERGED_N)
    topic_names = publisher.frame.topics
    assert received(ros, probe, topic_names, 40) == python_path_payloads(40)


def test_a_waiting_callback_gets_the_lock_in_the_slack_before_the_deadline(ros):
    publisher, _ = frame_publisher(ros)
    wake_fd = os.eventfd(0, os.EFD_NONBLOCK | os.EFD_CLOEXEC)
    lock = HandoffLock(on_request=lambda: os.eventfd_write(wake_fd, 1))
    loop = TickLoop(lock.requests, wake_fd, catch_up=50, batch=20,
                    short_wait_ns=5_000_000_000)          # the loop itself waits up to 5 s
    pacer = Pacer(10_000_000)
    pacer.anchor(time.monotonic_ns() + 3_000_000_000)    # the first deadline, 3 s away
    sim = session()
    inside = threading.Event()
    reasons: list[int] = []

    def ticker() -> None:
        lock.acquire_background()
        try:
            inside.set()
            reasons.append(loop.run(sim, publisher, pacer, 10, SUBMERGED_N))
        finally:
            lock.release()

    thread = threading.Thread(target=ticker, daemon=True)
    try:
        thread.start()
        assert inside.wait(10.0)
        time.sleep(0.05)                       # most likely inside ppoll by now
        with lock.urgent():
            # the callback holds the lock in the slack: before the loop's next deadline
            assert time.monotonic_ns() < pacer.deadline_ns()
            assert reasons == [EXIT_WAKE]
            assert sim.next_index == 0         # nothing published: the deadline is ahead
        thread.join(10.0)
        assert not thread.is_alive()
    finally:
        os.close(wake_fd)


def test_a_refused_payload_raises_an_error_that_names_the_topic():
    context = Context()
    rclpy.init(context=context)
    node = Node("refused", context=context)
    try:
        frame = SampleFrame(PRESET.scales, with_clock=False)
        publishers = [node.create_publisher(type_of(t), t, DATA_QOS) for t in frame.topics]
        publisher = FramePublisher(frame, publishers)
        sim = session()
        time_ns, count = sim.run(1)
        rclpy.shutdown(context=context)        # as SIGINT does: rcl refuses to publish
        with pytest.raises(PublishError, match=topics.BIT_WOB):
            publisher.publish(sim.samples, 0, count, sim.sim.offsets, time_ns,
                              sim.period_ns, SUBMERGED_N)
    finally:
        node.destroy_node()
        rclpy.try_shutdown(context=context)
