"""Turn rerun's usage analytics off for this user, without starting the rerun CLI.

rerun reads ``analytics.json`` in its config directory (``$XDG_CONFIG_HOME/rerun`` or
``~/.config/rerun``); ``analytics_enabled: false`` is what ``rerun analytics disable``
writes. Run as ``python -m drill_sim_ros.viz.analytics_off``.
"""

from __future__ import annotations

import json
import os
from pathlib import Path


def config_path() -> Path:
    base = os.environ.get("XDG_CONFIG_HOME") or str(Path.home() / ".config")
    return Path(base) / "rerun" / "analytics.json"


def disable_analytics() -> Path:
    """Write ``analytics_enabled: false`` into rerun's analytics config; return its path."""
    path = config_path()
    config: dict = {}
    if path.exists():
        try:
            config = json.loads(path.read_text())
        except (OSError, json.JSONDecodeError):
            config = {}
    if config.get("analytics_enabled") is not False:
        config["analytics_enabled"] = False
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(json.dumps(config, indent=2))
    return path


if __name__ == "__main__":
    disable_analytics()
