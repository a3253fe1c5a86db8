"""Ticker and HandoffLock (pure threading): a busy ticker never starves a callback, wake and
stop take effect at once, errors are handed over."""

from __future__ import annotations

import threading
import time

from drill_sim_ros.realtime.ticker import HandoffLock, Ticker


def test_a_callback_gets_the_lock_from_a_ticker_that_never_sleeps():
    lock = HandoffLock()

    def busy() -> float:
        lock.acquire_background()
        try:
            time.sleep(0.002)           # one "batch" with the lock held
        finally:
            lock.release()
        return 0.0

    ticker = Ticker(busy, lambda exc: False)
    ticker.start()
    try:
        waits = []
        for _ in range(20):
            start = time.monotonic()
            with lock.urgent():
                waits.append(time.monotonic() - start)
        assert max(waits) < 0.5, waits
    finally:
        ticker.stop()


def test_wake_calls_work_now_and_stop_joins():
    calls = []
    woken = threading.Event()

    def work() -> None:
        calls.append(time.monotonic())
        if len(calls) == 2:
            woken.set()
        return None                      # idle until woken

    ticker = Ticker(work, lambda exc: False)
    ticker.start()
    time.sleep(0.05)
    assert len(calls) == 1
    ticker.wake()
    assert woken.wait(1.0)
    ticker.stop()
    assert not ticker._thread.is_alive()
    ticker.stop()                        # idempotent
    ticker.wake()                        # harmless once stopped


def test_a_long_wait_ends_at_a_wake_and_a_short_one_at_its_end():
    calls = []

    def work() -> float:
        calls.append(time.monotonic())
        return 30.0 if len(calls) == 1 else 0.005 if len(calls) == 2 else None

    ticker = Ticker(work, lambda exc: False)
    ticker.start()
    try:
        time.sleep(0.1)
        assert len(calls) == 1               # waiting 30 s
        ticker.wake()
        deadline = time.monotonic() + 2.0
        while len(calls) < 3 and time.monotonic() < deadline:
            time.sleep(0.001)
        assert len(calls) == 3               # woken, then a 5 ms sleep, then idle
        assert calls[2] - calls[1] >= 0.005
    finally:
        ticker.stop()


def test_an_error_goes_to_on_error_and_false_ends_the_loop():
    errors = []

    def work() -> float:
        raise RuntimeError("boom")

    ticker = Ticker(work, lambda exc: errors.append(exc) or False)
    ticker.start()
    ticker._thread.join(1.0)
    assert not ticker._thread.is_alive()
    assert [str(e) for e in errors] == ["boom"]
