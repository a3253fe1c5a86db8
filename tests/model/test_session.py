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
    cfg = SessionConfig(preset=load_preset("field_8p5in_shale"), publish_rate_hz=100.0,
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
    session = SimSession(SessionConfig(preset=load_preset("field_8p5in_shale")))
    session.run(50)
    session.reset()
    sev, stuck = session.severity()
    assert np.isnan(sev.ssi) and np.isnan(stuck)
