"""The paper's figures (RGD07 Figs. 5, 7-9, 11-14) and a field map, from the model.

``drill_sim figures -o docs/gallery`` writes one PNG per figure, each captioned with its
parameters and the trend the paper states. Time histories (Figs. 5, 7, 8) are single runs
in this process; the parameter studies are maps computed by :mod:`engine` on one Dask
cluster (kept in ``cache`` as NetCDF when given, so a re-run resumes them).
"""

from __future__ import annotations

import math
import tempfile
import textwrap
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
import xarray as xr
from matplotlib.colors import ListedColormap

from drill_sim_ros.model import analysis
from drill_sim_ros.model import kernel as k
from drill_sim_ros.model.errors import DrillSimError
from drill_sim_ros.model.params import DimensionlessParams
from drill_sim_ros.model.presets import load_preset
from drill_sim_ros.model.simulator import SimConfig, Simulator
from drill_sim_ros.study import engine, plot, store
from drill_sim_ros.study.grid import Control, MapSpec, Numerics, parse_vary
from drill_sim_ros.study.point import torsional_period
from drill_sim_ros.study.progress import MapProgress
from drill_sim_ros.study.regime import BOUNCING, STICK_SLIP

TAU_END = 600.0
AVERAGE_FROM = 300.0
FIG9_TAU_END = 3000.0     # first sticks of the Fig. 9 base case come late
DPI = 110


@dataclass
class Maps:
    """Computes the figures' maps on one client; NetCDF files in ``directory``."""

    client: object
    directory: Path
    progress: bool

    def get(self, name: str, spec: MapSpec) -> xr.Dataset:
        path = self.directory / f"{name}.nc"
        if path.exists():
            attrs = store.load(path).attrs
            if (attrs.get("spec_json") != spec.to_json()
                    or attrs.get("model_fingerprint")
                    != store.model_fingerprint(spec.control is not None)):
                path.unlink()              # the figure or the model changed: start afresh
        bar = MapProgress(self.progress)
        try:
            run = engine.run_map(spec, path, self.client, progress=bar)
        finally:
            bar.close()
        if run.interrupted:
            raise KeyboardInterrupt
        return run.dataset


def spec(preset: str, *vary: str, dtau: float | None = None,
         tau_end: float = TAU_END, average_from: float | None = None,
         control: Control | None = None, **base: float) -> MapSpec:
    """A map of ``preset`` (groups overridden by ``base``) over the ``vary`` axes."""
    pr = load_preset(preset)
    params = pr.params.with_(**base) if base else pr.params
    axes = tuple(parse_vary(v) for v in vary)
    start = min(AVERAGE_FROM, tau_end / 2) if average_from is None else average_from
    num = Numerics(tau_end=tau_end, average_from=start, dtau=dtau or pr.dtau)
    return MapSpec(params, axes, num, scales=pr.scales if pr.is_physical else None,
                   preset=pr.name, control=control)


def values_axis(name: str, values: list[float]) -> str:
    return f"{name}=" + ",".join(f"{v:g}" for v in values)


def caption(fig: plt.Figure, text: str, lines_reserved: int) -> None:
    """The caption below the axes (wrapped to the figure width)."""
    width = int(fig.get_figwidth() * 13)
    wrapped = "\n".join(textwrap.fill(p, width) for p in text.split("\n"))
    fig.text(0.01, 0.005, wrapped, ha="left", va="bottom", fontsize=8)
    bottom = (lines_reserved * 8 * 1.45 + 8) / (fig.get_figheight() * 72)
    fig.tight_layout(rect=(0, bottom, 1, 1))


def save(fig: plt.Figure, out: Path) -> Path:
    fig.savefig(out, dpi=DPI)
    plt.close(fig)
    return out


def trace(preset: str, tau_end: float, every_tau: float = 0.01,
          dtau: float = 1e-4) -> np.ndarray:
    """Sample rows (``kernel.C_*``) of one run from the trivial state perturbed by 0.01."""
    pr = load_preset(preset)
    sim = Simulator(pr.params, SimConfig(dtau=dtau), perturb_v=0.01)
    every = max(1, round(every_tau / dtau))
    parts, left = [], sim.steps_for(tau_end)
    while left > 0:
        n = min(left, 500_000)
        samples = sim.advance(n, every=every)
        data = samples.data.copy()
        data[:, k.C_PHI] += samples.angle_offset
        parts.append(data)
        left -= n
    return np.concatenate(parts)


