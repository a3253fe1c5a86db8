"""Turn rerun's usage analytics off for this user, before any rerun binary starts.

rerun (0.41) reads ``analytics.json`` from ``$XDG_CONFIG_HOME/rerun`` (else
``~/.config/rerun``) and accepts it only with every field it writes itself: ``analytics_enabled``,
``analytics_id``, ``metadata``, ``config_file_path`` and ``data_dir_path`` (pending events go
to ``$XDG_DATA_HOME/rerun/analytics``, else ``~/.local/share/rerun/analytics``). A file that
lacks one is rejected: rerun then takes the start as a first run and rewrites the file with
analytics enabled. This module writes the same record as ``rerun analytics disable``, without
starting rerun (whose every CLI call, ``analytics disable`` included, queues a usage event on a
first run). Run as ``python -m drill_sim_ros.viz.analytics_off``.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import uuid
from pathlib import Path

CONFIG_FILE = "analytics.json"


def _xdg(variable: str, fallback: str) -> Path:
    value = os.environ.get(variable, "")
    return Path(value) if os.path.isabs(value) else Path.home() / fallback


def config_path() -> Path:
    """Where rerun reads its analytics config."""
    return _xdg("XDG_CONFIG_HOME", ".config") / "rerun" / CONFIG_FILE


def data_dir() -> Path:
    """Where rerun keeps pending analytics events (one JSON file per session)."""
    return _xdg("XDG_DATA_HOME", ".local/share") / "rerun" / "analytics"


def _read(path: Path) -> dict:
    try:
        config = json.loads(path.read_text())
    except (OSError, ValueError):
        return {}
    return config if isinstance(config, dict) else {}


def disabled_config(existing: dict, path: Path) -> dict:
    """A complete config with analytics off; keeps an existing id and opt-in metadata."""
    analytics_id = existing.get("analytics_id")
    metadata = existing.get("metadata")
    return {
        "analytics_enabled": False,
        "analytics_id": analytics_id if isinstance(analytics_id, str) and analytics_id
        else uuid.uuid4().hex,
        "metadata": metadata if isinstance(metadata, dict) else {},
        "config_file_path": str(path),
        "data_dir_path": str(data_dir()),
    }


def disable_analytics() -> Path:
    """Make rerun's analytics config a valid, disabled one (atomic write); return its path."""
    path = config_path()
    existing = _read(path)
    wanted = disabled_config(existing, path)
    if existing != wanted:
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp = path.with_name(f"{CONFIG_FILE}.{os.getpid()}.tmp")
        tmp.write_text(json.dumps(wanted))
        os.replace(tmp, path)
    return path


def rerun_cli() -> str | None:
    """The rerun CLI of this environment (beside the interpreter), else the one on PATH."""
    beside = Path(sys.executable).with_name("rerun")
    return str(beside) if beside.exists() else shutil.which("rerun")


def read_back(env: dict[str, str] | None = None) -> tuple[dict | None, str]:
    """What ``rerun analytics config`` loads (it starts no viewer): (config, its stderr).

    Call it only after :func:`disable_analytics`: like any rerun CLI call it would queue a
    usage event on a first run.
    """
    exe = rerun_cli()
    if exe is None:
        return None, "no rerun CLI found"
    done = subprocess.run([exe, "analytics", "config"], env=env, capture_output=True,
                          text=True, timeout=60, check=False)
    try:
        loaded = json.loads(done.stdout)
    except ValueError:
        loaded = None
    return (loaded if isinstance(loaded, dict) else None), done.stderr


def rerun_reads_disabled() -> bool:
    """True when rerun itself reads this user's analytics config as valid and disabled."""
    loaded, stderr = read_back()
    return (loaded is not None and loaded.get("analytics_enabled") is False
            and "failed to load" not in stderr)


if __name__ == "__main__":
    print(f"rerun analytics off: {disable_analytics()}")
