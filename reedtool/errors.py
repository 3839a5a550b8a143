"""The one exception type for mistakes a user can cause.

The CLI turns a ReedtoolError into a single line on stderr and exit code 2; anything
else that escapes is a bug in reedtool and is reported as such.
"""

from __future__ import annotations

from pathlib import Path


class ReedtoolError(Exception):
    """A user-facing error: what went wrong, where (file and line), and what to do."""

    def __init__(self, message: str, file: str | Path | None = None,
                 line: int | None = None, hint: str | None = None):
        super().__init__(message)
        self.message = message
        self.file = str(file) if file is not None else None
        self.line = line
        self.hint = hint

    def one_line(self) -> str:
        where = ""
        if self.file:
            where = f"{self.file}:{self.line}: " if self.line else f"{self.file}: "
        text = f"{where}{self.message}"
        if self.hint:
            text += f" ({self.hint})"
        # Messages are one line by contract; embedded newlines from libraries are folded.
        return " ".join(text.split())