def groups_text(p: DimensionlessParams, skip: tuple[str, ...] = ()) -> str:
    names = {"n": "n", "psi": "ψ", "beta": "β", "lam": "λ", "w0": "W₀", "omega0": "ω₀"}
    return ", ".join(f"{names[g]} = {getattr(p, g):g}" for g in names if g not in skip)


# ---- time histories ------------------------------------------------------------------------
def fig8(out: Path, _maps: Maps) -> Path:
    fig, axes = plt.subplots(2, 1, figsize=(9, 6), sharex=True)
    for ax, preset, tag in zip(axes, ("fig5_8a", "fig8b"), ("(a) β = 0.3", "(b) β = 1.3"),
                               strict=True):
        rows = trace(preset, 400.0)
        omega0 = load_preset(preset).params.omega0
        ax.plot(rows[:, k.C_TAU], rows[:, k.C_OMEGA], lw=0.4)
        ax.axhline(omega0, color="k", lw=0.6, ls="--", label="ω₀")
        stuck = rows[rows[:, k.C_MODE] == k.MODE_STUCK]
        if stuck.size:
            ax.axvline(stuck[0, k.C_TAU], color="tab:red", lw=0.8,
                       label=f"first stick τ = {stuck[0, k.C_TAU]:.1f}")
        ax.set_ylabel("bit speed ω")
        ax.set_title(tag, fontsize=10, loc="left")
        ax.legend(fontsize=8, loc="upper left")
    axes[-1].set_xlabel("τ")
    caption(fig, "RGD07 Fig. 8: torsional vibrations after a perturbation v(0) = v₀ + 0.01 "
            f"({groups_text(load_preset('fig5_8a').params, ('beta',))}; Δτ = 1e-4). "
            "Paper: for β < 1 the oscillations grow until a stick-slip limit cycle (ω "
            "between 0 and about 2ω₀); for β > 1 they stay bounded, without stick.", 3)
    return save(fig, out / "fig8.png")


def fig5(out: Path, _maps: Maps) -> Path:
    pr = load_preset("fig5_8a")
    rows = trace(pr.name, 600.0, every_tau=0.002)
    late = rows[rows[:, k.C_TAU] > 550.0]
    triv = analysis.trivial_solution(pr.params)
    fig, axes = plt.subplots(1, 2, figsize=(10, 4.8))
    modes = ListedColormap(["tab:blue", "tab:orange", "tab:red", "tab:purple"])
    sc = axes[0].scatter(late[:, k.C_V], late[:, k.C_OMEGA], c=late[:, k.C_MODE], s=0.5,
                         cmap=modes, vmin=-0.5, vmax=3.5)
    axes[0].plot(triv.v, triv.omega, "ws", mec="k", label="trivial solution (eq. 34)")
    axes[0].set_xlabel("axial velocity v")
    axes[0].set_ylabel("bit speed ω")
    axes[0].legend(fontsize=8)
    cb = plt.colorbar(sc, ax=axes[0], ticks=range(4))
    cb.ax.set_yticklabels(["cutting", "lost contact", "stuck", "off bottom"], fontsize=7)
    axes[1].plot(late[:, k.C_OMEGA], late[:, k.C_T_PIPE] - triv.torque, lw=0.5)
    axes[1].set_xlabel("bit speed ω")
    axes[1].set_ylabel("pipe twist φ = Φₛ − Φ − T₀")
    caption(fig, f"RGD07 Fig. 5: phase diagram of the limit cycle ({groups_text(pr.params)}; "
            "τ in [550, 600], Δτ = 1e-4). Left: (v, ω) coloured by contact mode; right: "
            "torsional phase plane. Paper: the motion settles on a strict limit cycle of "
            "stick-slip, with fast axial oscillations during the slip phase.", 3)
    return save(fig, out / "fig5.png")


