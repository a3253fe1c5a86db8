"""Predicted first-mode growth against the simulated map (docs/string.md): tables and figure.

For each controller the closed-loop map of the default field preset over surface rpm x WOB
(``drill_sim map ... --t-end 180 --enable-at 60``; its statistics window is the map's
default, the second half of the run, 90-180 s; ``--t-end`` runs longer maps, windowed the
same way), and on the same grid the prediction of
``drill_sim stability`` (control/stability.py: the first mode's loop gain
G = |r_bit| |r_top| |exp(-2 gamma L_pipe)|, grows when G > 1). Every point of the map is run
again through the bench (the same scenario, so the same run) for the scorecard's own status
over the map's window: the prediction agrees where it predicts growth and the status is not
``ok`` (stick-slip, or a stall: the bit held while the drive sits at its torque limit), or
decay and ``ok``. Printed: per controller the agreement share, and the points that disagree
with their G, stick fraction, SSI, status and shares at the torque limit and off bottom;
where it stalls, the depth of cut the bit stuck at and the torque that holds it still
(RGD07 eq. 30 at rest, :func:`static_torque_nm`). Then, at every point where a re-run
stalled, --ensemble members per controller (member k: the bit's sigma l x (1 + k 1e-12),
``scenario.seeded``): how often each drive stalls there, a chance outcome of the bit's
bounce (docs/string.md).

The maps are run (by the command printed) into --maps unless their files are there already
(a re-run resumes them).

Usage: .venv/bin/python docs/stability_map.py [--maps DIR] [--plot docs/img/stability_map.png]
       [--ensemble N] [--t-end SECONDS]
       (the three maps: about 5 min on 2 cores; the prediction: about 20 s; the 168 re-runs:
       about 3 min on 2 cores; the ensemble of 6 at the 4 stalled points: about 3 min)
"""

from __future__ import annotations

import argparse
import subprocess
import sys
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

from drill_sim_ros.control import stability as st
from drill_sim_ros.control.scenario import Scenario, seeded
from drill_sim_ros.model.bit_rock import MODE_STUCK
from drill_sim_ros.model.telemetry import TELEMETRY_INDEX

PRESET = "field_8p5in_shale"
RPM = (20, 35, 50, 65, 80, 100, 140, 180)
WOB_N = (40000, 60000, 80000, 100000, 120000, 140000, 160000)
ENSEMBLE = 6        # members per controller at each point where a re-run stalled
WORKERS = 2
T_END_S = 180.0     # the map's runs (--t-end); the switch-on at 60 s, the window the second half
BOUNCE_SHARE = 0.05  # a point bounces: its bit off the rock more than this share of the window


def map_command(controller: str, out: Path, t_end_s: float = T_END_S) -> list[str]:
    return [sys.executable, "-m", "drill_sim_ros.cli", "map", "--params", PRESET,
            "--controller", controller, "--enable-at", "60",
            "--vary", "surface_rpm=" + ",".join(str(r) for r in RPM),
            "--vary", "wob_n=" + ",".join(str(w) for w in WOB_N),
            "--t-end", f"{t_end_s:g}", "--out", str(out)]


def stuck_share(path: Path) -> np.ndarray:
    """The stick fraction on the (rpm, WOB) grid of a map file (the figure's colour)."""
    import xarray as xr
    with xr.open_dataset(path) as ds:
        return ds.sel(surface_rpm=list(RPM), wob_n=list(WOB_N)).stick_fraction.values


def _point_card(job: tuple[str, float, float, int, float]) -> dict[str, object]:
    return rerun(*job)


def scored(controller: str, t_end_s: float = T_END_S) -> list[list[dict[str, object]]]:
    """The scorecard of every map point of ``controller`` (rerun), indexed [rpm][WOB]."""
    jobs = [(controller, float(r), float(w), 0, t_end_s) for r in RPM for w in WOB_N]
    with ProcessPoolExecutor(WORKERS) as pool:
        cards = list(pool.map(_point_card, jobs))
    return [cards[i * len(WOB_N):(i + 1) * len(WOB_N)] for i in range(len(RPM))]


