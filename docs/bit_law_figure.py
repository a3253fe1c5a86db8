"""The bit torque against the bit's speed at the field point (docs/model.md): draws the PNG.

The default field preset's bit (8.5 in, its sigma l, 60 kN applied, steady drilling:
W_f = lambda, the depth of cut of eq. 34) through the model's own law
(``Preset.bit_law``, ``bit_rock.BitLaw.torque``), in SI: RGD07's flat line, and
``physical.friction_weakening`` with floor 0.5 and 7 rad/s on the wearflat friction only and
on the whole bit torque (the preset's own law, drawn at a held speed: its lag does not
show); beside them the COPPE/UFRJ field fit (Castello & Ritto, arXiv
2206.14609) T = WOB x 0.0239 m x [tanh(1.91 w) + 8.5 w / (1 + 5.47 w^2)], w in rad/s.

Usage: .venv/bin/python docs/bit_law_figure.py [--out docs/img/bit_law_field.png]
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

import numpy as np

from drill_sim_ros.model.analysis import trivial_solution
from drill_sim_ros.model.presets import Preset, preset_from_dict, preset_path
from drill_sim_ros.model.validate_input import read_preset_file

OUT = Path(__file__).resolve().parent / "img" / "bit_law_field.png"
PRESET = "field_8p5in_shale"
WEAKENING = {"floor_ratio": 0.5, "speed_rad_s": 7.0}


def preset_with(applies_to: str | None) -> Preset:
    """The default field preset, with ``friction_weakening`` on ``applies_to`` (None:
    RGD07's law, the option removed)."""
    data = read_preset_file(preset_path(PRESET))
    data["physical"].pop("friction_weakening", None)
    if applies_to is not None:
        data["physical"]["friction_weakening"] = {**WEAKENING, "applies_to": applies_to}
    return preset_from_dict(PRESET, data)


def law_torque_nm(preset: Preset, omega_rad_s: np.ndarray) -> np.ndarray:
    """The preset's bit torque in N m at the bit speeds ``omega_rad_s``, steady drilling at
    its applied weight (the depth of cut of eq. 34, the wearflat in full contact)."""
    p, sc, law = preset.params, preset.scales, preset.bit_law
    steady = trivial_solution(p)
    return np.array([sc.tob_nm(law.torque(steady.depth_of_cut, steady.wearflat, p.beta,
                                          w * sc.time_s))
                     for w in omega_rad_s])


def coppe_torque_nm(wob_n: float, omega_rad_s: np.ndarray) -> np.ndarray:
    """Castello & Ritto's fitted bit torque (arXiv 2206.14609), N m."""
    w = omega_rad_s
    return wob_n * 0.0239 * (np.tanh(1.91 * w) + 8.5 * w / (1.0 + 5.47 * w * w))


def draw(path: Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    omega = np.linspace(0.0, 20.0, 801)
    base = preset_with(None)
    wob_n = base.physical.applied_wob_n
    fig, ax = plt.subplots(figsize=(7.5, 4.4))
    ax.plot(omega, law_torque_nm(base, omega) / 1e3, "k-", lw=2, label="RGD07 (rate-independent)")
    ax.plot(omega, law_torque_nm(preset_with("friction"), omega) / 1e3, "C0-", lw=2,
            label="weakening on the wearflat friction (floor 0.5, 7 rad/s)")
    ax.plot(omega, law_torque_nm(preset_with("bit"), omega) / 1e3, "C3-", lw=2,
            label="weakening on the whole bit torque (floor 0.5, 7 rad/s): the default")
    ax.plot(omega, coppe_torque_nm(wob_n, omega) / 1e3, "C2--", lw=1.8,
            label="COPPE/UFRJ field fit, Castello & Ritto (2022)")
    for rpm in (35.0, 60.0):
        ax.axvline(rpm * 2.0 * math.pi / 60.0, color="0.6", lw=0.8, ls=":")
        ax.text(rpm * 2.0 * math.pi / 60.0 + 0.15, 0.25, f"{rpm:.0f} rpm", color="0.4",
                fontsize=8)
    ax.set_xlabel("bit speed ω (rad/s)")
    ax.set_ylabel("torque on bit (kN m)")
    sigma_l = base.physical.contact_stress_times_wearflat_n_per_m
    ax.set_title(f"Bit torque at the field point: 8.5-in bit, {wob_n / 1e3:.0f} kN, "
                 f"σℓ = {sigma_l:.0e} N/m", fontsize=10)
    ax.set_xlim(0.0, 20.0)
    ax.set_ylim(0.0, 4.5)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="upper right")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=OUT)
    args = parser.parse_args()
    draw(args.out)
    print(args.out)


if __name__ == "__main__":
    main()
