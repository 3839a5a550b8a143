"""Legacy (pre-namespace) xacro: find it, and rewrite it to modern spelling.

Old tutorials write `<property>`, `<macro>`, `<include>`, `<insert_block>` and call
macros as `<smartcar_body/>`. xacro 2.x no longer understands any of that and copies the
tags into the URDF unchanged, so the model silently loses its links. Here each such tag is
found with its line, and the text is rewritten tag name by tag name: only the names
change (`<property` -> `<xacro:property`, `</macro>` -> `</xacro:macro>`), so comments,
attribute order, indentation and line numbers stay exactly as the user wrote them.

A small tag scanner is used instead of an XML parser because the rewrite must be a text
edit at exact offsets, and because legacy files are often not namespace-clean.
"""

from __future__ import annotations

import functools
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Callable, Iterable

XACRO_NS = "http://ros.org/wiki/xacro"

# Legacy directive -> attribute that distinguishes it from a same-named tag of URDF/SDF
# (an SDF <include> has a <uri> child, not a filename attribute).
LEGACY_DIRECTIVES = {
    "property": "name",
    "macro": "name",
    "include": "filename",
    "insert_block": "name",
    "arg": "name",
    "if": "value",
    "unless": "value",
}

_TOKEN = re.compile(
    r"<!--.*?-->"
    r"|<!\[CDATA\[.*?\]\]>"
    r"|<\?.*?\?>"
    r"|<!DOCTYPE[^>]*>"
    r"|</\s*(?P<close>[^\s>/]+)\s*>"
    r"|<(?P<open>[^\s>/!?]+)(?P<attrs>(?:[^>\"']|\"[^\"]*\"|'[^']*')*?)(?P<empty>/?)>",
    re.DOTALL)
_ATTR = re.compile(r"([^\s=]+)\s*=\s*(?:\"([^\"]*)\"|'([^']*)')")


@dataclass(frozen=True)
class LegacyTag:
    file: str
    line: int
    tag: str          # as written, e.g. "property" or "smartcar_body"
    modern: str       # e.g. "xacro:property", "xacro:smartcar_body"
    kind: str         # "directive" or "macro-call"

    def __str__(self) -> str:
        what = "macro call" if self.kind == "macro-call" else "legacy xacro tag"
        return f"{self.file}:{self.line}: {what} <{self.tag}> -> write <{self.modern}>"


@dataclass(frozen=True)
class _Tag:
    name: str
    start: int        # offset of the name in the text
    line: int
    attrs: dict[str, str]
    empty: bool
    closing: bool


# The tags of a file are read for its includes, its macros and its legacy tags, and a
# repository's models include the same macro files: the tags of recent texts are kept
# (texts up to 1 MB; the key is the text itself, so an edited file is read again).
TAG_CACHE_MAX_CHARS = 1024 * 1024


@functools.lru_cache(maxsize=64)
def _cached_tags(text: str) -> tuple[_Tag, ...]:
    return tuple(_read_tags(text))


def _tags(text: str) -> Iterable[_Tag]:
    return _cached_tags(text) if len(text) <= TAG_CACHE_MAX_CHARS else _read_tags(text)


def _read_tags(text: str) -> Iterable[_Tag]:
    line, last = 1, 0
    for match in _TOKEN.finditer(text):
        line += text.count("\n", last, match.start())
        last = match.start()
        if match.group("close"):
            yield _Tag(match.group("close"), match.start("close"), line, {}, False, True)
        elif match.group("open"):
            attrs = {m.group(1): m.group(2) if m.group(2) is not None else m.group(3)
                     for m in _ATTR.finditer(match.group("attrs"))}
            yield _Tag(match.group("open"), match.start("open"), line, attrs,
                       bool(match.group("empty")), False)


def macro_names(text: str) -> set[str]:
    """Names of the macros a file defines, in legacy or modern spelling."""
    return {tag.attrs["name"].strip() for tag in _tags(text)
            if not tag.closing and tag.name in ("macro", "xacro:macro") and "name" in tag.attrs}


def include_specs(text: str) -> list[str]:
    """The filename attributes of every include, legacy or modern."""
    return [tag.attrs["filename"] for tag in _tags(text)
            if not tag.closing and tag.name in ("include", "xacro:include")
            and "filename" in tag.attrs]