def fig7(out: Path, _maps: Maps) -> Path:
    fig = plt.figure(figsize=(10, 10))
    notes = []
    for row, preset in enumerate(("fig7", "fig5_8a")):
        pr = load_preset(preset)
        rows = trace(pr.name, 400.0, every_tau=0.001)
        cycles = _two_cycles(rows[rows[:, k.C_TAU] > 300.0])
        for i, (t0, t1) in enumerate(cycles):
            cyc = rows[(rows[:, k.C_TAU] >= t0) & (rows[:, k.C_TAU] < t1)]
            ax = fig.add_subplot(2, 2, 2 * row + i + 1, projection="polar")
            ax.plot(np.mod(cyc[:, k.C_PHI], 2 * np.pi), np.maximum(cyc[:, k.C_DOC], 0.0),
                    lw=0.6, color=("tab:blue", "tab:orange")[i])
            ax.set_title(f"{pr.name}, cycle {i + 1}: τ in [{t0:.1f}, {t1:.1f}]", fontsize=9)
            ax.tick_params(labelsize=7)
        notes.append(f"{pr.name}: {groups_text(pr.params)}")
    caption(fig, "RGD07 Fig. 7: depth of cut δ (radius; δ < 0 drawn at 0) against the bit "
            "angle Φ mod 2π over two successive torsional cycles (slip onset to slip onset), "
            f"top: the paper's Fig. 7 case ({notes[0]}), bottom: the Fig. 5 case ({notes[1]}); "
            "Δτ = 1e-4. Paper: successive cycles are quasi-identical up to a phase shift, a "
            "repetitive bottom-hole pattern.", 4)
    return save(fig, out / "fig7.png")


def _two_cycles(rows: np.ndarray) -> list[tuple[float, float]]:
    """Two successive torsional cycles: slip onset to slip onset, else by the period."""
    tau = rows[:, k.C_TAU]
    stuck = rows[:, k.C_MODE] == k.MODE_STUCK
    slips = tau[np.flatnonzero(stuck[:-1] & ~stuck[1:]) + 1]
    if slips.size >= 3:
        return [(slips[0], slips[1]), (slips[1], slips[2])]
    period = torsional_period(tau, rows[:, k.C_OMEGA])
    if not math.isfinite(period):
        raise DrillSimError("fig7: no torsional cycle found")
    return [(tau[0], tau[0] + period), (tau[0] + period, tau[0] + 2 * period)]


# ---- parameter studies ------------------------------------------------------------------
FIG9_AXES = (("w0", "W₀", "w0=7.9:12:14"), ("omega0", "ω₀", "omega0=0.5:10:14"),
             ("psi", "ψ", "psi=10:300:14"), ("lam", "λ", "lam=2:7.95:14"),
             ("beta", "β", "beta=0.05:0.95:14"))


def fig9(out: Path, maps: Maps) -> Path:
    fig, axes = plt.subplots(2, 3, figsize=(11, 7))
    base = load_preset("fig9").params
    for ax, (name, label, vary) in zip(axes.flat, FIG9_AXES, strict=False):
        ds = maps.get(f"fig9_{name}", spec("fig9", vary, tau_end=FIG9_TAU_END))
        x, tsk = ds[name].values, ds["first_stick_tau"].values
        ax.semilogy(x, tsk, "o-", ms=4)
        none = ~np.isfinite(tsk)
        ax.plot(x[none], np.full(none.sum(), FIG9_TAU_END), "v", color="tab:red", ms=5,
                label=f"no stick by τ = {FIG9_TAU_END:g}")
        ax.axvline(getattr(base, name), color="grey", lw=0.6, ls=":")
        ax.set_xlabel(label)
        ax.set_ylabel("τ_sk (log)")
        ax.set_ylim(1.0, FIG9_TAU_END * 1.6)
        if none.any():
            ax.legend(fontsize=7)
    axes.flat[-1].axis("off")
    caption(fig, f"RGD07 Fig. 9: first-stick time τ_sk against W₀, ω₀, ψ, λ and β "
            f"({groups_text(base)} unless varied; dotted: the base value; τ ≤ {FIG9_TAU_END:g}, "
            "Δτ = 1e-4, perturbation v(0) = v₀ + 0.01). Paper: τ_sk increases with λ and β "
            "(asymptote at β = 1) and decreases with W₀; increasing ω₀ mitigates stick-slip, "
            "with windows without stick (anti-resonance, quasi-limit cycle); τ_sk decreases "
            "with ψ beyond the anti-resonance range. τ_sk depends on the perturbation: "
            "trends only.", 5)
    return save(fig, out / "fig9.png")


