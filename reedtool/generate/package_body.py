"""`import-stl --package`: a body mesh into the model new-package wrote for that package.

A package new-package generated holds its body in properties of one xacro file
(urdf/NAME.xacro, or urdf/NAME.urdf.xacro for gz-sim): `mesh_file` (and `use_mesh_file`),
`mass`, `body_com_xyz` (the COM in the CAD frame, in <inertial><origin>) and the block
`body_inertia` (the tensor about the COM). Setting those makes the imported mesh the
model's body; nothing else in the file changes (io.xacro_edit splices the text).
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from reedtool.errors import ReedtoolError

BODY_PROPERTIES = ("mesh_file", "body_inertia")


@dataclass
class BodyEdit:
    file: Path                       # the package's model file
    old_text: str
    new_text: str
    encoding: str
    lines: list[str]                 # the exact lines to change, as "FILE:LINE: new line"
    mass_kg: float                   # the body mass written (or kept)


def find_body_model(package_dir: Path) -> Path | None:
    """The package's xacro file that declares the body properties, if exactly one does."""
    from reedtool.io.fileio import read_xml_file
    from reedtool.io.xacro_edit import property_block_span, property_value_span

    found = []
    for path in sorted((package_dir / "urdf").glob("*.xacro")):
        try:
            text, _ = read_xml_file(path, what="xacro file")
        except ReedtoolError:
            continue
        if property_value_span(text, "mesh_file") and property_block_span(text, "body_inertia"):
            found.append(path)
    return found[0] if len(found) == 1 else None


def property_value(text: str, name: str) -> str | None:
    from reedtool.io.xacro_edit import property_value_span

    span = property_value_span(text, name)
    return None if span is None else text[span.start:span.end]


def package_mass_kg(model_file: Path) -> float | None:
    """The body `mass` property when it is a plain number."""
    from reedtool.io.fileio import read_xml_file

    text, _ = read_xml_file(model_file, what="xacro file")
    try:
        return float(property_value(text, "mass") or "")
    except ValueError:
        return None


def plan_body_edit(model_file: Path, package: str, mesh_name: str, props,
                   set_mass: bool) -> BodyEdit:
    """The edit that makes meshes/MESH_NAME.stl (with `props`: MassProperties in the
    mesh's frame) the body of `model_file`."""
    from reedtool.io.fileio import read_xml_file
    from reedtool.io.xacro_edit import property_value_span, set_block_inertia, set_properties
    from reedtool.io.xml_numbers import short_text
    from reedtool.physics.inertia import inertia_element
    from reedtool.generate.package_spec import com_text

    text, encoding = read_xml_file(model_file, what="xacro file")
    values = {"mesh_file": f"package://{package}/meshes/{mesh_name}.stl"}
    if property_value_span(text, "use_mesh_file") is not None:
        values["use_mesh_file"] = "true"
    com = np.asarray(props.com_m, dtype=float)
    if property_value_span(text, "body_com_xyz") is not None:
        values["body_com_xyz"] = com_text(com)
    elif np.linalg.norm(com) > 1e-6:
        # The RotorS macro's <inertial> is fixed at the body origin: a COM elsewhere
        # cannot be written without moving the mesh, which is what the user must not get.
        raise ReedtoolError(
            f"the body COM is ({', '.join(f'{v * 1000:.4g}' for v in com)}) mm off the mesh "
            f"origin and {model_file.name} has no body_com_xyz property: its body is the "
            "RotorS multirotor_base_macro, whose <inertial> sits at the origin",
            file=model_file,
            hint="regenerate the package with `reedtool new-package NAME --mesh MESH`, which "
                 "writes the body with its COM, or pass --recenter com to move the mesh")
    mass_kg = float(props.mass_kg)
    if set_mass:
        values["mass"] = short_text(mass_kg)
    new_text, missing = set_properties(text, values)
    missing = [name for name in missing if name != "use_mesh_file"]
    new_text, inertia_span = set_block_inertia(new_text, "body_inertia",
                                               inertia_element(props.inertia_kg_m2))
    if missing or inertia_span is None:
        raise ReedtoolError(f"{model_file.name} has no {' / '.join(missing or ['body_inertia'])}"
                            " property to set", file=model_file)
    lines = []
    for name in values:
        span = property_value_span(new_text, name)
        lines.append(f"{model_file}:{span.line}: "
                     f'<xacro:property name="{name}" value="{values[name]}" />')
    lines.append(f"{model_file}:{inertia_span.line}: {inertia_element(props.inertia_kg_m2)} "
                 "(inside <xacro:property name=\"body_inertia\">)")
    return BodyEdit(model_file, text, new_text, encoding, lines, mass_kg)


def check_edit(edit: BodyEdit, props) -> None:
    """The edited text declares what was meant (read back with an XML parser)."""
    from lxml import etree

    root = etree.fromstring(edit.new_text.encode("utf-8"))
    props_by_name = {}
    for element in root.iter():
        if isinstance(element.tag, str) and element.tag.endswith("property"):
            props_by_name[element.get("name")] = element
    block = props_by_name.get("body_inertia")
    inertia = block.find("inertia") if block is not None else None
    ok = inertia is not None
    if ok:
        values = {key: float(inertia.get(key)) for key in
                  ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")}
        I = np.asarray(props.inertia_kg_m2)
        expected = {"ixx": I[0, 0], "ixy": I[0, 1], "ixz": I[0, 2], "iyy": I[1, 1],
                    "iyz": I[1, 2], "izz": I[2, 2]}
        scale = float(np.abs(I).max())
        # Written to 10 significant digits: 1e-9 of the largest moment holds them.
        ok = all(abs(values[k] - expected[k]) <= 1e-9 * scale + 1e-15 for k in values)
    if not ok or re.search(r"<xacro:property\s+name=\"mesh_file\"", edit.new_text) is None:
        raise ReedtoolError("internal check failed setting the body; the file was left "
                            "unchanged", file=edit.file)
