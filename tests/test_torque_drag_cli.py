"""``drill_sim torque-drag``: the summary and one JSON line, --plot, and one-line errors."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from tests.model.helpers import SMALL_DEVIATED
from tests.robust.helpers import one_error_line, run_cli

KEYS = {"preset", "wob_n", "mu_dynamic", "hook_load_n", "surface_torque_nm",
        "static_torque_nm", "max_dogleg_deg_per_30m", "profile"}


def test_torque_drag_json_summary_and_plot(capsys: pytest.CaptureFixture[str],
                                           tmp_path: Path) -> None:
    """--json is one line; the profile runs from the top (the hook loads, the surface
    torque) to the bit (no tension off bottom, no torque); pick-up > rotating > slack-off;
    the static torque is the rotating one times mu_s / mu_d (the same normal force)."""
    preset = tmp_path / "deviated.yaml"
    preset.write_text(SMALL_DEVIATED)
    rc, out, err = run_cli(capsys, "torque-drag", "--params", str(preset), "--json")
    assert rc == 0, err
    assert len(out.splitlines()) == 1
    s = json.loads(out)
    assert set(s) == KEYS
    hook, profile = s["hook_load_n"], s["profile"]
    assert hook["pickup"] > hook["rotating"] > hook["slackoff"] > 0.0
    assert profile["depth_m"][0] == 0.0 and profile["depth_m"][-1] == 1000.0
    assert profile["rotating_n"][0] == hook["rotating"] and profile["rotating_n"][-1] == 0.0
    assert profile["torque_nm"][0] == s["surface_torque_nm"] and profile["torque_nm"][-1] == 0
    assert s["static_torque_nm"] == pytest.approx(s["surface_torque_nm"] * 0.35 / 0.25,
                                                  rel=1e-6)
    plot = tmp_path / "td.png"
    rc, out, err = run_cli(capsys, "torque-drag", "--params", str(preset), "--plot", str(plot))
    assert rc == 0, err
    assert "pick-up" in out and json.loads(out.splitlines()[-1]) == s
    assert plot.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


@pytest.mark.parametrize(("args", "names"), [
    (("--params", "field_8p5in_shale"), ("field_8p5in_shale", "no well")),
    (("--params", "fig8b"), ("fig8b", "no string sections")),
    (("--params", "field_8p5in_deviated", "--wob-n", "-5"), ("--wob-n", "-5")),
    (("--params", "nope_no_such_preset"), ("nope_no_such_preset",)),
])
def test_torque_drag_errors_are_one_line(capsys: pytest.CaptureFixture[str],
                                         args: tuple[str, ...],
                                         names: tuple[str, ...]) -> None:
    rc, out, err = run_cli(capsys, "torque-drag", *args)
    one_error_line(rc, err, *names)
    assert out == ""
