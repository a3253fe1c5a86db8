"""SimSession: the stick-slip window of /diagnostics, from the kernel's running sums, equals
the statistics of every step of the same window recorded one by one."""

from __future__ import annotations

import numpy as np
import pytest

from drill_sim_ros.model import kernel as k
from drill_sim_ros.model.analysis import severity
from drill_sim_ros.model.presets import load_preset
from drill_sim_ros.model.session import WINDOW_BUCKETS, SessionConfig, SimSession

BUCKET = 5                      # samples per part of the window


@pytest.mark.parametrize("periods", [7, 1552])  # window not yet full / full, over a stick
def test_severity_window_equals_the_statistics_of_every_step(periods):
    cfg = SessionConfig(preset=load_preset("field_8p5in_shale_lumped"), publish_rate_hz=100.0,
                        window_s=WINDOW_BUCKETS * BUCKET * 0.01)
    session = SimSession(cfg)
    for _ in range(periods):
        session.run(1)
    sev, stuck = session.severity()
    # Reference: the same run, every step recorded.
    reference = SimSession(cfg).sim
    steps = reference.advance(periods * session.steps, every=1).data
    full = periods // BUCKET > WINDOW_BUCKETS
    first = (periods // BUCKET - WINDOW_BUCKETS) * BUCKET * session.steps if full else 0
    window = steps[first:]
    assert len(window) > (WINDOW_BUCKETS * BUCKET * session.steps if full else 0)
    if full:                                  # first stick at about 15 s
        assert 0.0 < stuck < 1.0
    expected = severity(window[:, k.C_OMEGA], reference.targets[0])
    assert sev.omega_min == expected.omega_min and sev.omega_max == expected.omega_max
    assert sev.ssi == pytest.approx(expected.ssi, rel=1e-9)
    assert sev.utr == pytest.approx(expected.utr, rel=1e-12)
    assert stuck == pytest.approx(np.mean(window[:, k.C_MODE] == k.MODE_STUCK), rel=1e-12)


def test_reset_empties_the_window():
    session = SimSession(SessionConfig(preset=load_preset("field_8p5in_shale_lumped")))
    session.run(50)
    session.reset()
    sev, stuck = session.severity()
    assert np.isnan(sev.ssi) and np.isnan(stuck)


def test_a_block_is_the_state_at_the_end_of_each_period_whatever_the_batching():
    """Sample i of a block is what an every-period recording of the same run holds at the
    start of period i + 1, converted to SI by si_rows, stamped (i + 1) periods; taking the
    end sample never moves the simulation, so 10 runs of 1 period equal one run of 10."""
    from drill_sim_ros.model.telemetry import NS_PER_S, field_scales, si_rows

    cfg = SessionConfig(preset=load_preset("field_8p5in_shale_lumped"))
    one_by_one = SimSession(cfg)
    start = one_by_one.current()
    singles = [one_by_one.run(1) for _ in range(10)]
    batched = SimSession(cfg)
    blocks = [batched.run(7), batched.run(3)]
    rows = np.vstack([b.rows for b in blocks])
    assert np.array_equal(rows, np.vstack([b.rows for b in singles]))
    reference = SimSession(cfg)
    # one step past the 10th period: its row is recorded at the start of that step
    recorded = reference.sim.advance(10 * reference.steps + 1, every=reference.steps)
    stamps_ns = np.arange(11, dtype=np.int64) * reference.period_ns
    expected = si_rows(recorded.data, (recorded.depth_offset, recorded.angle_offset),
                       field_scales(cfg.preset.scales), stamps_ns / NS_PER_S, 0.0)
    assert len(recorded.data) == 11
    assert np.array_equal(start.rows[0], expected[0]) and start.stamps_ns[0] == 0
    assert np.array_equal(rows, expected[1:])
    assert np.array_equal(np.concatenate([b.stamps_ns for b in blocks]), stamps_ns[1:])
