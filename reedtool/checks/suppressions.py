"""Inline suppressions: `<!-- reedtool: ignore[I203] -->` on an element's line or above it.

Like ruff's `# noqa: E501` and catkin_lint's `#catkin_lint: ignore`, written as an XML
comment because models are XML. Several codes or rule names go comma-separated
(`ignore[I203, mesh-unresolved]`); a bare `ignore` (no brackets) silences every rule on
that line. The comment belongs in the file the finding names: for an element a macro made,
the .xacro line of the macro call the user wrote, which is where `validate` points.

A suppression names whole codes or rule names (as ruff's noqa names whole codes): a name
that is neither silences nothing, and rule S142 says so; one that silenced nothing in a
run is reported by S143, as ruff's RUF100 reports unused noqa comments.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, fields, is_dataclass
from functools import lru_cache
from pathlib import Path
from typing import Iterable, Iterator

_COMMENT = re.compile(r"<!--\s*reedtool:\s*ignore(?:\[([^\]]*)\])?\s*-->", re.IGNORECASE)
ALL = "*"


@dataclass(frozen=True)
class Comment:
    """One suppression comment: the line it is on and the names it gives (ALL: bare)."""

    line: int
    names: tuple[str, ...]


@lru_cache(maxsize=256)
def _file_comments(path: str, mtime_ns: int) -> tuple[Comment, ...]:
    try:
        text = Path(path).read_text(encoding="utf-8-sig", errors="replace")
    except OSError:
        return ()
    if "reedtool" not in text.lower():
        return ()       # most files have none: no line-by-line search
    out = []
    for number, line in enumerate(text.splitlines(), start=1):
        for match in _COMMENT.finditer(line):
            names = ((ALL,) if match.group(1) is None else
                     tuple(n.strip() for n in match.group(1).split(",") if n.strip()))
            out.append(Comment(number, names))
    return tuple(out)


def comments(path: str) -> tuple[Comment, ...]:
    """The suppression comments of a file (read once per version of the file)."""
    try:
        mtime_ns = Path(path).stat().st_mtime_ns
    except OSError:
        return ()
    return _file_comments(str(Path(path).resolve()), mtime_ns)


def _names_match(name: str, code: str, slug: str) -> bool:
    return name == ALL or name.upper() == code or name.lower() == slug


def silencers(code: str, slug: str, file: str | None, line: int | None
              ) -> list[tuple[str, int, str]]:
    """The (file, comment line, name) entries that silence a finding of rule `code`/`slug`
    at file:line: a comment covers its own line and the next."""
    if not file or not line:
        return []
    key = str(Path(file).resolve())
    return [(key, c.line, name) for c in comments(file) if c.line in (line, line - 1)
            for name in c.names if _names_match(name, code, slug)]


def is_suppressed(code: str, slug: str, file: str | None, line: int | None) -> bool:
    """Is a finding of rule `code`/`slug` at file:line silenced by an inline comment?"""
    return bool(silencers(code, slug, file, line))


def source_files(robot) -> dict[str, str]:
    """Every file an element of `robot` was read from (where its suppressions can be):
    resolved path -> the path as the elements name it (what the findings show). Kept on
    the robot: S142 and the run's S143 both ask."""
    cached = getattr(robot, "_suppression_source_files", None)
    if cached is not None:
        return cached
    from reedtool.model import SourceLoc

    files: set[str] = set()
    seen: set[int] = set()

    def visit(value, depth: int) -> None:
        if depth > 6 or id(value) in seen:
            return
        if isinstance(value, SourceLoc):
            files.add(value.file)
            return
        if isinstance(value, (list, tuple)):
            for item in value:
                if isinstance(item, (SourceLoc, list, tuple)) or is_dataclass(item):
                    visit(item, depth + 1)
        elif is_dataclass(value) and not isinstance(value, type):
            seen.add(id(value))
            for name in _dataclass_fields(type(value)):
                item = getattr(value, name, None)
                if isinstance(item, (SourceLoc, list, tuple)) or is_dataclass(item):
                    visit(item, depth + 1)

    visit(robot, 0)
    out = {str(Path(f).resolve()): f for f in sorted(files) if f and Path(f).is_file()}
    try:
        robot._suppression_source_files = out
    except AttributeError:        # a frozen or slotted stand-in: computed again next time
        pass
    return out


@lru_cache(maxsize=128)
def _dataclass_fields(kind: type) -> tuple[str, ...]:
    return tuple(f.name for f in fields(kind))


def unknown_names(path: str) -> Iterator[tuple[int, str]]:
    """(line, name) for each name of a suppression comment that is no rule code or name."""
    from reedtool.checks.registry import all_rules

    rules = all_rules()
    codes = {r.code for r in rules}
    slugs = {r.slug for r in rules}
    for comment in comments(path):
        for name in comment.names:
            if name != ALL and name.upper() not in codes and name.lower() not in slugs:
                yield comment.line, name


def unused(files: Iterable[str], used: set[tuple[str, int, str]], enabled
           ) -> Iterator[tuple[str, int, str]]:
    """(file, line, name) of each suppression in `files` that silenced nothing (`used`
    holds the entries that did, from `silencers`). `enabled(code_or_name) -> bool`: a name
    for a rule that did not run (`--select`) is not judged; unknown names are S142's."""
    from reedtool.checks.registry import get_rule

    for file in sorted(files):
        for comment in comments(file):
            for name in comment.names:
                if (file, comment.line, name) in used:
                    continue
                rule = get_rule(name) if name != ALL else None
                if name != ALL and (rule is None or not enabled(rule.code)):
                    continue
                yield file, comment.line, name
