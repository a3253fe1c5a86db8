"""The sticks where the map's bit bounces (docs/string.md, the stalls): whether any lasts.

Until 2026-12-07 the bit stalled for good at these points (stiff 5, soft_torque 9 of these
12 runs each): the stick held a bit a bounce had landed deep against the string's pull too.
Since the stick lets the string lift the bit (model.md, the kernel's stick), this script
shows that none stalls, how deep the bit still lands, and that no stick lasts.

Runs the map's point (the default field preset, 180 s, switch-on at 60 s) at 140 rpm with
100 and 140 kN, members 0-5 of its ensemble (``scenario.seeded``), under stiff and
soft_torque, and reads every stick of the bit after the switch-on from the telemetry:
its depth of cut (mm per revolution, held while stuck: the deepest if it slipped and stuck
again between two samples), the drive's speed over the second
before, how long it lasted, whether it ended within the run, and the highest quill and bit
torque while it lasted. Printed per drive: the runs the scorecard calls stalled, the
sticks deeper than what the motor's limit holds quasi-statically (:func:`freed_depth_mm`),
and every stick that lasted longer than ``LONG_S`` (those the wind-up alone can end).

Usage: .venv/bin/python docs/stall_trace.py      (24 runs: about 10 s on 2 cores)
"""

from __future__ import annotations

import sys
from concurrent.futures import ProcessPoolExecutor

import numpy as np
from stability_map import PRESET, T_END_S, WORKERS, point_scenario, static_torque_nm

from drill_sim_ros.control import stability as st
from drill_sim_ros.control.bench import run_in_process
from drill_sim_ros.model.bit_rock import MODE_STUCK
from drill_sim_ros.model.telemetry import TELEMETRY_INDEX as F

RPM = 140.0
WOB_N = (100e3, 140e3)
MEMBERS = 6
DRIVES = ("stiff", "soft_torque")
ENABLE_AT_S = 60.0            # the map's switch-on (stability_map.point_scenario)
LONG_S = 5.0                  # a stick this long was not ended by the bounce's own torque


def freed_depth_mm() -> float:
    """The deepest cut (mm per revolution) whose stick the motor's torque limit (the
    preset's top_drive.max_torque_nm) ends (RGD07 eq. 30 at rest, :func:`static_torque_nm`
    is linear in the depth)."""
    limit_nm = st.checked_preset(PRESET).drive.max_torque_nm
    slope = static_torque_nm(1.0) - static_torque_nm(0.0)
    return 1e3 * (limit_nm - static_torque_nm(0.0)) / slope


def sticks(rows: np.ndarray) -> list[dict[str, float | bool]]:
    """Every stick of the bit that starts after the switch-on (as the 100 Hz telemetry
    samples it)."""
    t, stuck = rows[:, F["sim_time_s"]], rows[:, F["mode"]] == MODE_STUCK
    starts = np.nonzero(stuck[1:] & ~stuck[:-1])[0] + 1
    ends = np.nonzero(~stuck[1:] & stuck[:-1])[0] + 1
    out = []
    for i in starts[t[starts] >= ENABLE_AT_S]:
        later = ends[ends > i]
        end = int(later[0]) if later.size else len(t)
        before = slice(max(0, i - 100), i)                   # the second before (100 Hz)
        # the deepest cut held: a slip shorter than a sample (10 ms) and a stick again
        # deeper would read as one stick
        out.append({"depth_mm": 1e3 * float(np.max(rows[i:end, F["depth_of_cut_m"]])),
                    "drive_rpm": float(np.mean(rows[before, F["surface_rpm"]])),
                    "lasted_s": float(t[end - 1] - t[i]), "ended": bool(later.size),
                    "quill_knm": 1e-3 * float(np.max(rows[i:end, F["surface_torque_nm"]])),
                    "bit_knm": 1e-3 * float(np.max(rows[i:end, F["tob_nm"]]))})
    return out


def run(job: tuple[str, float, int]) -> tuple[str, list[dict[str, float | bool]]]:
    """The scorecard's status and the sticks of one run."""
    drive, wob_n, member = job
    result = run_in_process(point_scenario(drive, RPM, wob_n, member))
    return str(result.score(T_END_S / 2)["status"]), sticks(result.rows)


def report(drive: str, runs: list[tuple[str, list[dict[str, float | bool]]]]) -> None:
    freed_mm = freed_depth_mm()
    deep = [s for _, found in runs for s in found if s["depth_mm"] > freed_mm]
    stalled = sum(status == "stalled" for status, _ in runs)
    speeds = [s["drive_rpm"] for s in deep]
    print(f"\n{drive}: stalled in {stalled} of {len(runs)} runs; {len(deep)} sticks deeper "
          f"than {freed_mm:.1f} mm, the drive at {min(speeds):.0f}-{max(speeds):.0f} "
          "rpm over the second before")
    print(f"sticks that lasted more than {LONG_S:g} s:")
    print("| depth mm | lasted s | ended | quill peak kN m | bit peak kN m | holds kN m |")
    print("|---|---|---|---|---|---|")
    for s in sorted((s for _, found in runs for s in found if s["lasted_s"] > LONG_S),
                    key=lambda s: s["depth_mm"]):
        print(f"| {s['depth_mm']:.0f} | {s['lasted_s']:.1f} | {'yes' if s['ended'] else 'no'} "
              f"| {s['quill_knm']:.0f} | {s['bit_knm']:.0f} "
              f"| {static_torque_nm(s['depth_mm'] / 1e3) / 1e3:.0f} |")


def main() -> int:
    jobs = [(d, w, k) for d in DRIVES for w in WOB_N for k in range(MEMBERS)]
    with ProcessPoolExecutor(WORKERS) as pool:
        results = list(pool.map(run, jobs))
    per_drive = len(WOB_N) * MEMBERS
    for n, drive in enumerate(DRIVES):
        report(drive, results[n * per_drive:(n + 1) * per_drive])
    return 0


if __name__ == "__main__":
    sys.exit(main())
