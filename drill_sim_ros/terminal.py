"""One live line on a terminal (status and progress lines of every command).

The only writer to a stream in library code; silent unless the stream is a TTY (or
``force``), so logs and pipes stay clean.
"""

from __future__ import annotations

import sys
from typing import TextIO


class StatusLine:
    """Rewrites one line of ``stream`` (default stderr) in place."""

    def __init__(self, stream: TextIO | None = None, force: bool = False) -> None:
        self._stream = stream if stream is not None else sys.stderr
        self.active = force or bool(getattr(self._stream, "isatty", lambda: False)())
        self._shown = False

    def show(self, text: str) -> None:
        if self.active:
            self._shown = self._write(f"\r{text}\x1b[K")

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
