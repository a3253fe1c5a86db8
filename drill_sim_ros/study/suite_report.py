"""The league table of a suite: printed, and as DIR/suite.json, DIR/suite.nc (xarray) and
DIR/report.md with one picture per scenario (DIR/<scenario>.png, one column per controller).
"""

from __future__ import annotations

import json
import math
from collections.abc import Sequence
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import numpy as np
import xarray as xr

from drill_sim_ros import __version__
from drill_sim_ros.control.registry import display_name
from drill_sim_ros.control.scenario import ENSEMBLE_KEY, ENSEMBLE_STEP, ensemble_caption
from drill_sim_ros.control.scorecard import status_text, summarize
from drill_sim_ros.study.suite import Entry, EntryResult

# (card key, column head, format) of the table
COLUMNS = (("ssi_mean", "SSI after", ".3f"), ("stick_fraction", "stick frac", ".3f"),
           ("period_s", "period s", ".2f"), ("ring_rms_rpm", "ring rpm", ".1f"),
           ("off_bottom_fraction", "off rock", ".1%"),
           ("rop_m_h", "ROP m/h", ".2f"), ("mse_mpa", "MSE MPa", ".0f"),
           ("time_to_suppress_s", "suppress s", ".1f"),
           ("saturation_fraction", "at limit", ".1%"),
           ("motor_torque_std_nm", "motor std N m", ".0f"),
           ("motor_torque_rate_mean_knm_s", "motor rate kN m/s", ".1f"),
           ("motor_energy_in_mj", "motor in MJ", ".2f"))
NUMERIC = ("ssi_before_mean", "ssi_mean", "ssi_max", "ssi_last", "stick_fraction",
           "stick_longest_s", "utr", "bit_rpm_max", "time_to_suppress_s", "rop_m_h", "mse_mpa",
           "quill_torque_peak_nm", "quill_torque_rms_nm", "motor_torque_std_nm",
           "motor_torque_rate_mean_knm_s", "motor_energy_mj", "motor_energy_in_mj",
           "saturation_count", "saturation_fraction", "period_s", "ring_rms_rpm", "ring_hz",
           "cutoff_hz", "off_bottom_fraction", "wob_rms_n", "stall_time_s", "wall_s")
UNITS = {"rop_m_h": "m/h", "mse_mpa": "MPa", "time_to_suppress_s": "s", "stall_time_s": "s",
         "stick_longest_s": "s", "bit_rpm_max": "rev/min",
         "quill_torque_peak_nm": "N m", "quill_torque_rms_nm": "N m",
         "motor_torque_std_nm": "N m", "motor_torque_rate_mean_knm_s": "kN m/s",
         "motor_energy_mj": "MJ", "motor_energy_in_mj": "MJ",
         "period_s": "s", "ring_rms_rpm": "rev/min", "ring_hz": "Hz", "cutoff_hz": "Hz",
         "wob_rms_n": "N",
         "wall_s": "s"}


def _cell(value: Any, fmt: str) -> str:
    if value is None or (isinstance(value, float) and not math.isfinite(value)):
        return "-"
    return format(value, fmt)


def table_rows(entries: Sequence[Entry], results: dict[str, EntryResult]) -> list[list[str]]:
    """One row per entry: scenario, controller, the COLUMNS, status."""
    out = []
    for entry in entries:
        result = results.get(entry.key)
        card = result.card if result else {"status": "not run"}
        out.append([entry.scenario_name, _label(entry),
                    *(_cell(card.get(key), fmt) for key, _, fmt in COLUMNS),
                    status_text(card)])
    return out


def _label(entry: Entry) -> str:
    name = display_name(entry.controller)
    return name if entry.controller == "none" else f"{name} ({entry.scenario.mode})"


HEADS = ("scenario", "controller", *(head for _, head, _ in COLUMNS), "status")


def format_table(entries: Sequence[Entry], results: dict[str, EntryResult]) -> str:
    """The table as aligned text, a blank line between scenarios."""
    return _aligned(HEADS, table_rows(entries, results), last_left=True)


def _aligned(heads: Sequence[str], rows: list[list[str]], last_left: bool) -> str:
    """``rows`` under ``heads`` as aligned text: the first two columns (and the last, if
    ``last_left``) to the left, the rest to the right; a blank line between scenarios."""
    widths = [max(len(h), *(len(r[i]) for r in rows)) for i, h in enumerate(heads)]
    def line(cells: Sequence[str]) -> str:
        return "  ".join(c.ljust(w) if i < 2 or (last_left and i == len(cells) - 1)
                         else c.rjust(w)
                         for i, (c, w) in enumerate(zip(cells, widths, strict=True))).rstrip()
    out, last = [line(heads)], None
    for row in rows:
        if last is not None and row[0] != last:
            out.append("")
        out.append(line(row))
        last = row[0]
    return "\n".join(out)


