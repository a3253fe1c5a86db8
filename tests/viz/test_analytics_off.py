"""rerun itself reads the config analytics_off writes as valid and disabled.

Each test works in its own HOME / XDG_CONFIG_HOME / XDG_DATA_HOME. The only rerun call is
`rerun analytics config` (prints the loaded config, starts no viewer), made after the config
is written; rerun queues every usage event to a session file in its data directory before
sending it, so an empty data directory afterwards shows that nothing was queued.
"""

from __future__ import annotations

import json
import os
from pathlib import Path

import pytest

from drill_sim_ros.viz import analytics_off


@pytest.fixture
def isolated(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> dict[str, str]:
    env = {"HOME": str(tmp_path / "home"), "XDG_CONFIG_HOME": str(tmp_path / "config"),
           "XDG_DATA_HOME": str(tmp_path / "data")}
    for name, value in env.items():
        monkeypatch.setenv(name, value)
    for name in ("CI", "FORCE_RERUN_ANALYTICS"):   # neither may decide for the config
        monkeypatch.delenv(name, raising=False)
    Path(env["HOME"]).mkdir()
    return env


def rerun_reads_back(env: dict[str, str]) -> tuple[dict, str]:
    """What `rerun analytics config` loads: (the parsed config, its stderr)."""
    if analytics_off.rerun_cli() is None:
        pytest.fail("the rerun CLI of rerun-sdk is not installed")
    run_env = {k: v for k, v in os.environ.items() if k not in ("CI", "FORCE_RERUN_ANALYTICS")}
    loaded, stderr = analytics_off.read_back({**run_env, **env})
    assert loaded is not None, stderr
    return loaded, stderr


def queued_events(env: dict[str, str]) -> list[Path]:
    data = Path(env["XDG_DATA_HOME"]) / "rerun" / "analytics"
    return sorted(data.glob("*")) if data.exists() else []


def check_disabled_and_kept(env: dict[str, str]) -> dict:
    path = analytics_off.disable_analytics()
    written = path.read_bytes()
    loaded, stderr = rerun_reads_back(env)
    assert loaded["analytics_enabled"] is False
    assert loaded["analytics_id"] == json.loads(written)["analytics_id"]   # our file, not new
    assert "failed to load analytics config" not in stderr
    assert "Welcome to Rerun" not in stderr          # not taken as a first run
    assert path.read_bytes() == written              # rerun did not rewrite it
    assert queued_events(env) == []
    return loaded


def test_a_fresh_user_gets_a_config_rerun_reads_as_disabled(isolated: dict[str, str]) -> None:
    loaded = check_disabled_and_kept(isolated)
    config_dir = Path(isolated["XDG_CONFIG_HOME"]) / "rerun"
    assert loaded["config_file_path"] == str(config_dir / "analytics.json")
    assert loaded["data_dir_path"] == str(Path(isolated["XDG_DATA_HOME"]) / "rerun/analytics")


def test_the_old_partial_file_is_repaired(isolated: dict[str, str]) -> None:
    """The previous version wrote only analytics_enabled, which rerun rejects."""
    path = analytics_off.config_path()
    path.parent.mkdir(parents=True)
    path.write_text(json.dumps({"analytics_enabled": False}))
    check_disabled_and_kept(isolated)


def test_an_enabled_config_is_turned_off_keeping_its_id_and_metadata(
        isolated: dict[str, str]) -> None:
    path = analytics_off.config_path()
    path.parent.mkdir(parents=True)
    path.write_text(json.dumps({
        "analytics_enabled": True, "analytics_id": "0123abcd", "metadata": {"k": {"Bool": True}},
        "config_file_path": str(path), "data_dir_path": str(analytics_off.data_dir())}))
    loaded = check_disabled_and_kept(isolated)
    assert (loaded["analytics_id"], loaded["metadata"]) == ("0123abcd", {"k": {"Bool": True}})


def test_a_second_call_leaves_the_file_alone(isolated: dict[str, str]) -> None:
    path = analytics_off.disable_analytics()
    before = path.stat().st_mtime_ns, path.read_bytes()
    analytics_off.disable_analytics()
    assert (path.stat().st_mtime_ns, path.read_bytes()) == before
