"""Library rules of issue 5: explicit recording streams, no global rerun state."""

from __future__ import annotations

import ast
from pathlib import Path

import drill_sim_ros.viz as viz

GLOBAL_CALLS = {"init", "log", "send_columns", "set_time", "save", "connect_grpc",
                "serve_grpc", "serve_web_viewer", "spawn", "send_blueprint"}


def rr_calls(path: Path) -> set[str]:
    calls = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if (isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute)
                and isinstance(node.func.value, ast.Name) and node.func.value.id == "rr"):
            calls.add(node.func.attr)
    return calls


def test_no_global_rerun_calls_in_viz() -> None:
    for path in Path(viz.__file__).parent.glob("*.py"):
        assert not rr_calls(path) & GLOBAL_CALLS, path.name


def test_conversion_leaves_no_global_recording(tmp_path: Path) -> None:
    import rerun as rr

    from drill_sim_ros.viz.mcap_to_rerun import convert
    from tests.viz.sim_telemetry import default_rows, write_mcap

    write_mcap(tmp_path / "a.mcap", default_rows(2.0))
    assert convert(tmp_path / "a.mcap", tmp_path / "a.rrd") == 201
    assert rr.get_global_data_recording() is None
