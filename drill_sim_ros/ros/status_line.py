"""One live status line on a terminal: sim time, bit rpm, WOB, TOB, ROP, mode, real-time factor.

The only place in the package that writes to a stream directly; it does nothing unless the
stream is a TTY, so logs and pipes stay clean.
"""

from __future__ import annotations

import math
import sys
from typing import TextIO

from drill_sim_ros import topics

F = topics.TELEMETRY_INDEX
M_S_TO_M_H = 3600.0


def format_status(row: list[float], achieved_rtf: float, state: str = "") -> str:
    """The status text of one telemetry row (``topics.TELEMETRY_FIELDS`` order)."""
    mode = int(row[F["mode"]])
    mode_name = topics.MODE_NAMES[mode] if 0 <= mode < len(topics.MODE_NAMES) else "?"
    rtf = "  -  " if math.isnan(achieved_rtf) else f"{achieved_rtf:5.2f}"
    text = (f"t {row[F['sim_time_s']]:9.2f} s | bit {row[F['bit_rpm']]:6.1f} rpm | "
            f"WOB {row[F['wob_n']] / 1e3:7.2f} kN | TOB {row[F['tob_nm']] / 1e3:6.2f} kN m | "
            f"ROP {row[F['rop_m_s']] * M_S_TO_M_H:6.2f} m/h | {mode_name:<12} | x{rtf}")
    return f"{text} | {state}" if state else text


class StatusLine:
    """Rewrites one line in place on ``stream`` (default stderr) when it is a terminal."""

    def __init__(self, stream: TextIO | None = None) -> None:
        self._stream = stream if stream is not None else sys.stderr
        self.active = bool(getattr(self._stream, "isatty", lambda: False)())
        self._shown = False

    def show(self, text: str) -> None:
        if self.active:
            self._stream.write(f"\r{text}\x1b[K")
            self._stream.flush()
            self._shown = True

    def close(self) -> None:
        """End the line so later log output starts on a fresh one."""
        if self._shown:
            self._stream.write("\n")
            self._stream.flush()
            self._shown = False