def markdown_table(entries: Sequence[Entry], results: dict[str, EntryResult]) -> str:
    return _markdown(HEADS, table_rows(entries, results))


def _markdown(heads: Sequence[str], rows: list[list[str]]) -> str:
    """``rows`` as a markdown table without the scenario column."""
    lines = ["| " + " | ".join(heads[1:]) + " |", "|" + "---|" * (len(heads) - 1)]
    lines += ["| " + " | ".join(row[1:]) + " |" for row in rows]
    return "\n".join(lines)


# ---- an ensemble (suite --ensemble N): each entry's members summarised -----------------------
ENSEMBLE_HEADS = ("scenario", "controller", "runs", "stick-slip/ok/stalled/other",
                  "SSI after: median (range)", "stick frac: median (range)",
                  "at limit: median (max)")


def members_of(entries: Sequence[Entry]) -> int:
    """How many members the ensemble of ``entries`` has (1: a plain suite)."""
    return 1 + max((e.member for e in entries), default=0)


def plain(entries: Sequence[Entry]) -> list[Entry]:
    """The entries of member 0: the scenarios as they are (the plain table's)."""
    return [e for e in entries if e.member == 0]


def ensemble_rows(entries: Sequence[Entry], results: dict[str, EntryResult]
                  ) -> list[list[str]]:
    """One row per scenario and controller over all of its members that ran
    (``scorecard.summarize``)."""
    cards: dict[tuple[str, str], list[dict[str, Any]]] = {}
    for e in entries:
        group = cards.setdefault((e.scenario_name, _label(e)), [])
        if e.key in results:
            group.append(results[e.key].card)
    rows = []
    for (name, label), group in cards.items():
        cell = summarize(group)
        rows.append([name, label, cell["runs"], cell["counts"], cell["ssi_mean"],
                     cell["stick_fraction"], cell["saturation_fraction"]])
    return rows


def format_ensemble_table(entries: Sequence[Entry], results: dict[str, EntryResult]) -> str:
    return _aligned(ENSEMBLE_HEADS, ensemble_rows(entries, results), last_left=False)


def suite_json(entries: Sequence[Entry], results: dict[str, EntryResult],
               wall_s: float) -> dict[str, Any]:
    return {"package_version": __version__, "wall_s": wall_s,
            "created_utc": datetime.now(UTC).isoformat(timespec="seconds"),
            "ensemble": {"members": members_of(entries), "step": ENSEMBLE_STEP,
                         "seeded": ENSEMBLE_KEY},
            "entries": [{"scenario": e.scenario_name, "controller": e.controller,
                         "mode": e.scenario.mode, "member": e.member,
                         "status": status_text(results[e.key].card) if e.key in results
                         else "not run",
                         "score": _clean(results[e.key].card) if e.key in results else None,
                         "wall_s": results[e.key].wall_s if e.key in results else None}
                        for e in entries]}


def _clean(value: Any) -> Any:
    if isinstance(value, dict):
        return {k: _clean(v) for k, v in value.items()}
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value


def suite_dataset(entries: Sequence[Entry], results: dict[str, EntryResult]) -> xr.Dataset:
    """The table over (scenario, controller), of member 0: each figure, and the status as
    text; with an ensemble, the same over (scenario, controller, member) as ``ensemble_*``
    variables."""
    scenarios = list(dict.fromkeys(e.scenario_name for e in entries))
    controllers = list(dict.fromkeys(_label(e) for e in entries))
    members = members_of(entries)
    shape = (len(scenarios), len(controllers), members)
    data = {name: np.full(shape, np.nan) for name in NUMERIC}
    status = np.full(shape, "not run", dtype=object)
    for e in entries:
        i, j = scenarios.index(e.scenario_name), controllers.index(_label(e))
        result = results.get(e.key)
        if result is None:
            continue
        status[i, j, e.member] = status_text(result.card)
        for name in NUMERIC:
            value = result.wall_s if name == "wall_s" else result.card.get(name)
            if isinstance(value, (int, float)) and value is not None:
                data[name][i, j, e.member] = float(value)
    dims = ("scenario", "controller")
    variables = {name: (dims, values[..., 0], {"units": UNITS.get(name, "1")})
                 for name, values in data.items()}
    variables["status"] = (dims, status[..., 0].astype(str))
    coords: dict[str, Any] = {"scenario": scenarios, "controller": controllers}
    if members > 1:
        edims = (*dims, "member")
        variables.update({f"ensemble_{name}": (edims, values, {"units": UNITS.get(name, "1")})
                          for name, values in data.items()})
        variables["ensemble_status"] = (edims, status.astype(str))
        coords["member"] = np.arange(members)
    return xr.Dataset(variables, coords=coords,
                      attrs={"title": "drill_sim suite: controllers x scenarios",
                             "package_version": __version__,
                             "ensemble_members": members, "ensemble_step": ENSEMBLE_STEP,
                             "ensemble_seeded": ENSEMBLE_KEY})


