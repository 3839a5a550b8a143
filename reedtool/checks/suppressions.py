"""Inline suppressions: `<!-- reedtool: ignore[I203] -->` on an element's line or above it.

Like ruff's `# noqa: E501` and catkin_lint's `#catkin_lint: ignore`, written as an XML
comment because models are XML. Several codes or rule names go comma-separated
(`ignore[I203, mesh-unresolved]`); a bare `ignore` (no brackets) silences every rule on
that line. The comment belongs in the file the finding names: for an element a macro made,
the .xacro line of the macro call the user wrote, which is where `validate` points.
"""

from __future__ import annotations

import re
from functools import lru_cache
from pathlib import Path

_COMMENT = re.compile(r"<!--\s*reedtool:\s*ignore(?:\[([^\]]*)\])?\s*-->", re.IGNORECASE)
ALL = "*"


@lru_cache(maxsize=256)
def _file_suppressions(path: str, mtime_ns: int) -> dict[int, frozenset[str]]:
    """Line -> codes/slugs silenced there (a comment covers its own line and the next)."""
    try:
        text = Path(path).read_text(encoding="utf-8-sig", errors="replace")
    except OSError:
        return {}
    out: dict[int, set[str]] = {}
    for number, line in enumerate(text.splitlines(), start=1):
        for match in _COMMENT.finditer(line):
            names = ({ALL} if match.group(1) is None else
                     {n.strip() for n in match.group(1).split(",") if n.strip()})
            for target in (number, number + 1):
                out.setdefault(target, set()).update(names)
    return {line: frozenset(names) for line, names in out.items()}


def suppressions(path: str) -> dict[int, frozenset[str]]:
    try:
        mtime_ns = Path(path).stat().st_mtime_ns
    except OSError:
        return {}
    return _file_suppressions(str(Path(path).resolve()), mtime_ns)


def is_suppressed(code: str, slug: str, file: str | None, line: int | None) -> bool:
    """Is a finding of rule `code`/`slug` at file:line silenced by an inline comment?"""
    if not file or not line:
        return False
    names = suppressions(file).get(line)
    if not names:
        return False
    return ALL in names or code in {n.upper() for n in names} or slug in {n.lower()
                                                                        for n in names}
