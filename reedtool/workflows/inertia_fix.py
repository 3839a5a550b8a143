"""`inertia --fix` on a xacro model: each tensor to change edited where the user wrote it
(io.xacro_edit), or printed with the line to change.

The <inertial> of a link may be written in a macro body (RotorS' multirotor_base_macro,
in a file of reedtool's or of another package) with its tensor passed in as a block
from the user's file (`<xacro:insert_block name="body_inertia"/>`). The literal
<inertia/> to change is the one in the user's file (the call's file, inside the
model's own package) whose six moments are the link's declared ones: it is edited
there, with a numbered backup, when exactly one matches and every link it feeds gets
the same correction. Anything else is printed, with the line to change in the user's
file, never in a file of reedtool's install.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from reedtool.errors import ReedtoolError

# (file, span start, span end) -> (the span, the tensor to write, the links it feeds; a
# link prefixed "!" needs another tensor than the first).
Edits = dict[tuple[str, int, int], tuple[object, np.ndarray, list[str]]]


def _where(c, model: Path) -> str:
    """Where a correction that cannot be edited in place is to be made, in words."""
    from reedtool.io.xacro_edit import users_file

    if c.loc.macro and not users_file(c.loc.macro_file, model):
        return (f"written by the macro called at {c.loc} (the macro is not in your "
                "package: pass the block there)")
    if c.loc.macro:
        # The element is written once in the macro body; the call says which link.
        return f"in the macro body at {c.loc.macro} (the call at {c.loc})"
    return f"at {c.loc}"


def plan_edits(model: Path, comparisons, texts: dict[str, tuple[str, str]]
               ) -> tuple[Edits, list[str]]:
    """The in-place edits (one literal <inertia/> in the user's file per correction) and
    the lines to print for the corrections that cannot be placed. `texts` caches each
    file read (text, encoding)."""
    from reedtool.io.fileio import read_xml_file
    from reedtool.io.xacro_edit import inertia_elements_matching, users_file
    from reedtool.physics.inertia import inertial_xml

    edits: Edits = {}
    printed: list[str] = []
    for c in comparisons:
        props = c.corrected()
        if props is None:
            continue
        file = c.loc.file
        com_moves = not np.allclose(props.com_m, c.declared.com_m, atol=1e-12)
        spans = []
        if file and users_file(file, model) and not com_moves:
            if file not in texts:
                texts[file] = read_xml_file(Path(file), what="xacro file")
            spans = inertia_elements_matching(texts[file][0], c.declared.inertia_kg_m2)
        if len(spans) == 1:
            key = (file, spans[0].start, spans[0].end)
            if key in edits and not np.allclose(edits[key][1], props.inertia_kg_m2):
                edits[key][2].append(f"!{c.link}")       # two links, two corrections
            else:
                entry = edits.setdefault(key, (spans[0], props.inertia_kg_m2, []))
                entry[2].append(c.link)
            continue
        printed.append(f"--fix: link '{c.link}': replace the <inertial> {_where(c, model)} with")
        printed.append(inertial_xml(props, indent="  "))
        printed.append("")
    return edits, printed


def write_edits(edits: Edits, texts: dict[str, tuple[str, str]]
                ) -> tuple[list[str], set[str]]:
    """Each file's edits spliced, read back and written with a numbered backup; the notes
    and the links fixed. An <inertia/> two links share but need different tensors for is
    left as it is, with a note."""
    from reedtool.io.fileio import atomic_write_text
    from reedtool.io.xacro_edit import inertia_elements_matching, replace_span
    from reedtool.physics.inertia import inertia_element

    notes, fixed = [], set()
    by_file: dict[str, list] = {}
    for (file, _s, _e), (span, tensor, links) in edits.items():
        if any(link.startswith("!") for link in links):
            names = ", ".join(link.lstrip("!") for link in links)
            notes.append(f"--fix: links {names} share the <inertia/> at {file}:{span.line} "
                         "but need different tensors: give each its own; not changed")
            continue
        by_file.setdefault(file, []).append((span, tensor, links))
    for file, changes in by_file.items():
        text, encoding = texts[file]
        for span, tensor, _links in sorted(changes, key=lambda change: -change[0].start):
            text = replace_span(text, span, inertia_element(tensor))
        # The edit reads back as meant before it replaces the user's file.
        for span, tensor, links in changes:
            if len(inertia_elements_matching(text, tensor)) < 1:
                raise ReedtoolError(f"internal check failed rewriting the inertia of "
                                    f"{', '.join(links)}; the file was left unchanged",
                                    file=file)
        backup = atomic_write_text(Path(file), text, force=True, backup=True,
                                   encoding=encoding, in_place=True)
        for span, _tensor, links in changes:
            fixed.update(links)
            notes.append(f"--fix: rewrote the <inertia/> at {file}:{span.line} "
                         f"(link {', '.join(links)}; backup: {backup})")
    return notes, fixed


def apply_fix_xacro(model: Path, comparisons) -> tuple[list[str], set[str]]:
    """--fix on a xacro model (the module's docstring): the notes to show (edits made,
    then the blocks to paste) and the links whose tensor was rewritten."""
    texts: dict[str, tuple[str, str]] = {}
    edits, printed = plan_edits(model, comparisons, texts)
    notes, fixed = write_edits(edits, texts)
    return (notes + printed or ["--fix: nothing to change"]), fixed


def apply_fix_urdf(model: Path, comparisons) -> list[str]:
    """A .urdf's own <inertial> elements rewritten with the geometry's (io/urdf_edit), a
    numbered backup kept."""
    from reedtool.io.urdf_edit import rewrite_inertials

    todo = [(c, c.corrected()) for c in comparisons]
    todo = [(c, props) for c, props in todo if props is not None]
    if not todo:
        return ["--fix: nothing to change"]
    for c, _props in todo:
        if c.loc.line is None or Path(c.loc.file).resolve() != model.resolve():
            raise ReedtoolError(f"cannot locate the <inertial> of link '{c.link}'", file=model)
    backup = rewrite_inertials(model, [(c.link, c.loc.line, props) for c, props in todo])
    return [f"--fix: rewrote <inertial> of {', '.join(c.link for c, _ in todo)} in {model} "
            f"(backup: {backup})"]


def apply_fix(model: Path, comparisons) -> tuple[list[str], set[str], bool]:
    """inertia --fix: the notes to print, the links whose xacro tensor was fixed, and
    whether the model is a .urdf (fixed in place) rather than a xacro tree."""
    if model.suffix.lower() == ".urdf":
        return apply_fix_urdf(model, comparisons), set(), True
    notes, fixed = apply_fix_xacro(model, comparisons)
    return notes, fixed, False
