"""The line a start tag begins on, which is the line users look for.

libxml2 (lxml's `sourceline`) reports the line of a start tag's closing '>', which is
later than where the tag begins when its attributes are split over several lines,
as RotorS and gz-sim examples do.
"""

from __future__ import annotations

import re
from functools import lru_cache
from typing import Sequence

# A start tag spans at most this many lines in any file we have seen; bounded so a
# malformed file cannot make the search quadratic.
_MAX_TAG_LINES = 200


@lru_cache(maxsize=256)
def _opening(tag: str) -> re.Pattern:
    return re.compile(r"<" + re.escape(tag) + r"(?=[\s/>]|$)")


def start_line(tag: str, reported_line: int | None, lines: Sequence[str]) -> int | None:
    """The 1-based line where `<tag` begins, searching back from lxml's reported line."""
    if reported_line is None or not lines or reported_line > len(lines):
        return reported_line
    pattern = _opening(tag)
    for line in range(reported_line, max(reported_line - _MAX_TAG_LINES, 0), -1):
        if pattern.search(lines[line - 1]):
            return line
    return reported_line
