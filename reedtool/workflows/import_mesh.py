"""`import-stl` as one call: a CAD STL into a ROS package, in metres and FLU
(physics.mesh_import), its collision mesh and <link> snippet written all or nothing, and,
into a package new-package wrote, the edit that makes the mesh the model's body
(generate.package_body). The caller prints the outcome (report.import_text).
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

from reedtool.errors import ReedtoolError
from reedtool.report.import_text import snippet_text

NAME_RE = re.compile(r"^[A-Za-z0-9_][A-Za-z0-9_.-]*$")


def package_name(package_dir: Path) -> str:
    """<name> from DIR/package.xml; a directory without one is not a ROS package."""
    from lxml import etree

    manifest = package_dir / "package.xml"
    if not package_dir.is_dir():
        raise ReedtoolError("package directory not found", file=package_dir,
                            hint="create it with `reedtool new-package`, or pass an existing one")
    if not manifest.is_file():
        raise ReedtoolError("not a ROS package: no package.xml", file=package_dir,
                            hint="pass the package's root directory (the one with package.xml)")
    try:
        root = etree.parse(str(manifest)).getroot()
    except etree.XMLSyntaxError as exc:
        raise ReedtoolError(f"malformed XML: {exc.msg}", file=manifest, line=exc.lineno) from exc
    name = (root.findtext("name") or "").strip()
    if root.tag != "package" or not name:
        raise ReedtoolError("package.xml has no <package><name>", file=manifest,
                            hint="add <name>your_package</name>")
    return name


def default_name(mesh_path: Path) -> str:
    name = re.sub(r"[^A-Za-z0-9_.-]", "_", mesh_path.stem)
    return name if NAME_RE.match(name) else f"mesh_{name}"


@dataclass
class ImportOutcome:
    imported: object               # reedtool.physics.mesh_import.ImportedMesh
    package: str
    mesh_file: Path
    collision_file: Path | None
    snippet: str
    body_edit: object | None = None   # generate.package_body.BodyEdit for the package's model
    body_written: bool = False        # the edit was written (--set-body)
    body_backup: Path | None = None


def _check_numbers(from_frame: str, mass_kg: float | None, density_kg_m3: float | None) -> None:
    from reedtool.errors import check_plausible
    from reedtool.frames import axis_convention

    if from_frame.strip().lower() != "auto":
        axis_convention(from_frame)  # an unknown frame is the error to report, not a refusal
    if mass_kg is not None:
        check_plausible("mass", mass_kg, "--mass")
    if density_kg_m3 is not None:
        check_plausible("density", density_kg_m3, "--density")


def _outputs(mesh: Path, package_dir: Path, name: str | None, collision: str,
             snippet_file: Path | None, force: bool) -> tuple[str, Path, Path | None]:
    """The part's name, its mesh file and collision file (None: the visual mesh), each
    refused before any work when it may not be written, so a refusal leaves no partial
    import."""
    from reedtool.io.fileio import check_writable

    name = name or default_name(mesh)
    if not NAME_RE.match(name):
        raise ReedtoolError(f"bad --name '{name}'",
                            hint="use letters, digits, '_', '-' and '.' only")
    mesh_file = package_dir / "meshes" / f"{name}.stl"
    will_collide = collision.strip().lower() != "same"
    collision_file = package_dir / "meshes" / f"{name}_collision.stl" if will_collide else None
    for target in (mesh_file, collision_file, snippet_file):
        if target is not None:
            check_writable(target, force)
    if mesh.resolve() == mesh_file.resolve():
        raise ReedtoolError("the output would overwrite the input mesh", file=mesh,
                            hint="pass a different --name")
    return name, mesh_file, collision_file


def _body_model(package_dir: Path, set_body: bool):
    """The package's model new-package wrote (its body properties), or None."""
    from reedtool.generate.package_body import find_body_model

    body_model = find_body_model(package_dir)
    if set_body and body_model is None:
        raise ReedtoolError("--set-body: no model in DIR/urdf/ declares the body properties "
                            "(mesh_file and body_inertia) new-package writes", file=package_dir,
                            hint="set the body by hand from the snippet, or create the package "
                                 "with `reedtool new-package`")
    return body_model


def run_import(mesh: Path, package_dir: Path, *, name: str | None = None, units: str = "auto",
               from_frame: str = "auto", mass_kg: float | None = None,
               density_kg_m3: float | None = None, recenter: str = "none",
               collision: str = "same", snippet_file: Path | None = None,
               force: bool = False, progress=None, set_body: bool = False) -> ImportOutcome:
    """Import `mesh` into `package_dir`: the whole command without its printing.

    When the package's model is one new-package wrote (generate.package_body), the edit
    that makes the mesh its body is planned: written with `set_body` (a numbered backup
    of the model file first), else returned for its lines to be printed."""
    from reedtool.io.fileio import atomic_write_many
    from reedtool.io.stl import stl_bytes
    from reedtool.physics.mesh_import import import_mesh

    _check_numbers(from_frame, mass_kg, density_kg_m3)
    package = package_name(package_dir)
    name, mesh_file, collision_file = _outputs(mesh, package_dir, name, collision,
                                               snippet_file, force)
    from reedtool.generate.package_body import package_mass_kg

    body_model = _body_model(package_dir, set_body)
    # The body's mass is the package's unless given: it is what the model flies with.
    body_mass = None
    if body_model is not None and mass_kg is None and density_kg_m3 is None:
        body_mass = package_mass_kg(body_model)
    imported = import_mesh(mesh, units=units, from_frame=from_frame,
                           mass_kg=mass_kg if body_mass is None else body_mass,
                           density_kg_m3=density_kg_m3, recenter=recenter,
                           collision=collision, progress=progress,
                           role="body" if body_model is not None else "part")
    if body_mass is not None:
        imported.mass_source = f"the body mass in {body_model.name}"
    if progress:
        progress("writing")
    header = f"reedtool import-stl {mesh.name}: metres, FLU"
    outputs = [(mesh_file, stl_bytes(imported.triangles_m, header))]
    if collision_file is not None and imported.collision_m is not None:
        outputs.append((collision_file,
                        stl_bytes(imported.collision_m, header + ", collision")))
    snippet = snippet_text(imported, package, name,
                           collision_file.stem if collision_file is not None else None)
    if snippet_file is not None:
        outputs.append((snippet_file, snippet.encode("utf-8")))
    edit = None
    if body_model is not None:
        from reedtool.generate.package_body import check_edit, plan_body_edit

        edit = plan_body_edit(body_model, package, name, imported.mass,
                              set_mass=mass_kg is not None or density_kg_m3 is not None)
        check_edit(edit, imported.mass)
    # All or nothing: a snippet that cannot be written must not leave the meshes behind.
    atomic_write_many(outputs, force=force)
    backup = None
    if set_body:
        from reedtool.io.fileio import atomic_write_text

        backup = atomic_write_text(edit.file, edit.new_text, force=True, backup=True,
                                   encoding=edit.encoding, in_place=True)
    return ImportOutcome(imported, package, mesh_file, collision_file, snippet, edit,
                         set_body, backup)
