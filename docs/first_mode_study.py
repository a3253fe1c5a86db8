"""How strongly the bit feeds the first torsional mode (docs/string.md): prints the tables.

In process, the closed-loop bench's own runs (``control.bench.run_in_process``) scored by
the scorecard, on two process workers. Two studies:

1. **The feed.** The stiff drive on the distributed field string at the lumped twin's
   operating point (60 rpm, 60 kN, a moderately worn bit: sigma l = 3e5 N/m), 600 s, over
   the string's torsional and axial loss rates and two bit inertias; beside it the lumped
   twin itself. Printed: the RMS of the low-passed bit speed about its mean over the last
   300 s, its dominant period over T1, the stick fraction and the ringing above the
   cut-off. A first mode the bit drives grows to stick-slip (RMS of tens of rpm); one it
   cannot drive stays at the few rpm of the bit's own noise. Two more rows make the
   collars 40 times stiffer axially: a BHA that moves axially as one body, as the lumped
   twin's does.
2. **The earlier default bit under other losses.** The sharp bit (sigma l = 1e5 N/m, RGD07's
   law; the default until 2026-12-06) at 35 rpm and
   60 kN, 180 s, switch-on at 60 s: stiff, soft_torque and z_torque at torsional rates
   0.1, 0.42 (the source read right) and 0.84 1/s (the earlier misreading). Printed: the
   stick fraction after the switch-on, the period over T1 and the share at the torque limit.
3. **A bit that loses grip with speed** (``physical.friction_weakening``, docs/model.md):
   the preset's losses, 60 kN, 180 s, switch-on at 60 s, stiff and soft_torque; RGD07's
   law, NORCE's friction-only weakening and the COPPE field fit on the whole bit torque, on
   the sharp bit (sigma l = 1e5 N/m) and a worn one (3e5), at 35 and 60 rpm; last, NORCE's
   shape on the whole torque read through a 0.06 s lag (the default preset's law on the worn
   bit). Printed besides: the share of the time the bit is off the rock and the WOB's RMS
   at the bit.

Usage: .venv/bin/python docs/first_mode_study.py [--workers 2] [--plot FILE.png]
       (about 1 min on 2 quiet cores)
"""

from __future__ import annotations

import argparse
import sys
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path
from typing import Any

import numpy as np

from drill_sim_ros.control.bench import run_in_process
from drill_sim_ros.control.rig import rig_physics
from drill_sim_ros.control.scenario import Scenario
from drill_sim_ros.control.scorecard import F, lowpassed_bit_rpm
from drill_sim_ros.model.presets import preset_path
from drill_sim_ros.model.string import STEEL_YOUNGS_MODULUS_PA
from drill_sim_ros.model.validate_input import read_preset_file

FIELD, LUMPED = "field_8p5in_shale", "field_8p5in_shale_lumped"
# RGD07's law (no weakening: floor ratio 1) on the worn bit, and the sharp bit of the default
# until 2026-12-06
WORN_BIT = {"contact_stress_times_wearflat_n_per_m": 3.0e5,
            "friction_weakening": {"floor_ratio": 1.0}}
SHARP_BIT = {"contact_stress_times_wearflat_n_per_m": 1.0e5,
             "friction_weakening": {"floor_ratio": 1.0}}
FEED_RATES = ((0.0, 1.35), (0.02, 1.35), (0.05, 1.35), (0.1, 1.35), (0.84, 1.35),
              (0.42, 0.68),
              (0.0, 0.3), (0.05, 0.3), (0.1, 0.3), (0.2, 0.3))
FEED_BIT_INERTIAS_KG_M2 = (0.3, 100.0)
# the collars' Young's modulus x 40: a BHA nearly rigid in its axial motion, as the lumped
# twin's (its lowest axial mode from about 6 to 40 Hz, far from the blade passage)
RIGID_BHA_RATES = ((0.1, 1.35), (0.84, 1.35))
RIGID_BHA_E_FACTOR = 40.0
DEFAULT_RATES = (0.1, 0.42, 0.84)
CONTROLLERS = ("stiff", "soft_torque", "z_torque")
# physical.friction_weakening of each law (docs/model.md#a-bit-friction-that-falls-with-speed)
LAWS = {"RGD07": None,
        "NORCE friction": {"floor_ratio": 0.5, "speed_rad_s": 7.0, "applies_to": "friction"},
        "COPPE bit": {"floor_ratio": 0.4, "speed_rad_s": 2.1, "applies_to": "bit"},
        "NORCE bit, lag 0.06 s": {"floor_ratio": 0.5, "speed_rad_s": 7.0, "applies_to": "bit",
                                  "response_s": 0.06}}
