"""The one exception type for mistakes a user can cause.

The CLI turns a ReedtoolError into a single line on stderr and exit code 2; anything
else that escapes is a bug in reedtool and is reported as such.
"""

from __future__ import annotations

import errno
import re
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
            file = shorten(self.file, MAX_SHOWN_PATH)
            where = f"{file}:{self.line}: " if self.line else f"{file}: "
        text = f"{where}{shorten_names(self.message)}"
        if self.hint:
            text += f" ({shorten_names(self.hint)})"
        # Messages are one line by contract; embedded newlines from libraries are folded.
        return " ".join(text.split())


# A name the user wrote (a link, a path, a value) is shown at most this long in a message:
# a 1 MB link name echoed whole makes the message useless (issue 14).
MAX_SHOWN_NAME = 80
MAX_SHOWN_PATH = 240
# A quoted name: an apostrophe inside a word ("geometry's") neither opens nor closes one,
# or the text between two such words would be cut as if it were a name.
_QUOTED = re.compile(rf"(?<!\w)'([^']{{{MAX_SHOWN_NAME + 1},}})'(?!\w)")


def shorten(text: str, limit: int = MAX_SHOWN_NAME) -> str:
    """`text` cut to `limit` characters with an ellipsis in the middle (both ends stay)."""
    text = str(text)
    if len(text) <= limit:
        return text
    keep = limit - 1
    return f"{text[:keep - keep // 3]}\u2026{text[len(text) - keep // 3:]}"


def shorten_names(message: str) -> str:
    """Every quoted name in a message shortened; an overlong message cut as a whole."""
    def cut(match: re.Match) -> str:
        name = match.group(1)   # a path may be longer than a name and still be useful
        return f"'{shorten(name, MAX_SHOWN_PATH if '/' in name else MAX_SHOWN_NAME)}'"

    message = _QUOTED.sub(cut, message)
    return shorten(message, 4 * MAX_SHOWN_PATH)


_ERRNO_HINTS = {
    errno.ENOSPC: "the disk is full: free some space and run again",
    errno.EDQUOT: "the disk quota is exceeded: free some space and run again",
    errno.ENAMETOOLONG: "the file name is too long for the filesystem: choose a shorter name",
    errno.EACCES: "check the permissions, or choose another path",
    errno.EPERM: "check the permissions, or choose another path",
    errno.EROFS: "the filesystem is read-only: choose another path",
    errno.EPIPE: "the reader of the output went away",
    errno.EISDIR: "pass a file's path, not a directory",
    errno.ENOTDIR: "a part of the path is not a directory",
    errno.ELOOP: "too many symbolic links: check the path",
    errno.EIO: "the device reported an input/output error",
}


def os_error(exc: OSError, file: str | Path | None = None, *,
             action: str | None = None) -> ReedtoolError:
    """An OSError from the user's environment as one ReedtoolError naming the file."""
    file = file if file is not None else exc.filename
    reason = exc.strerror or type(exc).__name__
    message = f"cannot {action}: {reason}" if action else reason
    return ReedtoolError(message, file=file, hint=_ERRNO_HINTS.get(exc.errno))


# ------------------------------------------------------------------ plausible ranges
# One table of the physical ranges reedtool accepts from a user (command line and
# new-package specs), SI units. Outside them the value is a typo or a unit slip
# (`--arm-length 1e9`, `--rate 1e-3`), refused with exit 2 before any work, instead of
# being flown and "failing" or generating a package that cannot hover.
PLAUSIBLE: dict[str, tuple[float, float, str]] = {
    # quantity: (lowest, highest, unit)
    "mass": (1e-6, 1e4, "kg"),                 # a 1 mg part .. a 10 t vehicle
    "length": (1e-5, 100.0, "m"),              # 10 um .. 100 m
    "density": (0.1, 1e5, "kg/m^3"),           # aerogel .. beyond osmium (22,590)
    "time": (1e-5, 100.0, "s"),                # motor time constants
    "angular_velocity": (1.0, 1e5, "rad/s"),   # rotor speeds
    "rate": (50.0, 1e5, "Hz"),                 # fixed-step integration; below 50 Hz a
                                               # multirotor's attitude loop is not resolved
    "duration": (0.1, 1e5, "s"),
    "offset": (0.0, 1000.0, "m"),              # |start - setpoint| per axis
    "angle": (0.0, 2 * 3.141592653589793, "rad"),  # |roll|, |pitch|, |yaw|
}


def check_plausible(quantity: str, value: float, what: str, *,
                    file: str | Path | None = None, magnitude: bool = False) -> float:
    """`value` if it lies in PLAUSIBLE[quantity] (its absolute value if `magnitude`)."""
    low, high, unit = PLAUSIBLE[quantity]
    number = abs(value) if magnitude else value
    if not (low <= number <= high):    # NaN fails too
        span = f"|{what}|" if magnitude else what
        where = "must be positive and within" if value <= 0 < low else "is outside"
        raise ReedtoolError(f"{span} = {value:g} {unit} {where} the plausible range "
                            f"{low:g} .. {high:g} {unit}", file=file,
                            hint="check the value and its unit")
    return value
