"""Predicted first-mode growth against the simulated map (docs/string.md): tables and figure.

For each controller the closed-loop map of the default field preset over surface rpm x WOB
(``drill_sim map ... --t-end 180 --enable-at 60``; its statistics window is the map's
default, the second half of the run, 90-180 s), and on the same grid the prediction of
``drill_sim stability`` (control/stability.py: the first mode's loop gain
G = |r_bit| |r_top| |exp(-2 gamma L_pipe)|, grows when G > 1). A simulated point counts as
stick-slip by the scorecard's rule as far as the map records it: stuck 10 % of the window
or more, or a mean SSI of 1 or more. Printed: per controller the agreement share, and the
points that disagree with their G, stick fraction and SSI, each run again through the
bench for the scorecard's status (a stall, the bit held while the drive sits at its torque
limit, is not the first mode's growth) and its shares at the torque limit and off bottom.

The maps are run (by the command printed) into --maps unless their files are there already
(a re-run resumes them).

Usage: .venv/bin/python docs/stability_map.py [--maps DIR] [--plot docs/img/stability_map.png]
       (the three maps: about 5 min on 2 cores; the prediction: about 20 s)
"""

from __future__ import annotations

import argparse
import subprocess
import sys
from pathlib import Path

import numpy as np

from drill_sim_ros.control import stability as st
from drill_sim_ros.control.scorecard import SSI_OK, STICK_FRACTION_OK

PRESET = "field_8p5in_shale"
RPM = (20, 35, 50, 65, 80, 100, 140, 180)
WOB_N = (40000, 60000, 80000, 100000, 120000, 140000, 160000)


def map_command(controller: str, out: Path) -> list[str]:
    return [sys.executable, "-m", "drill_sim_ros.cli", "map", "--params", PRESET,
            "--controller", controller, "--enable-at", "60",
            "--vary", "surface_rpm=" + ",".join(str(r) for r in RPM),
            "--vary", "wob_n=" + ",".join(str(w) for w in WOB_N),
            "--t-end", "180", "--out", str(out)]


def simulated(path: Path) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(stick-slip?, stick fraction, SSI) on the (rpm, WOB) grid of a map file."""
    import xarray as xr
    with xr.open_dataset(path) as ds:
        ds = ds.sel(surface_rpm=list(RPM), wob_n=list(WOB_N))
        stuck = ds.stick_fraction.values
        ssi = ds.ssi.values
    return (stuck >= STICK_FRACTION_OK) | (ssi >= SSI_OK), stuck, ssi


def predicted(tops: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    """Loop gain G per controller on the grid."""
    preset = st.checked_preset(PRESET)
    out = {c: np.empty((len(RPM), len(WOB_N))) for c in tops}
    for i, rpm in enumerate(RPM):
        for j, wob in enumerate(WOB_N):
            for p in st.predict(preset, tops, float(rpm), float(wob)):
                out[p.controller][i, j] = p.loop_gain
    return out


def rerun(controller: str, rpm: float, wob_n: float) -> dict[str, object]:
    """The map's point again through the bench, scored over the map's window (90-180 s):
    the scorecard's status (which tells a stall from stick-slip) and what the map lacks."""
    from drill_sim_ros.control.bench import run_in_process
    from drill_sim_ros.control.scenario import Scenario
    scenario = Scenario(preset=PRESET, duration_s=180.0, control_rate_hz=100.0,
                        controller=controller, enable_at_s=60.0,
                        schedule=({"t_s": 0.0, "rpm": rpm, "wob_n": wob_n},))
    return run_in_process(scenario).score(90.0)


def report(controller: str, gain: np.ndarray, sim: tuple[np.ndarray, ...]) -> None:
    """Agreement, then every disagreeing point with its re-run's status."""
    sticks, stuck, ssi = sim
    agree = (gain > 1.0) == sticks
    print(f"\n{controller}: agreement {agree.sum()} of {agree.size} "
          f"({agree.mean():.0%}); simulated stick-slip at {sticks.sum()}, "
          f"predicted growth at {(gain > 1.0).sum()}")
    print("| rpm | WOB kN | G | predicted | stuck | SSI | simulated | re-run: status, "
          "at the torque limit, off bottom |")
    print("|---|---|---|---|---|---|---|---|")
    stalls = 0
    for i, j in zip(*np.nonzero(~agree), strict=True):
        card = rerun(controller, float(RPM[i]), float(WOB_N[j]))
        stalls += card["status"] == "stalled"
        print(f"| {RPM[i]} | {WOB_N[j] / 1e3:.0f} | {gain[i, j]:.2f} | "
              f"{'grows' if gain[i, j] > 1 else 'decays'} | {stuck[i, j]:.2f} | "
              f"{ssi[i, j]:.2f} | {'stick-slip' if sticks[i, j] else 'ok'} | "
              f"{card['status']}, {card['saturation_fraction']:.2f}, "
              f"{card['off_bottom_fraction']:.2f} |")
    kept = agree.size - stalls
    print(f"{controller}: without the {stalls} stalled points: {agree.sum()} of {kept} "
          f"({agree.sum() / kept:.0%})")


