"""One live line on a terminal (status and progress lines of every command).

The only writer to a stream in library code; silent unless the stream is a TTY (or
``force``), so logs and pipes stay clean. A long command may ask for a plain line every
``every_s`` seconds where there is no TTY (``drill_sim fit``: minutes of work), so a log of
it still shows progress.
"""

from __future__ import annotations

import math
import sys
import time
from typing import TextIO

from drill_sim_ros.model.telemetry import MODE_NAMES, TELEMETRY_INDEX


class StatusLine:
    """Rewrites one line of ``stream`` (default stderr) in place."""

    def __init__(self, stream: TextIO | None = None, force: bool = False,
                 every_s: float | None = None) -> None:
        self._stream = stream if stream is not None else sys.stderr
        self.active = force or bool(getattr(self._stream, "isatty", lambda: False)())
        self._shown = False
        self._every_s = None if self.active else every_s
        self._last_plain_s = time.monotonic()

    def show(self, text: str) -> None:
        if self.active:
            self._shown = self._write(f"\r{text}\x1b[K")
        elif self._every_s is not None and \
                time.monotonic() - self._last_plain_s >= self._every_s:
            self._last_plain_s = time.monotonic()
            self._write(f"{text}\n")

    def close(self) -> None:
        """End the line so later output starts on a fresh one (idempotent)."""
        if self._shown:
            self._write("\n")
            self._shown = False

    def _write(self, text: str) -> bool:
        """Write and flush; a terminal that has gone away (EIO after a hang-up, a closed
        stream) turns the line off instead of failing the caller, which may be finishing a
        recording."""
        try:
            self._stream.write(text)
            self._stream.flush()
        except (OSError, ValueError):
            self.active = False
            return False
        return True


M_S_TO_M_H = 3600.0


def format_status(row: list[float], achieved_rtf: float, state: str = "") -> str:
    """sim_node's live line of one telemetry row (``TELEMETRY_FIELDS`` order): sim time,
    bit rpm, WOB, TOB, ROP, mode, achieved real-time factor, state."""
    f = TELEMETRY_INDEX
    mode = int(row[f["mode"]])
    mode_name = MODE_NAMES[mode] if 0 <= mode < len(MODE_NAMES) else "?"
    rtf = "  -  " if math.isnan(achieved_rtf) else f"{achieved_rtf:5.2f}"
    text = (f"t {row[f['sim_time_s']]:9.2f} s | bit {row[f['bit_rpm']]:6.1f} rpm | "
            f"WOB {row[f['wob_n']] / 1e3:7.2f} kN | TOB {row[f['tob_nm']] / 1e3:6.2f} kN m | "
            f"ROP {row[f['rop_m_s']] * M_S_TO_M_H:6.2f} m/h | {mode_name:<12} | x{rtf}")
    return f"{text} | {state}" if state else text
