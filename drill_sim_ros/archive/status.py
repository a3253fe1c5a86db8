"""A one-line live status on a terminal (the recorder's and the replayer's progress line)."""

from __future__ import annotations

import sys
from typing import TextIO


class StatusLine:
    """Rewrites one line of ``stream`` in place; silent when the stream is not a terminal."""

    def __init__(self, stream: TextIO | None = None, force: bool = False) -> None:
        self._stream = stream or sys.stderr
        self.enabled = force or self._stream.isatty()
        self._width = 0

    def show(self, text: str) -> None:
        if not self.enabled:
            return
        padding = " " * max(0, self._width - len(text))
        self._width = len(text)
        self._stream.write(f"\r{text}{padding}")
        self._stream.flush()

    def end(self) -> None:
        if self.enabled and self._width:
            self._stream.write("\n")
            self._stream.flush()
            self._width = 0
