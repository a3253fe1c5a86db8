"""``drill_sim params``: every parameter of the one table, with type, unit, range, default
and whether it changes at runtime."""

from __future__ import annotations

import json
import subprocess
import sys

from drill_sim_ros.model.presets import DEFAULT_PRESET, load_preset
from drill_sim_ros.ros.parameters import SPECS

LUMPED = "field_8p5in_shale_lumped"     # a preset whose rpm and WOB differ from the default's


def drill_sim_params(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "drill_sim_ros.cli", "params", *args],
                          capture_output=True, text=True, timeout=120)


def test_every_parameter_is_listed_with_its_type_unit_range_default_and_runtime():
    done = drill_sim_params("--json")
    assert done.returncode == 0, done.stderr
    rows = {row["name"]: row for row in json.loads(done.stdout)}
    assert list(rows) == [spec.name for spec in SPECS]
    assert rows["publish_rate_hz"] | {"description": ""} == {
        "name": "publish_rate_hz", "type": "double", "unit": "Hz", "range": "[1, 1000]",
        "default": 100.0, "runtime": "no", "description": ""}
    assert rows["lockstep.warn_after_s"]["unit"] == "s"
    assert rows["lockstep.warn_after_s"]["runtime"] == "yes"
    assert rows["model.applied_wob_n"]["unit"] == "N"                # from its [N]
    default, lumped = load_preset(DEFAULT_PRESET).physical, load_preset(LUMPED).physical
    assert rows["model.applied_wob_n"]["default"] == default.applied_wob_n   # the preset's
    assert rows["model.surface_rpm"]["default"] == default.surface_rpm
    other = {row["name"]: row for row in json.loads(drill_sim_params(
        "--preset", LUMPED, "--json").stdout)}
    assert (lumped.applied_wob_n, lumped.surface_rpm) != (default.applied_wob_n,
                                                          default.surface_rpm)
    assert other["model.applied_wob_n"]["default"] == lumped.applied_wob_n
    assert other["model.surface_rpm"]["default"] == lumped.surface_rpm
    assert rows["lockstep_trigger"]["range"] == "service | command"
    assert rows["model.n_nodes"]["range"] == "[16, 4194304]"


def test_the_table_and_a_bad_preset():
    table = drill_sim_params()
    assert table.returncode == 0
    header, first = table.stdout.splitlines()[:2]
    assert header.split() == ["name", "type", "unit", "range", "default", "runtime"]
    assert first.split() == ["model.preset", "string", "field_8p5in_shale", "no"]
    bad = drill_sim_params("--preset", "nope")
    assert bad.returncode == 2 and "preset 'nope'" in bad.stderr
    assert "Traceback" not in bad.stderr and len(bad.stderr.strip().splitlines()) == 1