def predicted(tops: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    """Loop gain G per controller on the grid."""
    preset = st.checked_preset(PRESET)
    out = {c: np.empty((len(RPM), len(WOB_N))) for c in tops}
    for i, rpm in enumerate(RPM):
        for j, wob in enumerate(WOB_N):
            for p in st.predict(preset, tops, float(rpm), float(wob)):
                out[p.controller][i, j] = p.loop_gain
    return out


def point_scenario(controller: str, rpm: float, wob_n: float, member: int = 0,
                   t_end_s: float = T_END_S) -> Scenario:
    """The map's point as a bench scenario (the switch-on at 60 s), ``member`` of its
    ensemble (0: the map's own run)."""
    scenario = Scenario(preset=PRESET, duration_s=t_end_s, control_rate_hz=100.0,
                        controller=controller, enable_at_s=60.0,
                        schedule=({"t_s": 0.0, "rpm": rpm, "wob_n": wob_n},))
    return seeded(scenario, member)


def rerun(controller: str, rpm: float, wob_n: float, member: int = 0,
          t_end_s: float = T_END_S) -> dict[str, object]:
    """The map's point again through the bench (``member`` of its ensemble; 0: the map's
    own run), scored over the map's window (its second half): the scorecard (whose status tells a
    stall from stick-slip) and, for a stall, ``stall_depth_m``, the depth of cut per
    revolution the bit stuck at for good (None otherwise)."""
    from drill_sim_ros.control.bench import run_in_process
    run = run_in_process(point_scenario(controller, rpm, wob_n, member, t_end_s))
    card = run.score(t_end_s / 2)
    return {**card, "stall_depth_m": stall_depth_m(run.rows, card["stall_time_s"])}


def stall_depth_m(rows: np.ndarray, stall_s: float | None) -> float | None:
    """The depth of cut (m per revolution) held through the bit's last stick, from the
    stall's start on (it does not change while the bit is stuck); None without a stall."""
    if stall_s is None:
        return None
    t, mode = rows[:, TELEMETRY_INDEX["sim_time_s"]], rows[:, TELEMETRY_INDEX["mode"]]
    held = np.nonzero((t >= stall_s) & (mode == MODE_STUCK))[0]
    return float(rows[held[0], TELEMETRY_INDEX["depth_of_cut_m"]]) if held.size else None


def static_torque_nm(depth_m: float) -> float:
    """The torque a bit stuck at ``depth_m`` of cut per revolution holds before it slips:
    RGD07 eq. (30) with the wearflat in full contact, T = eps a^2 d / 2 + mu gamma
    sigma l a^2 / 2 (the preset's law is weakened only while it turns)."""
    p = st.checked_preset(PRESET).physical
    a2 = p.bit_radius_m ** 2
    return 0.5 * a2 * (p.intrinsic_specific_energy_pa * depth_m
                       + p.mu_gamma * p.contact_stress_times_wearflat_n_per_m)


def stall_text(card: dict[str, object]) -> str:
    """``stalled at t s, d mm: holds T kN m`` for a stalled re-run, else its status."""
    depth = card["stall_depth_m"]
    if card["status"] != "stalled" or depth is None:
        return str(card["status"])
    return (f"stalled at {card['stall_time_s']:.0f} s, {1e3 * depth:.0f} mm: holds "
            f"{static_torque_nm(depth) / 1e3:.0f} kN m")


def report(controller: str, gain: np.ndarray, cards: list[list[dict[str, object]]]
           ) -> list[tuple[int, int]]:
    """Agreement, then every disagreeing point with its status; the stalled points' (rpm,
    WOB) grid indices."""
    status = np.array([[str(c["status"]) for c in row] for row in cards])
    fails = status != "ok"
    agree = (gain > 1.0) == fails
    stalled = [(int(i), int(j)) for i, j in zip(*np.nonzero(status == "stalled"), strict=True)]
    print(f"\n{controller}: agreement {agree.sum()} of {agree.size} "
          f"({agree.mean():.0%}); simulated stick-slip at {(status == 'stick-slip').sum()}, "
          f"stalled at {len(stalled)}, predicted growth at {(gain > 1.0).sum()}")
    print("| rpm | WOB kN | G | predicted | stuck | SSI | status, at the torque limit, "
          "off bottom |")
    print("|---|---|---|---|---|---|---|")
    for i, j in zip(*np.nonzero(~agree), strict=True):
        card = cards[i][j]
        print(f"| {RPM[i]} | {WOB_N[j] / 1e3:.0f} | {gain[i, j]:.2f} | "
              f"{'grows' if gain[i, j] > 1 else 'decays'} | {card['stick_fraction']:.2f} | "
              f"{card['ssi_mean'] or 0.0:.2f} | {stall_text(card)}, "
              f"{card['saturation_fraction']:.2f}, {card['off_bottom_fraction']:.2f} |")
    kept = agree.size - len(stalled)
    agree_kept = sum(bool(agree[i, j]) for i, j in np.ndindex(agree.shape)
                     if status[i, j] != "stalled")
    print(f"{controller}: without the {len(stalled)} stalled points: {agree_kept} of {kept} "
          f"({agree_kept / kept:.0%})")
    return stalled


def _member_status(job: tuple[str, float, float, int, float]) -> tuple[str, float | None]:
    card = rerun(*job)
    return str(card["status"]), card["stall_depth_m"]


def stall_ensemble(points: list[tuple[int, int]], members: int,
                   t_end_s: float = T_END_S) -> None:
    """At each point, ``members`` runs per controller: how many stall, stick-slip or are
    ok, and the depths of cut the stalled ones stuck at (each run on its own process,
    ``WORKERS`` at a time)."""
    print(f"\nstalls over an ensemble of {members} (member k: sigma l x (1 + k 1e-12)): "
          "stalled / stick-slip / ok, per controller")
    print("| rpm | WOB kN | " + " | ".join(st.CONTROLLERS) + " |")
    print("|---|---|" + "---|" * len(st.CONTROLLERS))
    jobs = [(c, float(RPM[i]), float(WOB_N[j]), k, t_end_s) for i, j in points
            for c in st.CONTROLLERS for k in range(members)]
    with ProcessPoolExecutor(WORKERS) as pool:
        results = iter(pool.map(_member_status, jobs))
        totals = {c: 0 for c in st.CONTROLLERS}
        depths: list[float] = []
        for i, j in points:
            cells = []
            for c in st.CONTROLLERS:
                runs = [next(results) for _ in range(members)]
                counts = [sum(s == name for s, _ in runs)
                          for name in ("stalled", "stick-slip", "ok")]
                totals[c] += counts[0]
                depths += [d for s, d in runs if s == "stalled" and d is not None]
                cells.append(" / ".join(str(n) for n in counts))
            print(f"| {RPM[i]} | {WOB_N[j] / 1e3:.0f} | " + " | ".join(cells) + " |")
    print("stalled in all: " + ", ".join(f"{c} {n} of {members * len(points)}"
                                         for c, n in totals.items()))
    if depths:
        print(f"depth of cut at the stalls: {1e3 * min(depths):.0f}-{1e3 * max(depths):.0f} mm "
              f"(holding {static_torque_nm(min(depths)) / 1e3:.0f}-"
              f"{static_torque_nm(max(depths)) / 1e3:.0f} kN m)")


def plot(path: Path, gains: dict[str, np.ndarray], stuck: dict[str, np.ndarray],
         fails: dict[str, np.ndarray], stalled: dict[str, list[tuple[int, int]]],
         bouncing: dict[str, np.ndarray], t_end_s: float = T_END_S) -> None:
    """One panel per controller: the simulated stick fraction (colour; a ring: the status
    not ok), the predicted G = 1 contour, the points where they disagree, the ones where
    the bit bounces (off the rock more than BOUNCE_SHARE of the window: a dot) and the
    ones that stalled (a square, drawn only where there are any)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, len(gains), figsize=(5.2 * len(gains), 4.4), sharey=True)
    x, y = np.array(RPM, float), np.array(WOB_N, float) / 1e3
    for ax, (name, gain) in zip(np.atleast_1d(axes), gains.items(), strict=True):
        sticks = fails[name]
        mesh = ax.pcolormesh(x, y, stuck[name].T, shading="nearest", cmap="Reds", vmin=0,
                             vmax=1)
        xx, yy = np.meshgrid(x, y, indexing="ij")
        ax.scatter(xx[sticks], yy[sticks], s=70, facecolors="none", edgecolors="k",
                   label="simulated: not ok")
        wrong = (gain > 1.0) != sticks
        ax.scatter(xx[wrong], yy[wrong], marker="x", s=60, c="tab:blue",
                   label="prediction disagrees")
        ax.scatter(xx[bouncing[name]], yy[bouncing[name]], marker=".", s=30, c="tab:green",
                   label=f"bit off the rock > {BOUNCE_SHARE:.0%} of the window")
        held = np.zeros(gain.shape, dtype=bool)
        for i, j in stalled[name]:
            held[i, j] = True
        if held.any():
            ax.scatter(xx[held], yy[held], marker="s", s=150, facecolors="none",
                       edgecolors="tab:purple", linewidths=1.5, label="stalled")
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
    fig.colorbar(mesh, ax=axes, label=f"stuck share, {t_end_s / 2:g}-{t_end_s:g} s (simulated)")
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
    parser.add_argument("--ensemble", type=int, default=ENSEMBLE,
                        help="members per controller at each stalled point (0: none)")
    parser.add_argument("--t-end", type=float, default=T_END_S,
                        help="each run's seconds (the switch-on at 60 s, the window the "
                             "second half; default %(default)g)")
    args = parser.parse_args()
    if args.t_end < 120.0:
        parser.error(f"--t-end {args.t_end:g}: at least 120 s (the switch-on is at 60 s "
                     "and the window is the second half)")
    args.maps.mkdir(parents=True, exist_ok=True)
    stuck = {}
    for c in st.CONTROLLERS:
        out = args.maps / (f"map_{c}.nc" if args.t_end == T_END_S
                           else f"map_{c}_{args.t_end:g}s.nc")
        cmd = map_command(c, out, args.t_end)
        print("$ drill_sim " + " ".join(cmd[3:]))
        if not out.exists():
            subprocess.run(cmd, check=True)
        stuck[c] = stuck_share(out)
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
    cards = {c: scored(c, args.t_end) for c in st.CONTROLLERS}
    stalled = {c: report(c, gains[c], cards[c]) for c in st.CONTROLLERS}
    fails = {c: np.array([[str(x["status"]) != "ok" for x in row] for row in cards[c]])
             for c in st.CONTROLLERS}
    bouncing = {c: np.array([[float(x["off_bottom_fraction"]) > BOUNCE_SHARE for x in row]
                             for row in cards[c]]) for c in st.CONTROLLERS}
    bit_check()
    points = sorted(set().union(*stalled.values()))
    if args.ensemble > 0 and points:
        stall_ensemble(points, args.ensemble, args.t_end)
    if args.plot is not None:
        plot(args.plot, gains, stuck, fails, stalled, bouncing, args.t_end)
        print(f"wrote {args.plot}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