WEAKENING_BITS_N_PER_M = (1.0e5, 3.0e5)
WEAKENING_RPM = (35.0, 60.0)
TAIL_S = 300.0


def _run(case: dict[str, Any]) -> dict[str, Any]:
    """One run of ``case`` (a Scenario's fields), scored; plus the slow speed's RMS over
    the last TAIL_S seconds."""
    scenario = Scenario(**case)
    preset = scenario.load_preset()
    rig = rig_physics(preset)
    run = run_in_process(scenario)
    rows, card = run.rows, run.score()
    t_s = rows[:, F["sim_time_s"]]
    slow = lowpassed_bit_rpm(rows, rig.cutoff_hz)[t_s >= t_s[-1] - TAIL_S]
    return {**card, "slow_rms_rpm": float(np.std(slow)),
            "t1_s": 1.0 / rig.torsional_modes_hz[0]}


def _string(torsional: float, axial: float, bit_inertia: float,
            collar_e_factor: float = 1.0) -> dict[str, Any]:
    string = {"torsional_damping_per_s": torsional, "axial_damping_per_s": axial,
              "bit_inertia_kg_m2": bit_inertia}
    if collar_e_factor != 1.0:
        pipe, collars = read_preset_file(preset_path(FIELD))["string"]["sections"]
        string["sections"] = [pipe, {**collars, "youngs_modulus_pa":
                                     collar_e_factor * STEEL_YOUNGS_MODULUS_PA}]
    return {"string": string, "physical": WORN_BIT}


def _feed_case(torsional: float, axial: float, inertia: float,
               collar_e_factor: float = 1.0) -> dict[str, Any]:
    return {"preset": FIELD, "controller": "stiff", "duration_s": 600.0,
            "enable_at_s": 200.0, "schedule": ({"t_s": 0, "rpm": 60, "wob_n": 60e3},),
            "overrides": _string(torsional, axial, inertia, collar_e_factor)}


def feed_cases() -> list[tuple[str, dict[str, Any]]]:
    cases = [("the lumped twin (no losses) | - | - | -", {
        "preset": LUMPED, "controller": "stiff", "duration_s": 600.0, "enable_at_s": 200.0})]
    for inertia in FEED_BIT_INERTIAS_KG_M2:
        for torsional, axial in FEED_RATES:
            cases.append((f"{torsional:g} | {axial:g} | {inertia:g} | steel",
                          _feed_case(torsional, axial, inertia)))
    for torsional, axial in RIGID_BHA_RATES:
        cases.append((f"{torsional:g} | {axial:g} | 0.3 | x {RIGID_BHA_E_FACTOR:g}",
                      _feed_case(torsional, axial, 0.3, RIGID_BHA_E_FACTOR)))
    return cases


def default_cases() -> list[tuple[str, dict[str, Any]]]:
    return [(f"{rate:g} | {controller}", {
        "preset": FIELD, "controller": controller,
        "overrides": {"string": {"torsional_damping_per_s": rate}, "physical": SHARP_BIT}})
        for rate in DEFAULT_RATES for controller in CONTROLLERS]


def weakening_cases() -> list[tuple[str, dict[str, Any]]]:
    cases = []
    for sigma_l in WEAKENING_BITS_N_PER_M:
        for law, weakening in LAWS.items():
            physical: dict[str, Any] = {"contact_stress_times_wearflat_n_per_m": sigma_l,
                                        "friction_weakening": weakening or {"floor_ratio": 1.0}}
            for rpm in WEAKENING_RPM:
                for controller in CONTROLLERS[:2]:
                    cases.append((f"{sigma_l:.0e} | {law} | {rpm:g} | {controller}", {
                        "preset": FIELD, "controller": controller,
                        "schedule": ({"t_s": 0, "rpm": rpm, "wob_n": 60e3},),
                        "overrides": {"physical": physical}}))
    return cases


