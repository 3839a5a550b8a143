"""Edits of a user's xacro file: a property's value, an <inertia> element found by its values.

The text is spliced, never re-serialised, so every other byte (comments, layout, the order
of attributes) stays as the user wrote it. Only a file of the user's own package is ever
edited: the ROS package (the nearest directory up with a package.xml) that holds the model,
never a file of reedtool's install or of another package (`users_file`).
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from reedtool.model import INERTIA_INDEX, INERTIA_KEYS

_ATTR = re.compile(r'([A-Za-z_:][\w:.-]*)\s*=\s*"([^"]*)"')
_INERTIA = re.compile(r"<inertia\b([^>]*?)/>", re.S)
_PROPERTY = re.compile(r'<xacro:property\b([^>]*?)(/?)>', re.S)


def users_file(candidate: str | Path, model: str | Path) -> bool:
    """`candidate` is in the model's own package (its directory tree when it has none),
    and not inside reedtool's install."""
    import reedtool
    from reedtool.resolve.packages import enclosing_package

    candidate = Path(candidate).resolve()
    install = Path(reedtool.__file__).resolve().parent
    if candidate.is_relative_to(install):
        return False
    root = enclosing_package(Path(model)) or Path(model).resolve().parent
    return candidate.is_relative_to(root)


@dataclass(frozen=True)
class Span:
    start: int
    end: int
    line: int            # 1-based line of `start`


def _line(text: str, offset: int) -> int:
    return text.count("\n", 0, offset) + 1


def _numbers(attrs: str) -> dict[str, float] | None:
    values = dict(_ATTR.findall(attrs))
    try:
        return {key: float(values[key]) for key in INERTIA_KEYS}
    except (KeyError, ValueError):
        return None        # an expression (${...}) or a missing moment: not a literal tensor


def inertia_elements_matching(text: str, tensor_kg_m2, rtol: float = 1e-6) -> list[Span]:
    """Literal <inertia .../> elements whose six moments equal `tensor_kg_m2` (to `rtol`
    of its largest moment: the file's numbers are printed to 6+ significant digits)."""
    tensor = np.asarray(tensor_kg_m2, dtype=float)
    scale = float(np.abs(tensor).max()) or 1.0
    found = []
    for match in _INERTIA.finditer(text):
        values = _numbers(match.group(1))
        if values is None:
            continue
        if all(abs(values[key] - tensor[INERTIA_INDEX[key]]) <= rtol * scale for key in INERTIA_KEYS):
            found.append(Span(match.start(), match.end(), _line(text, match.start())))
    return found


def replace_span(text: str, span: Span, new: str) -> str:
    return text[:span.start] + new + text[span.end:]


def property_value_span(text: str, name: str) -> Span | None:
    """The value="..." of `<xacro:property name="NAME" value="..."/>` (the value's
    characters, without the quotes), or None when there is no such property."""
    for match in _PROPERTY.finditer(text):
        attrs = match.group(1)
        if dict(_ATTR.findall(attrs)).get("name") != name:
            continue
        value = re.search(r'\bvalue\s*=\s*"([^"]*)"', attrs)
        if value is None:
            return None
        start = match.start(1) + value.start(1)
        return Span(start, match.start(1) + value.end(1), _line(text, start))
    return None


def property_block_span(text: str, name: str) -> Span | None:
    """The body of `<xacro:property name="NAME"> ... </xacro:property>` (a block property)."""
    for match in _PROPERTY.finditer(text):
        if match.group(2) or dict(_ATTR.findall(match.group(1))).get("name") != name:
            continue
        close = text.find("</xacro:property>", match.end())
        if close < 0:
            return None
        return Span(match.end(), close, _line(text, match.end()))
    return None


def set_properties(text: str, values: dict[str, str]) -> tuple[str, list[str]]:
    """`text` with each named property's value replaced; the names not found."""
    missing = []
    for name, value in values.items():
        span = property_value_span(text, name)
        if span is None:
            missing.append(name)
            continue
        text = replace_span(text, span, value)
    return text, missing


def set_block_inertia(text: str, name: str, element: str) -> tuple[str, Span | None]:
    """`text` with the <inertia/> inside block property NAME replaced by `element`."""
    block = property_block_span(text, name)
    if block is None:
        return text, None
    match = _INERTIA.search(text, block.start, block.end)
    if match is None:
        return text, None
    span = Span(match.start(), match.end(), _line(text, match.start()))
    return replace_span(text, span, element), span
