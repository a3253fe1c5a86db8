"""docs/img/hil_closed_loop.png: a closed-loop run through opcua_gateway beside the in-process
bench of the same law (docs/hil.md).

sim_node (recording in process) and opcua_gateway run as processes on loopback, and
examples/opcua_controller.py, an asyncua client, closes the loop through the counters for
3000 periods (30 s of the field preset). The bench runs the same law in this process
(tests/ros/opcua_pi_law.py loads it from the example). The figure shows the bit speed and the
quill torque of both runs, and their largest difference.
Usage: .venv/bin/python docs/make_hil_figure.py [-o docs/img/hil_closed_loop.png]
"""

from __future__ import annotations

import argparse
import os
import random
import subprocess
import sys
import tempfile
from pathlib import Path

os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
os.environ.pop("ROS_LOCALHOST_ONLY", None)
os.environ.setdefault("ROS_DOMAIN_ID", str(random.randint(1, 101)))
os.environ.setdefault("AMENT_PREFIX_PATH", sys.prefix)
ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import numpy as np  # noqa: E402

from drill_sim_ros import topics  # noqa: E402
from drill_sim_ros.control.bench import run_in_process  # noqa: E402
from drill_sim_ros.control.plot import pyplot  # noqa: E402
from drill_sim_ros.control.scenario import Scenario  # noqa: E402
from drill_sim_ros.ros.closed_loop import read_telemetry  # noqa: E402
from tests.archive.helpers import stop  # noqa: E402
from tests.ros.opcua_pi_law import EXAMPLE  # noqa: E402
from tests.ros.test_opcua_gateway import sim_and_gateway  # noqa: E402

SCENARIO = Scenario(controller="tests.ros.opcua_pi_law:PiLaw", duration_s=30.0,
                    enable_at_s=0.0)
F = topics.TELEMETRY_INDEX


def over_opcua(periods: int) -> np.ndarray:
    """The telemetry of the example controller through the gateway (periods + 1 rows)."""
    with tempfile.TemporaryDirectory(prefix="hil_figure_") as tmp:
        folder = Path(tmp)
        with sim_and_gateway(folder, folder / "run.mcap") as (sim, gateway, url):
            subprocess.run([sys.executable, str(EXAMPLE), "--endpoint", url, "--periods",
                            str(periods)], check=True, timeout=600)
            stop(gateway)
            stop(sim)
        return read_telemetry(folder / "run.mcap")


def draw(local: np.ndarray, remote: np.ndarray, path: Path) -> None:
    plt = pyplot()
    fig, axes = plt.subplots(2, 1, figsize=(10, 6), sharex=True)
    time_s = local[:, F["sim_time_s"]]
    for ax, field, label in ((axes[0], "bit_rpm", "bit speed, rev/min"),
                             (axes[1], "string_torque_measured_nm", "quill torque, N m")):
        ax.plot(time_s, local[:, F[field]], lw=2.5, color="0.75",
                label="in-process bench")
        ax.plot(remote[:, F["sim_time_s"]], remote[:, F[field]], lw=0.8, color="C0",
                label="through opcua_gateway (asyncua client)")
        ax.set_ylabel(label)
        ax.grid(alpha=0.3)
    axes[0].legend(loc="upper right")
    axes[1].set_xlabel("simulated time, s")
    same = local.shape == remote.shape and local.tobytes() == remote.tobytes()
    largest = float(np.max(np.abs(local - remote))) if local.shape == remote.shape else np.nan
    fig.suptitle(f"PI law of examples/opcua_controller.py, field preset, {len(local) - 1} "
                 f"periods: {'identical bit for bit' if same else 'DIFFERENT'} "
                 f"(largest difference {largest:g})")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    print(f"{path}: {'identical' if same else 'different'}, largest difference {largest:g}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("-o", "--output", type=Path,
                        default=ROOT / "docs" / "img" / "hil_closed_loop.png")
    args = parser.parse_args()
    local = run_in_process(SCENARIO).rows
    draw(local, over_opcua(len(local) - 1), args.output)


if __name__ == "__main__":
    main()
