"""Edits of a user's URDF file: each named link's <inertial> replaced (`inertia --fix`).

The text is spliced, never re-serialised, so every other byte (comments, layout, the order
of attributes) stays as the user wrote it; the new <inertial> is written by io/urdf_write.py
at the indentation of the one it replaces. The edit is read back with io/urdf.py before it
replaces the file, which is kept as a numbered backup (io/fileio.py).
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from reedtool.errors import ReedtoolError

_INERTIAL_OPEN = re.compile(r"<inertial\b[^>]*?(/?)>")


def inertial_span(text: str, line: int) -> tuple[int, int]:
    """Character span of the <inertial> element that starts on `line` (1-based)."""
    start_of_line = 0
    for _ in range(line - 1):
        start_of_line = text.index("\n", start_of_line) + 1
    match = _INERTIAL_OPEN.search(text, start_of_line)
    if match is None:
        raise ValueError(f"no <inertial> at line {line}")
    if match.group(1):                       # <inertial/>
        return match.start(), match.end()
    close = text.find("</inertial>", match.end())
    if close < 0:
        raise ValueError(f"unclosed <inertial> at line {line}")
    return match.start(), close + len("</inertial>")


def replace_inertials(text: str, fixes: list[tuple[int, object]]) -> str:
    """Replace each <inertial> starting on the given line with one for the given mass
    properties (anything with mass_kg, com_m and inertia_kg_m2, about the COM in link axes)."""
    from reedtool.io.urdf_write import inertial_text

    spans = []
    for line, props in fixes:
        start, end = inertial_span(text, line)
        indent = text[text.rfind("\n", 0, start) + 1:start]
        block = inertial_text(props.mass_kg, props.com_m, props.inertia_kg_m2,
                              indent=indent if not indent.strip() else "")
        spans.append((start, end, block.lstrip()))
    for start, end, block in sorted(spans, reverse=True):
        text = text[:start] + block + text[end:]
    return text


def rewrite_inertials(path: Path, fixes: list[tuple[str, int, object]]) -> Path:
    """Rewrite the <inertial> of each (link, line, mass properties) in the URDF file `path`
    in place; returns the backup's path. The edit is read back first: every fixed link must
    read as meant, else the file is left unchanged."""
    from reedtool.io.fileio import atomic_write_text, read_xml_file
    from reedtool.io.urdf import parse_urdf

    text, encoding = read_xml_file(path, what="URDF file")
    new_text = replace_inertials(text, [(line, props) for _link, line, props in fixes])
    check = parse_urdf(new_text, path)
    for link, _line, props in fixes:
        read_back = check.link_map[link].inertial
        # Ten significant digits are written (5e-10 relative); round-off entries as 0.
        if (read_back is None or not np.isclose(read_back.mass_kg, props.mass_kg, rtol=1e-9)
                or not np.allclose(read_back.inertia_in_link_axes(), props.inertia_kg_m2,
                                   rtol=1e-8, atol=1e-12 * np.abs(props.inertia_kg_m2).max())):
            raise ReedtoolError(f"internal check failed rewriting link '{link}'; "
                                "the file was left unchanged", file=path)
    return atomic_write_text(path, new_text, force=True, backup=True, encoding=encoding,
                             in_place=True)