FIG11_AXES = (("w0_ratio", "W₀′ = W₀/λ", "w0_ratio=1.1:2.6:14"),
              ("omega0", "ω₀", "omega0=1:10:14"), ("psi", "ψ", "psi=20:300:14"),
              ("beta", "β", "beta=0.05:0.95:14"))


def fig11(out: Path, maps: Maps) -> Path:
    fig, axes = plt.subplots(2, 2, figsize=(10, 7.5))
    base = load_preset("fig11").params
    for ax, (name, label, vary) in zip(axes.flat, FIG11_AXES, strict=True):
        ds = maps.get(f"fig11_{name}", spec("fig11", vary))
        x = ds[name].values
        bounced = ds["regime"].values == BOUNCING
        ax.plot(x, ds["kappa"].values, "o-", ms=4, label="κ = 1 − ⟨W_f⟩/λ (eq. 42)")
        ax.plot(x, ds["kappa_from_depth"].values, "x--", ms=5,
                label="(⟨δ⟩ − δ₀)/λ (eq. 45a)")
        if bounced.any():
            ax.plot(x[bounced], ds["kappa"].values[bounced], "s", mfc="none", color="k",
                    ms=8, label="bit bounced")
        ax.axvline(base.w0 / base.lam if name == "w0_ratio" else getattr(base, name),
                   color="grey", lw=0.6, ls=":")
        kept = np.concatenate([ds[v].values[~bounced] for v in ("kappa", "kappa_from_depth")])
        if np.isfinite(kept).any():
            ax.set_ylim(min(0.0, np.nanmin(kept)), 1.15 * np.nanmax(kept) + 1e-3)
        ax.set_xlabel(label)
        ax.set_ylabel("κ")
        ax.legend(fontsize=7)
    caption(fig, f"RGD07 Fig. 11: κ against W₀′, ω₀, ψ and β (W₀′ = 1.7, λ = {base.lam:g}, "
            f"ω₀ = 4, ψ = 63, n = 6, β = 0.28 unless varied; W₀′ varied with λ held; "
            f"averages over τ in [{AVERAGE_FROM:g}, {TAU_END:g}], Δτ = 1e-4). Paper: κ "
            "increases with ψ and W₀′, decreases with ω₀, and is virtually insensitive to "
            "β. Eqs. 42 and 45a agree on a limit cycle (eq. 44). Squares: the bit bounced (the "
            "y range leaves out their eq. 45a values).", 4)
    return save(fig, out / "fig11.png")


FIG12_OMEGAS = [1.0, 2.0, 3.0, 4.0, 6.0, 8.0, 10.0]


FIG12_LAM_ADMISSIBLE = 5.0     # W0' = 1.6: below the bouncing bound of Figs. 13-14


def fig12(out: Path, maps: Maps) -> Path:
    cases = ((0.9, "paper's case, λ = 0.9 (W₀′ = 8.9)"),
             (FIG12_LAM_ADMISSIBLE, f"λ = {FIG12_LAM_ADMISSIBLE:g} (W₀′ = 1.6)"))
    fig, axes = plt.subplots(2, 2, figsize=(11, 9.5))
    for row_axes, (lam, tag) in zip(axes, cases, strict=True):
        name = "fig12" if lam == 0.9 else "fig12_lam5"
        ds = maps.get(name, spec("fig12", "beta=0.276,1.5",
                                 values_axis("omega0", FIG12_OMEGAS), lam=lam))
        for ax, beta in zip(row_axes, ds["beta"].values, strict=True):
            _es_panel(ax, ds.sel(beta=beta), load_preset("fig12").params.with_(
                beta=float(beta), lam=lam))
            ax.set_title(f"β = {beta:g}, {tag}", fontsize=9)
    caption(fig, f"RGD07 Fig. 12: E-S diagram for β = 0.276 and 1.5 with ω₀ = "
            f"{', '.join(f'{w:g}' for w in FIG12_OMEGAS)} (W₀ = 8, ψ = 100, n = 6; top: the "
            f"paper's λ = 0.9, bottom: λ = {FIG12_LAM_ADMISSIBLE:g}; averages over τ in "
            f"[{AVERAGE_FROM:g}, {TAU_END:g}], Δτ = 5e-5; circled: the bit bounced). Paper: "
            "the state point moves up the friction line with increasing ω₀ (η decreases) and "
            "converges to the trivial solution (minimum efficiency).", 3)
    return save(fig, out / "fig12.png")


