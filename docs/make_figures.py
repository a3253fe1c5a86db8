"""Regenerate the README figures from the model (needs matplotlib: pip install matplotlib).

    .venv/bin/python docs/make_figures.py

Fig. 8 of RGD07 (beta = 0.3 sticks, beta = 1.3 does not), the phase portrait of Fig. 5,
and the bottom-hole pattern of Fig. 7, all computed by drill_sim_ros.model.
"""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from drill_sim_ros.model import kernel as k  # noqa: E402
from drill_sim_ros.model.presets import load_preset  # noqa: E402
from drill_sim_ros.model.simulator import SimConfig, Simulator  # noqa: E402

OUT = Path(__file__).parent / "img"


def trace(preset: str, tau_end: float, every: int = 20) -> tuple[Simulator, np.ndarray]:
    pr = load_preset(preset)
    sim = Simulator(pr.params, SimConfig(dtau=1e-4), perturb_v=0.01)
    return sim, sim.advance(sim.steps_for(tau_end), every=every).data


def fig8() -> None:
    fig, axes = plt.subplots(2, 1, figsize=(9, 5), sharex=True)
    for ax, name, title in zip(axes, ("fig5_8a", "fig8b"), ("beta = 0.3", "beta = 1.3"),
                               strict=True):
        _, rows = trace(name, 300.0)
        ax.plot(rows[:, k.C_TAU], rows[:, k.C_OMEGA], lw=0.4)
        ax.axhline(5.0, color="k", lw=0.6, ls="--")
        ax.set_ylabel("omega")
        ax.set_title(f"RGD07 Fig. 8 case, {title}", fontsize=10)
    axes[-1].set_xlabel("tau")
    fig.tight_layout()
    fig.savefig(OUT / "fig8_omega.png", dpi=110)


def fig5_and_7() -> None:
    sim, rows = trace("fig5_8a", 300.0, every=5)
    late = rows[rows[:, k.C_TAU] > 280.0]
    fig = plt.figure(figsize=(10, 4.5))
    ax = fig.add_subplot(1, 2, 1)
    ax.plot(late[:, k.C_V], late[:, k.C_OMEGA], lw=0.6)
    ax.set_xlabel("axial velocity v")
    ax.set_ylabel("angular velocity omega")
    ax.set_title("Phase portrait (cf. Fig. 5)", fontsize=10)
    polar = fig.add_subplot(1, 2, 2, projection="polar")
    one_turn = late[late[:, k.C_PHI] > late[-1, k.C_PHI] - 2 * np.pi]
    polar.plot(np.mod(one_turn[:, k.C_PHI], 2 * np.pi), np.maximum(one_turn[:, k.C_DOC], 0),
               lw=0.8)
    polar.set_title("Depth of cut vs bit angle, last turn (cf. Fig. 7)", fontsize=10)
    fig.tight_layout()
    fig.savefig(OUT / "fig5_fig7.png", dpi=110)


if __name__ == "__main__":
    OUT.mkdir(exist_ok=True)
    fig8()
    fig5_and_7()
