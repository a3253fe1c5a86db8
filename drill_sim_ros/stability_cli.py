"""``drill_sim stability``: will the first torsional mode grow at an operating point?

A command of its own rather than ``drill_sim reflection --bit``: it answers per controller
from both ends of the pipe (the bit's reflection, analytic about the operating point, and
the top's, measured with the controller in the loop; control/stability.py), not one |r|
curve. Prints a table, then, as the last line of stdout, one JSON object (``--json``: only
that line).
"""

from __future__ import annotations

import json
from typing import Any

from drill_sim_ros.control import stability as st
from drill_sim_ros.model.presets import DEFAULT_PRESET


def add_parser(sub: Any) -> None:
    cmd = sub.add_parser("stability", help="predict from the reflections at the bit and at "
                         "the top whether the first torsional mode grows, per controller")
    cmd.add_argument("--params", default=DEFAULT_PRESET,
                     help="physical preset with a distributed string (name or YAML path)")
    cmd.add_argument("--controller", action="append", default=[],
                     help="a controller (a built-in or path/file.py:Class); repeat for "
                     f"several (default: {', '.join(st.CONTROLLERS)})")
    cmd.add_argument("--rpm", type=float, default=None,
                     help="surface rpm of the operating point (default: the preset's)")
    cmd.add_argument("--wob-n", type=float, default=None,
                     help="applied WOB of the operating point, N (default: the preset's)")
    cmd.add_argument("--json", action="store_true", help="print only the JSON line")


def cmd_stability(args: Any) -> int:
    preset = st.checked_preset(args.params)
    rpm, wob_n = st.operating_point(preset)
    rpm = rpm if args.rpm is None else args.rpm
    wob_n = wob_n if args.wob_n is None else args.wob_n
    st.check_point(rpm, wob_n)
    tops = st.measure_tops(args.params, args.controller or list(st.CONTROLLERS))
    rows = st.predict(preset, tops, rpm, wob_n)
    if not args.json:
        first = rows[0]
        if first.runs_away:
            print(f"{preset.name} at {rpm:g} rpm, {wob_n / 1e3:g} kN: bit slope b = "
                  f"{first.slope_nm_s:.1f} N m s: the bit and BHA are unstable by "
                  "themselves on an endless pipe: growth under every controller")
        else:
            print(f"{preset.name} at {rpm:g} rpm, {wob_n / 1e3:g} kN: bit slope b = "
                  f"{first.slope_nm_s:.1f} N m s; r_bit analytic, r_top measured")
            print("controller      mode Hz  |r_bit|  |r_top|  pipe round trip  loop gain  "
                  "first mode")
            for r in rows:
                print(f"{r.controller:14s}  {r.mode_hz:7.4f}  {r.r_bit:7.3f}  {r.r_top:7.3f}"
                      f"  {r.pipe:15.3f}  {r.loop_gain:9.3f}  "
                      f"{'grows' if r.grows else 'decays'}")
    print(json.dumps({"params": preset.name, "rpm": rpm, "wob_n": wob_n,
                      "predictions": [r.as_dict() for r in rows]}))
    return 0