def _es_panel(ax: plt.Axes, row: xr.Dataset, p0: DimensionlessParams) -> None:
    """One E-S panel: friction line (eq. 50), cutting point, trivial state, the runs."""
    s, e = row["drilling_strength"].values, row["specific_energy"].values
    delta0 = p0.w0 - p0.lam
    triv_s, triv_e = p0.w0 / delta0, analysis.trivial_solution(p0).torque / delta0
    line_s = np.linspace(min(1.0, np.nanmin(s)), max(np.nanmax(s), triv_s) * 1.05, 50)
    ax.plot(line_s, 1 - p0.beta + p0.beta * line_s, "k-", lw=0.8,
            label="friction line (eq. 50)")
    ax.plot([1], [1], "k*", ms=10, label="cutting point")
    ax.plot([triv_s], [triv_e], "ws", mec="k", ms=9, label="trivial solution")
    sc = ax.scatter(s, e, c=row["omega0"].values, cmap="plasma", s=40, zorder=3)
    for si, ei, w in zip(s, e, row["omega0"].values, strict=True):
        ax.annotate(f"{w:g}", (si, ei), textcoords="offset points", xytext=(5, -10),
                    fontsize=7)
    bounced = row["regime"].values == BOUNCING
    if bounced.any():
        ax.plot(s[bounced], e[bounced], "o", mfc="none", mec="k", ms=11, label="bit bounced")
    plt.colorbar(sc, ax=ax, label="ω₀")
    ax.set_xlabel("S = ⟨W⟩/⟨δ⟩")
    ax.set_ylabel("E = ⟨T⟩/⟨δ⟩")
    ax.legend(fontsize=7, loc="upper left")


FIG13_OMEGAS = [1.0, 3.0, 4.0, 7.0, 8.2, 8.4]
FIG13_PSIS = [20.0, 30.0, 40.0, 60.0, 100.0, 200.0, 500.0, 1000.0]
FIG13_RATIO = "w0_ratio=1.05:3:14"


def fig13(out: Path, maps: Maps) -> Path:
    base = load_preset("fig13").params
    by_omega = maps.get("fig13_omega0", spec("fig13", values_axis("omega0", FIG13_OMEGAS),
                                             FIG13_RATIO))
    by_psi = maps.get("fig13_psi", spec("fig13", values_axis("psi", FIG13_PSIS), FIG13_RATIO,
                                        dtau=5e-5))
    fig, axes = plt.subplots(1, 2, figsize=(12, 5.2))
    for ax, ds, name, label in ((axes[0], by_omega, "omega0", "ω₀"),
                                (axes[1], by_psi, "psi", "ψ")):
        ratio = ds["w0_ratio"].values
        ax.plot(ratio, base.lam * (ratio - 1), "k--", lw=0.8, label="δ₀ = W₀ − λ (trivial)")
        ax.plot(ratio, base.lam * ratio, "k:", lw=0.8, label="δ_max = W₀ (sharp bit)")
        colors = plt.cm.viridis(np.linspace(0, 0.9, ds.sizes[name]))
        for value, color in zip(ds[name].values, colors, strict=True):
            row = ds.sel({name: value})
            bounced = row["regime"].values == BOUNCING
            ok = np.cumsum(bounced) == 0            # the curve ends at the first bounce
            depth = row["mean_depth_of_cut"].values
            ax.plot(ratio[ok], depth[ok], "o-", ms=3, color=color, label=f"{label} = {value:g}")
            if not ok.all():
                first = int(np.argmin(ok))
                ax.plot(ratio[first], base.lam * (ratio[first] - 1), "x", ms=8, mew=2,
                        color=color)
        ax.set_ylim(0, 1.1 * base.lam * ratio.max())
        ax.set_xlabel("W₀′ = W₀/λ")
        ax.set_ylabel("⟨δ⟩")
        ax.legend(fontsize=7, ncol=2)
    caption(fig, f"RGD07 Fig. 13: mean depth of cut ⟨δ⟩ against W₀′ for several (a) ω₀ and "
            f"(b) ψ (n = 6, ψ = 63.1, ω₀ = 4, β = 0.276, λ = {base.lam:g} held, W₀ = λW₀′; "
            "each curve ends before the first W₀′ at which the bit bounced, marked × on the δ₀ "
            "line; Δτ = 1e-4 in (a), 5e-5 in (b)). "
            "Paper: ⟨δ⟩ rises from δ₀ with W₀′ up to a bound ⟨δ⟩_k where bouncing starts, "
            "always below δ_max; larger ω₀ stabilises (points towards δ₀), larger ψ widens "
            "bouncing.", 4)
    return save(fig, out / "fig13.png")


