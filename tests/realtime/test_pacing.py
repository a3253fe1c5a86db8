"""Pacer (pure): deadlines on a fixed grid, so lateness never accumulates into drift."""

from __future__ import annotations

import random

from drill_sim_ros.realtime.pacing import Pacer, RateMeter, lateness_percentiles_ms

MS = 1_000_000


def test_jittery_ticks_do_not_drift():
    pacer = Pacer(10 * MS)
    pacer.anchor(0)
    rng = random.Random(3)
    now, done = 0, 0
    for _ in range(10_000):
        now += rng.randint(int(0.2 * MS), int(9.9 * MS))   # the timer wakes at random times
        count = pacer.due(now, limit=1000)
        pacer.complete(count, now)
        done += count
        # after `now` ns, exactly the ticks whose deadline has passed are done
        assert done == now // (10 * MS) + 1
    assert pacer.overruns == 0


def test_late_ticks_are_counted_as_overruns_and_caught_up():
    pacer = Pacer(10 * MS)
    pacer.anchor(5 * MS)
    assert pacer.due(4 * MS, 50) == 0
    assert pacer.due(5 * MS, 50) == 1
    assert pacer.due(38 * MS, 2) == 2                 # four due, a limit of two
    pacer.complete(2, 38 * MS)                         # 33 ms and 23 ms late: two overruns
    assert pacer.overruns == 2
    assert pacer.due(38 * MS, 50) == 2
    pacer.complete(2, 38 * MS)                         # 13 and 3 ms late: one more
    assert pacer.overruns == 3
    p50, p99 = lateness_percentiles_ms(pacer.lateness_ns(), 50, 99)
    assert 3.0 <= p50 <= 33.0 and p99 <= 33.0


def test_rate_meter_measures_sim_seconds_per_wall_second():
    meter = RateMeter(0, 0.0)
    assert meter.update(2_000 * MS, 5.0) == 2.5