def _period(card: dict[str, Any]) -> str:
    return "-" if card["period_s"] is None else f"{card['period_s'] / card['t1_s']:.2f}"


def plot_feed(path: Path, feed: list[tuple[str, dict[str, Any]]],
              cards: list[dict[str, Any]]) -> None:
    """The slow bit speed's RMS against the torsional loss rate, one line per string, with
    the lumped twin and the RMS of a sine that touches zero at the setpoint."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(8, 5.5))
    lines: dict[str, list[tuple[float, float]]] = {}
    for (label, _), card in zip(feed[1:], cards[1:], strict=True):
        torsional, axial, inertia, collars = (part.strip() for part in label.split("|"))
        name = (f"axial {axial} 1/s, bit {inertia} kg m², collars' E {collars}")
        lines.setdefault(name, []).append((float(torsional), card["slow_rms_rpm"]))
    for name, points in lines.items():
        rate, rms = zip(*sorted(points), strict=True)
        ax.plot(rate, rms, "o-", ms=4, label=name)
    ax.axhline(cards[0]["slow_rms_rpm"], color="k", lw=1.2,
               label="the lumped twin (no losses): sticks, 1.03 T1")
    ax.axhline(60.0 / np.sqrt(2.0), color="tab:red", ls="--", lw=1.0,
               label="a sine touching zero at 60 rpm (42 rpm RMS)")
    ax.axvline(0.42, color="0.4", ls=":", lw=1.0)
    ax.text(0.8, 0.55, "the preset's losses\n(A&vdW 2019) ", color="0.3", fontsize=8,
            ha="right", transform=ax.get_xaxis_transform())
    ax.set_xscale("symlog", linthresh=0.02)
    ticks = sorted({rate for rate, _ in FEED_RATES})
    ax.set_xticks(ticks, [f"{rate:g}" for rate in ticks])
    ax.set_xlim(0.0, 1.0)
    ax.set_yscale("log")
    ax.set_xlabel("torsional loss rate, 1/s (mode 1 damping ratio = rate / 2.66)")
    ax.set_ylabel("slow bit speed RMS, last 300 s, rpm")
    ax.set_title("The stiff drive at 60 rpm, 60 kN: the bit's feed of the first mode",
                 fontsize=10)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.18), ncol=2,
              frameon=False)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--plot", type=Path, help="also draw the first table as a PNG")
    args = parser.parse_args()
    feed, default = feed_cases(), default_cases()
    with ProcessPoolExecutor(args.workers) as pool:
        print("| torsional 1/s | axial 1/s | bit inertia kg m² | collars' E | slow RMS, last "
              "300 s, rpm | period / T1 | stuck | ringing, rpm |\n"
              "|---|---|---|---|---|---|---|---|")
        cards = []
        for (label, _), card in zip(feed, pool.map(_run, [c for _, c in feed]), strict=True):
            cards.append(card)
            print(f"| {label} | {card['slow_rms_rpm']:.1f} | {_period(card)} | "
                  f"{card['stick_fraction']:.2f} | {card['ring_rms_rpm']:.1f} |", flush=True)
        if args.plot:
            plot_feed(args.plot, feed, cards)
        print("\n| torsional 1/s | controller | stuck after the switch-on | period / T1 | "
              "at the limit | status |\n|---|---|---|---|---|---|")
        for (label, _), card in zip(default, pool.map(_run, [c for _, c in default]),
                                    strict=True):
            print(f"| {label} | {card['stick_fraction']:.2f} | {_period(card)} | "
                  f"{card['saturation_fraction']:.3f} | {card['status']} |", flush=True)
        weak = weakening_cases()
        print("\n| sigma l N/m | bit law | rpm | controller | stuck | SSI last 20 s | period / T1 "
              "| ringing, rpm | off the rock | WOB RMS, kN | status |\n"
              "|---|---|---|---|---|---|---|---|---|---|---|")
        for (label, _), card in zip(weak, pool.map(_run, [c for _, c in weak]), strict=True):
            print(f"| {label} | {card['stick_fraction']:.2f} | {card['ssi_last']:.2f} | "
                  f"{_period(card)} | {card['ring_rms_rpm']:.1f} | "
                  f"{card['off_bottom_fraction']:.2f} | "
                  f"{card['wob_rms_n'] * 1e-3:.0f} | {card['status']} |", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