FIG14_PSIS = [30.0, 63.1, 100.0, 200.0]


def fig14(out: Path, maps: Maps) -> Path:
    ds = maps.get("fig14", spec("fig14", values_axis("psi", FIG14_PSIS),
                                "w0_ratio=1.1:3:12", "omega0=1:10:12"))
    fig, axes = plt.subplots(1, 2, figsize=(12, 5.2))
    colors = plt.cm.viridis(np.linspace(0, 0.85, len(FIG14_PSIS)))
    styles = ("-", "--", "-.", ":")
    handles = []
    for psi, color, style in zip(ds["psi"].values, colors, styles, strict=True):
        bounce = (ds["regime"].sel(psi=psi) == BOUNCING).astype(float)
        axes[0].contourf(ds["omega0"].values, ds["w0_ratio"].values, bounce.values,
                         levels=[0.5, 1.5], colors=[color], alpha=0.12)
        axes[0].contour(ds["omega0"].values, ds["w0_ratio"].values, bounce.values,
                        levels=[0.5], colors=[color], linewidths=2, linestyles=style)
        handles.append(plt.Line2D([], [], color=color, lw=2, ls=style, label=f"ψ = {psi:g}"))
    axes[0].legend(handles=handles, fontsize=8, loc="lower right",
                   title="bouncing above / left of the line", title_fontsize=8)
    axes[0].set_xlabel("ω₀")
    axes[0].set_ylabel("W₀′ = W₀/λ")
    axes[0].set_title("(a) bit-bouncing region", fontsize=10)
    eta = ds["eta"].sel(psi=100.0)
    eta = eta.where(ds["regime"].sel(psi=100.0) != BOUNCING)
    plot.draw_variable(axes[1], eta, label="η (eq. 43)")
    axes[1].set_title("(b) drilling efficiency η, ψ = 100 (blank: bouncing)", fontsize=10)
    caption(fig, "RGD07 Fig. 14: (a) the bit-bouncing region in (ω₀, W₀′) for ψ = "
            f"{', '.join(f'{p:g}' for p in FIG14_PSIS)}; (b) η for ψ = 100 (n = 6, λ = 4.2, "
            f"β = 0.43; 12 × 12 points per ψ, τ ≤ {TAU_END:g}, Δτ = 5e-5; bouncing = the bit "
            "left the rock at any time). Paper: the bouncing region (large W₀′, small ω₀) "
            "grows with ψ; η is largest next to the bouncing boundary and falls towards "
            "large ω₀ / small W₀′.", 4)
    return save(fig, out / "fig14.png")


FIELD = "field_8p5in_shale"
FIELD_END_S = 120.0           # per point: 120 s of the bench, statistics over [60, 120] s
FIELD_WINDOW_S = 60.0
FIELD_AXES = ("wob_n=20000:120000:11", "surface_rpm=30:180:11")
FIELD_CONTROLLERS = (("none", "no control (the drive's own speed loop)"),
                     ("soft_torque", "soft_torque, on from t = 0"))


