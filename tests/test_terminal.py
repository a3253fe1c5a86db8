"""The one live line (drill_sim_ros/terminal.py): silent in a pipe, unless a long command
asks for a plain line every so often."""

from __future__ import annotations

import io

import pytest

from drill_sim_ros import terminal


def test_a_pipe_gets_nothing_by_default_and_a_plain_line_every_so_often(
        monkeypatch: pytest.MonkeyPatch) -> None:
    now = [100.0]
    monkeypatch.setattr(terminal.time, "monotonic", lambda: now[0])
    quiet, paced = io.StringIO(), io.StringIO()
    lines = [terminal.StatusLine(quiet), terminal.StatusLine(paced, every_s=30.0)]
    for t, text in ((100.0, "a"), (129.9, "b"), (130.0, "c"), (140.0, "d"), (160.0, "e")):
        now[0] = t
        for line in lines:
            line.show(text)
    for line in lines:
        line.close()
    assert quiet.getvalue() == ""
    assert paced.getvalue() == "c\ne\n"          # whole lines, no carriage returns