def write_outputs(out: Path, entries: Sequence[Entry], results: dict[str, EntryResult],
                  wall_s: float, pictures: bool = True) -> list[Path]:
    """suite.json, suite.nc, the pictures and report.md in ``out``; the files written."""
    out.mkdir(parents=True, exist_ok=True)
    (out / "suite.json").write_text(json.dumps(suite_json(entries, results, wall_s), indent=1))
    suite_dataset(entries, results).to_netcdf(out / "suite.nc", engine="h5netcdf")
    written = [out / "suite.json", out / "suite.nc"]
    images = draw_pictures(out, plain(entries), results) if pictures else {}
    (out / "report.md").write_text(report_markdown(entries, results, images, wall_s))
    return [*written, *images.values(), out / "report.md"]


def _by_scenario(entries: Sequence[Entry]) -> dict[str, list[Entry]]:
    groups: dict[str, list[Entry]] = {}
    for e in entries:
        groups.setdefault(e.scenario_name, []).append(e)
    return groups


def draw_pictures(out: Path, entries: Sequence[Entry],
                  results: dict[str, EntryResult]) -> dict[str, Path]:
    """One PNG per scenario that ran: one column per controller."""
    from drill_sim_ros.control.plot import PlotContext, PlotRun, plot_runs, schedule_events
    from drill_sim_ros.control.rig import rig_physics
    images = {}
    for name, group in _by_scenario(entries).items():
        runs = [(e, results[e.key]) for e in group
                if e.key in results and len(results[e.key].trace)]
        if not runs:
            continue
        scenario = group[0].scenario
        preset = scenario.load_preset()
        rig, schedule = rig_physics(preset), scenario.setpoints(preset)
        ctx = PlotContext(f"{name}: {scenario.description}"[:150], schedule,
                          scenario.enable_at_s, rig, schedule_events(schedule))
        path = out / f"{name}.png"
        plot_runs(path, [PlotRun(_label(e), r.rows(), e.scenario.mode == "speed",
                                 status_text(r.card)) for e, r in runs], ctx)
        images[name] = path
    return images


def report_markdown(entries: Sequence[Entry], results: dict[str, EntryResult],
                    images: dict[str, Path], wall_s: float) -> str:
    lines = ["# drill_sim suite", "",
             f"{len(entries)} runs (controller x scenario), {wall_s:.0f} s of wall time for "
             "those computed by the last call. Columns (of the bit speed low-passed at the "
             "rig's cut-off, twice its third torsional mode, unless said): SSI after the "
             "switch-on (mean of whole 20 s windows, clipped at 10, which a window stuck "
             "throughout reads), stick fraction after it, the stick-slip period, the RMS of "
             "the bit speed above the cut-off (the collars' ringing, 7-16 Hz on the field "
             "string; not the 50-400 Hz HFTO of field logs), mean ROP, MSE at the bit, time "
             "from the switch-on to the last stick (- while it still sticks in the last "
             "20 s or its quiet end is no longer than its longest spell between sticks), "
             "share of samples with the motor torque at its limit, the motor torque's RMS "
             "about its mean, its mean absolute rate, the motor's positive work, status "
             "(ok only when stuck under 10 % of the time after the switch-on, suppressed "
             "and with an SSI under 1 in the last 20 s; docs/closed-loop.md).", ""]
    members = members_of(entries)
    if members > 1:
        lines += ["Each scenario's first table is member 0; below it, "
                  + ensemble_caption(members).rstrip(":") + ".", ""]
    for name, group in _by_scenario(entries).items():
        scenario = group[0].scenario
        lines += [f"## {name}", "", scenario.description or "", "",
                  markdown_table(plain(group), results), ""]
        if members > 1:
            lines += [_markdown(ENSEMBLE_HEADS, ensemble_rows(group, results)), ""]
        if name in images:
            lines += [f"![{name}]({images[name].name})", ""]
    return "\n".join(lines)