def _legacy_kind(tag: _Tag, macros: set[str], in_gazebo: bool) -> str | None:
    if ":" in tag.name:
        return None
    if tag.name in LEGACY_DIRECTIVES and LEGACY_DIRECTIVES[tag.name] in tag.attrs:
        return "directive"
    # Gazebo extension content is plugin parameters (gz-sim's <rotorConfiguration><rotor>,
    # ...), never a macro call, even when a macro happens to share the element's name.
    if tag.name in macros and tag.name not in LEGACY_DIRECTIVES and not in_gazebo:
        return "macro-call"
    return None


def scan_and_fix(text: str, file: str, macros: set[str]) -> tuple[list[LegacyTag], str]:
    """Legacy tags in `text` (with lines) and the text rewritten to modern spelling.

    `macros` are the macro names known in the whole include tree, so that a macro defined
    in one file and called unprefixed in another is recognised.
    """
    found: list[LegacyTag] = []
    edits: list[int] = []                 # offsets where "xacro:" is inserted
    stack: list[tuple[str, bool]] = []    # (tag name, renamed)
    gazebo_open = 0                       # <gazebo> elements on the stack (kept, not searched:
    root_seen = False                     # a deep file would make that quadratic)
    root_needs_ns: int | None = None
    for tag in _tags(text):
        if tag.closing:
            # Pop to the matching open tag; tolerate sloppy nesting in old files.
            for depth in range(len(stack) - 1, -1, -1):
                if stack[depth][0] == tag.name:
                    if stack[depth][1]:
                        edits.append(tag.start)
                    gazebo_open -= sum(1 for name, _ in stack[depth:] if name == "gazebo")
                    del stack[depth:]
                    break
            continue
        if not root_seen:
            root_seen = True
            if "xmlns:xacro" not in tag.attrs:
                root_needs_ns = tag.start + len(tag.name)
        kind = _legacy_kind(tag, macros, in_gazebo=gazebo_open > 0)
        if kind:
            found.append(LegacyTag(file, tag.line, tag.name, f"xacro:{tag.name}", kind))
            edits.append(tag.start)
        if not tag.empty:
            stack.append((tag.name, bool(kind)))
            gazebo_open += tag.name == "gazebo"
    if not found:
        return [], text
    pieces, prev = [], 0
    inserts = [(offset, "xacro:") for offset in edits]
    if root_needs_ns is not None:
        inserts.append((root_needs_ns, f' xmlns:xacro="{XACRO_NS}"'))
    for offset, insert in sorted(inserts):
        pieces.append(text[prev:offset])
        pieces.append(insert)
        prev = offset
    pieces.append(text[prev:])
    return found, "".join(pieces)


@dataclass
class LegacyScan:
    """Legacy tags of a whole include tree, and each file's modern text."""

    files: list[Path]                      # every file reached, in include order
    tags: list[LegacyTag]
    fixed_text: dict[Path, str]            # only files that change


def follow_includes(model: Path, resolve_include: Callable[[str, Path], Path | None]
                    ) -> dict[Path, str]:
    """The text of `model` and of every file it includes statically, in include order.

    Includes `resolve_include` cannot evaluate (None) are not followed; missing and
    unreadable files are left out (the expansion reports them with their include line).
    """
    texts: dict[Path, str] = {}
    pending = [Path(model).resolve()]
    while pending:
        path = pending.pop(0)
        if path in texts:
            continue
        if not path.is_file():
            continue  # missing, a directory or a device: the expansion reports it
        try:
            texts[path] = path.read_text(encoding="utf-8")
        except (OSError, UnicodeDecodeError):
            continue
        for spec in include_specs(texts[path]):
            target = resolve_include(spec, path)
            if target is not None:
                pending.append(target.resolve())
    return texts


def scan_tree(model: Path, resolve_include: Callable[[str, Path], Path | None],
              display: Callable[[Path], str] = str) -> LegacyScan:
    """Follow includes from `model`, collect macro names, then find legacy tags.

    `resolve_include(spec, including_file)` turns a filename attribute into a path, or
    None when it cannot be evaluated statically (e.g. it uses ${...}); such includes are
    not followed here, and their legacy tags, if any, are not seen.
    """
    texts = follow_includes(model, resolve_include)
    order = list(texts)
    macros: set[str] = set()
    for text in texts.values():
        macros |= macro_names(text)
    tags: list[LegacyTag] = []
    fixed: dict[Path, str] = {}
    for path in order:
        found, new_text = scan_and_fix(texts[path], display(path), macros)
        tags.extend(found)
        if found:
            fixed[path] = new_text
    return LegacyScan(order, tags, fixed)