def plot(path: Path, gains: dict[str, np.ndarray],
         sims: dict[str, tuple[np.ndarray, ...]]) -> None:
    """One panel per controller: the simulated stick fraction (colour; a ring: stick-slip
    by the rule), the predicted G = 1 contour and the points where they disagree."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, len(gains), figsize=(5.2 * len(gains), 4.4), sharey=True)
    x, y = np.array(RPM, float), np.array(WOB_N, float) / 1e3
    for ax, (name, gain) in zip(np.atleast_1d(axes), gains.items(), strict=True):
        sticks, stuck, _ = sims[name]
        mesh = ax.pcolormesh(x, y, stuck.T, shading="nearest", cmap="Reds", vmin=0, vmax=1)
        xx, yy = np.meshgrid(x, y, indexing="ij")
        ax.scatter(xx[sticks], yy[sticks], s=70, facecolors="none", edgecolors="k",
                   label="simulated stick-slip")
        wrong = (gain > 1.0) != sticks
        ax.scatter(xx[wrong], yy[wrong], marker="x", s=60, c="tab:blue",
                   label="prediction disagrees")
        finite = np.minimum(gain, 10.0)       # a bit unstable by itself: G infinite
        levels = ax.contour(x, y, finite.T, levels=[1.0], colors="tab:blue", linewidths=2)
        ax.clabel(levels, fmt="G = 1", fontsize=8)
        agree = 1.0 - wrong.mean()
        ax.set_title(f"{name}: agreement {agree:.0%}", fontsize=10)
        ax.set_xlabel("surface rpm")
        ax.set_xscale("log")
        ax.set_xticks(x, [str(r) for r in RPM])
        ax.minorticks_off()
    np.atleast_1d(axes)[0].set_ylabel("applied WOB, kN")
    np.atleast_1d(axes)[0].legend(fontsize=8, loc="lower right")
    fig.colorbar(mesh, ax=axes, label="stuck share, 90-180 s (simulated)")
    fig.suptitle(f"{PRESET}: first-mode growth predicted (G > 1, left of/above the blue "
                 "line) against the closed-loop map", fontsize=10)
    fig.savefig(path, dpi=110, bbox_inches="tight")
    plt.close(fig)


def bit_check(sigma: float = 0.6) -> None:
    """r_bit measured in the time domain (string_instruments.measure_bit_reflection) beside
    the analytic one the prediction uses, at s = sigma + 2 pi i f (the measurement needs
    Re s > 0: steady drilling on RGD07's law departs after some seconds)."""
    from drill_sim_ros.model import bit_reflection as br
    from drill_sim_ros.model import string_instruments as si
    preset = st.checked_preset(PRESET)
    sc = preset.scales
    f = np.array([0.1, 0.15, 0.2, 0.3, 0.5, 1.0])
    s = sigma + 2j * np.pi * f
    print(f"\n|r_bit| at s = {sigma} + 2 pi i f, f = {', '.join(f'{x:g}' for x in f)} Hz: "
          "measured / analytic, largest |difference|")
    for rpm, wob in ((35, 60e3), (60, 100e3), (100, 60e3)):
        slope = st.bit_slope_nm_s(preset, rpm, wob)
        formula = br.bit_reflection_at(preset.string, slope, st.response_s(preset), s)
        measured = si.measure_bit_reflection(preset, sc.omega_from_rpm(rpm),
                                             sc.w_from_newton(wob), s)
        print(f"| {rpm} rpm {wob / 1e3:.0f} kN | b = {slope:.0f} N m s | "
              + " ".join(f"{m:.2f}/{a:.2f}" for m, a in zip(np.abs(measured),
                                                              np.abs(formula), strict=True))
              + f" | {np.max(np.abs(measured - formula)):.2f} |")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--maps", type=Path, default=Path("stability_maps"),
                        help="folder of the map files (run there if absent)")
    parser.add_argument("--plot", type=Path, default=None, help="PNG to write")
    args = parser.parse_args()
    args.maps.mkdir(parents=True, exist_ok=True)
    sims = {}
    for c in st.CONTROLLERS:
        out = args.maps / f"map_{c}.nc"
        cmd = map_command(c, out)
        print("$ drill_sim " + " ".join(cmd[3:]))
        if not out.exists():
            subprocess.run(cmd, check=True)
        sims[c] = simulated(out)
    tops = st.measure_tops(PRESET, list(st.CONTROLLERS))
    band = st.top_band_hz(st.checked_preset(PRESET))
    for c, r in tops.items():
        k = int(np.argmin(np.abs(r)))
        print(f"|r_top| {c}: {abs(r[k]):.3f} at its least ({band[k]:.3f} Hz)")
    gains = predicted(tops)
    alone = np.isinf(gains[st.CONTROLLERS[0]])
    print(f"the bit unstable by itself (G infinite): {alone.sum()} points, at "
          + ", ".join(f"{RPM[i]} rpm {WOB_N[j] / 1e3:.0f} kN" for i, j in zip(*np.nonzero(alone),
                                                                     strict=True)))
    for c in st.CONTROLLERS:
        report(c, gains[c], sims[c])
    bit_check()
    if args.plot is not None:
        plot(args.plot, gains, sims)
        print(f"wrote {args.plot}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