def field_map(out: Path, maps: Maps) -> Path:
    pr = load_preset(FIELD)
    t_star = pr.scales.time_s
    runs = [maps.get(f"field_{name}", spec(FIELD, *FIELD_AXES, tau_end=FIELD_END_S / t_star,
                                           average_from=FIELD_WINDOW_S / t_star,
                                           control=Control(name)))
            for name, _ in FIELD_CONTROLLERS]
    fig, axes = plt.subplots(2, 2, figsize=(12, 10), sharex=True, sharey=True)
    ssi_max = max(float(ds["ssi"].where(ds["regime"] != BOUNCING).max()) for ds in runs)
    for col, (ds, (_, title)) in enumerate(zip(runs, FIELD_CONTROLLERS, strict=True)):
        kn = {"wob_n": ds["wob_n"] / 1e3}
        plot.draw_regime(axes[0, col], ds["regime"].assign_coords(kn))
        ssi = ds["ssi"].where(ds["regime"] != BOUNCING).assign_coords(kn)
        plot.draw_variable(axes[1, col], ssi, cmap="magma", vmin=0.0, vmax=ssi_max,
                           label="SSI = (max − min)/(2 mean) of bit rpm")
        sticks = int((ds["regime"] == STICK_SLIP).sum())
        axes[1, col].text(0.02, 0.97, f"stick-slip points: {sticks} of {ds['regime'].size}\n"
                          f"largest SSI without bouncing: {float(ssi.max()):.3g}",
                          transform=axes[1, col].transAxes, va="top", fontsize=8,
                          bbox={"fc": "white", "ec": "none", "alpha": 0.85})
        axes[0, col].set_title(f"regime: {title}", fontsize=10)
        axes[1, col].set_title(f"stick-slip severity: {title} (blank: bouncing)", fontsize=10)
        for ax in axes[:, col]:
            ax.set_ylabel("applied weight [kN]")
    caption(fig, f"Field preset {pr.name} (8.5-in PDC bit in shale, 2500 m of 5-in pipe, "
            f"t* = {t_star:.3f} s, ψ = {pr.params.psi:.0f}, β = {pr.params.beta:.2f}, λ = "
            f"{pr.params.lam:.2f}) over surface speed and applied weight, closed loop in "
            f"process (the rig's top drive, 10 ms control period, {FIELD_END_S:g} s per point "
            f"from the trivial state + a small axial perturbation; figures over "
            f"[{FIELD_WINDOW_S:g}, {FIELD_END_S:g}] s). Left: no controller, right: "
            "soft_torque (torque feedback through a high-pass, ζ = 0.5). Expected: the torque "
            "feedback damps the torsional mode, so stick-slip disappears wherever the bit "
            "keeps contact; it does not act on the axial bouncing at high WOB.", 4)
    return save(fig, out / "field_map.png")


FIGURES: dict[str, Callable[[Path, Maps], Path]] = {
    "fig5": fig5, "fig7": fig7, "fig8": fig8, "fig9": fig9, "fig11": fig11, "fig12": fig12,
    "fig13": fig13, "fig14": fig14, "field_map": field_map,
}


@contextmanager
def _map_dir(cache: Path | None) -> Iterator[Path]:
    if cache is not None:
        cache.mkdir(parents=True, exist_ok=True)
        yield cache
        return
    with tempfile.TemporaryDirectory(prefix="drill_sim_figures_") as tmp:
        yield Path(tmp)


def make_all(out: Path, cache: Path | None = None, only: list[str] | None = None,
             scheduler: str | None = None, workers: int | None = None,
             progress: bool = False,
             log: Callable[[str], None] | None = None) -> list[Path]:
    """Render the figures named in ``only`` (default all) into ``out``."""
    names = only or list(FIGURES)
    unknown = [n for n in names if n not in FIGURES]
    if unknown:
        raise DrillSimError(f"--only {unknown}: unknown; figures: {', '.join(FIGURES)}")
    out.mkdir(parents=True, exist_ok=True)
    written = []
    with _map_dir(cache) as directory, engine.connect(scheduler, workers) as client:
        maps = Maps(client, directory, progress)
        for name in names:
            t0 = time.perf_counter()
            written.append(FIGURES[name](out, maps))
            if log:
                log(f"{name}: {time.perf_counter() - t0:.1f} s")
    return written

