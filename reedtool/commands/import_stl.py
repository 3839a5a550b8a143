"""`reedtool import-stl`: a CAD STL into a package, in metres and FLU, with its inertia."""

from __future__ import annotations

import re
import sys
from dataclasses import dataclass
from pathlib import Path

import click

from reedtool.errors import ReedtoolError

# A large mesh (about 200,000 binary triangles) gets a progress bar.
PROGRESS_MIN_BYTES = 10_000_000
STAGES = ("reading", "checking", "transforming", "mass properties", "collision mesh", "writing")
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


def snippet_text(imported, package: str, name: str, collision_name: str | None) -> str:
    from reedtool.physics.inertia import inertial_xml

    visual_uri = f"package://{package}/meshes/{name}.stl"
    collision_uri = (f"package://{package}/meshes/{collision_name}.stl"
                     if collision_name else visual_uri)
    units = imported.units
    how = [f"{units.unit} -> m", f"{imported.frame.name.upper()} -> FLU: "
           f"{imported.frame.rotation_text.replace('°', ' deg')}"]
    if imported.recenter != "none":
        how.append(f"recentred on the {imported.recenter}")
    mass_note = f"mass: {imported.mass_source}"
    if imported.mass.from_hull:
        mass_note += "; open mesh, so inertia of its convex hull"

    def geometry(tag: str, uri: str) -> str:
        return (f"  <{tag}>\n"
                f"    <origin xyz=\"0 0 0\" rpy=\"0 0 0\"/>\n"
                f"    <geometry>\n"
                f"      <mesh filename=\"{uri}\"/>\n"
                f"    </geometry>\n"
                f"  </{tag}>\n")

    # "--" may not appear inside an XML comment.
    comment = f"reedtool import-stl {imported.source.name}: {', '.join(how)}; {mass_note}"
    return (f"<!-- {comment.replace('--', '- -')} -->\n"
            f"<link name=\"{name}\">\n"
            + geometry("visual", visual_uri)
            + geometry("collision", collision_uri)
            + inertial_xml(imported.mass, indent="  ") + "\n"
            + "</link>\n")


def run_import(mesh: Path, package_dir: Path, *, name: str | None = None, units: str = "auto",
               from_frame: str = "auto", mass_kg: float | None = None,
               density_kg_m3: float | None = None, recenter: str = "none",
               collision: str = "same", snippet_file: Path | None = None,
               force: bool = False, progress=None, set_body: bool = False) -> ImportOutcome:
    """Import `mesh` into `package_dir`: the whole command without its printing.

    When the package's model is one new-package wrote (generate.package_body), the edit
    that makes the mesh its body is planned: written with `set_body` (a numbered backup
    of the model file first), else returned for its lines to be printed."""
    from reedtool.frames import axis_convention
    from reedtool.io.fileio import atomic_write_many, check_writable
    from reedtool.io.stl import stl_bytes
    from reedtool.physics.mesh_import import import_mesh

    if from_frame.strip().lower() != "auto":
        axis_convention(from_frame)  # an unknown frame is the error to report, not a refusal
    from reedtool.errors import check_plausible

    if mass_kg is not None:
        check_plausible("mass", mass_kg, "--mass")
    if density_kg_m3 is not None:
        check_plausible("density", density_kg_m3, "--density")
    package = package_name(package_dir)
    name = name or default_name(mesh)
    if not NAME_RE.match(name):
        raise ReedtoolError(f"bad --name '{name}'",
                            hint="use letters, digits, '_', '-' and '.' only")
    mesh_file = package_dir / "meshes" / f"{name}.stl"
    will_collide = collision.strip().lower() != "same"
    collision_file = package_dir / "meshes" / f"{name}_collision.stl" if will_collide else None
    # Refuse before any work, and before writing anything, so a refusal leaves no partial import.
    for target in (mesh_file, collision_file, snippet_file):
        if target is not None:
            check_writable(target, force)
    if mesh.resolve() == mesh_file.resolve():
        raise ReedtoolError("the output would overwrite the input mesh", file=mesh,
                            hint="pass a different --name")

    from reedtool.generate.package_body import find_body_model, package_mass_kg

    body_model = find_body_model(package_dir)
    if set_body and body_model is None:
        raise ReedtoolError("--set-body: no model in DIR/urdf/ declares the body properties "
                            "(mesh_file and body_inertia) new-package writes", file=package_dir,
                            hint="set the body by hand from the snippet, or create the package "
                                 "with `reedtool new-package`")
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


def _vector(v) -> str:
    # Sub-picometre values are round-off, not geometry: show them as 0.
    return "(" + ", ".join(f"{(0.0 if abs(x) < 1e-12 else float(x)) + 0.0:.6g}" for x in v) + ")"


def report_lines(outcome: ImportOutcome) -> list[str]:
    from reedtool.physics.inertia import clean_tensor

    imp = outcome.imported
    topo, props = imp.topology, imp.mass
    size = imp.size_m
    from reedtool.physics.mesh_import import assumption_lines

    lines = [
        f"read {imp.source}: {imp.file_format}, {imp.check.triangles} triangles, "
        f"{topo.vertices} vertices",
        *assumption_lines(imp),
        f"size: {size[0]:.6g} x {size[1]:.6g} x {size[2]:.6g} m (x, y, z in FLU)",
    ]
    if imp.recenter != "none":
        lines.append(f"recentred on the {imp.recenter}: moved by {_vector(imp.offset_m)} m")
    if topo.closed:
        lines.append("watertight: yes (closed and consistently wound)")
    elif topo.watertight:
        lines.append("watertight: yes, but inconsistently wound")
    else:
        lines.append("watertight: NO (open mesh)")
    lines.append(f"volume: {props.volume_m3:.6g} m^3{' (convex hull)' if props.from_hull else ''}")
    default = imp.mass_source.startswith("DEFAULT")
    lines.append(f"mass: {props.mass_kg:.6g} kg ({imp.mass_source}"
                 f"{'; pass --mass or --density' if default else ''})")
    lines.append(f"centre of mass: {_vector(props.com_m)} m")
    I = clean_tensor(props.inertia_kg_m2)
    lines.append(f"inertia about the COM: ixx {I[0, 0]:.6g}, iyy {I[1, 1]:.6g}, izz {I[2, 2]:.6g}, "
                 f"ixy {I[0, 1]:.6g}, ixz {I[0, 2]:.6g}, iyz {I[1, 2]:.6g} kg*m^2")
    lines.extend(f"note: {note}" for note in imp.notes)
    lines.append(f"wrote {outcome.mesh_file} ({imp.check.triangles} triangles, binary, "
                 "metres, FLU)")
    if outcome.collision_file is not None and imp.collision_m is not None:
        lines.append(f"wrote {outcome.collision_file} ({imp.collision.kind}, "
                     f"{len(imp.collision_m)} triangles)")
    edit = outcome.body_edit
    if edit is not None:
        if outcome.body_written:
            lines.append(f"set the body of {edit.file} to this mesh (backup: "
                         f"{outcome.body_backup}):")
        else:
            lines.append(f"to make it the body of {edit.file}, change these lines (or pass "
                         "--set-body to write them, keeping a backup):")
        lines.extend(f"  {line}" for line in edit.lines)
        lines.append("  the rotors stay where the model puts them; `reedtool new-package "
                     "--mesh` places them on the body's motor mounts")
        if outcome.body_written:
            package_dir = edit.file.parent.parent
            lines.append(f"next: reedtool validate {package_dir}   (R342: what the body's COM "
                         "does to the hover trim)")
            lines.append(f"      reedtool hover-test {package_dir}")
    return lines


class _StageBar:
    """Advances a click progress bar one stage at a time."""

    def __init__(self, bar):
        self.bar = bar

    def __call__(self, stage: str) -> None:
        self.bar.label = f"import-stl: {stage}"
        if stage != STAGES[0]:
            self.bar.update(1)


@click.command("import-stl")
@click.argument("mesh", type=click.Path(path_type=Path, dir_okay=False))
@click.option("--package", "package_dir", required=True, metavar="DIR",
              type=click.Path(path_type=Path),
              help="ROS package directory (with package.xml); the mesh goes to DIR/meshes/.")
@click.option("--name", default=None, help="Output name (default: the mesh file's stem).")
@click.option("--units", default="auto", show_default=True,
              type=click.Choice(["auto", "mm", "cm", "m", "in"]),
              help="Units of the STL; auto judges by the size and the mass (density), "
                   "says why, and refuses naming the choices when more than one unit fits.")
@click.option("--from-frame", default="auto", show_default=True, metavar="FRAME",
              help="Axes of the STL: ned, frd, flu, enu, nwu, y-up, z-up, or x/y/z letters "
                   "from f/b, l/r, u/d (e.g. luf). auto: FLU, unless the mesh's extents say "
                   "it stands on another axis (then it is refused, naming the choices).")
@click.option("--mass", "mass_kg", type=float, default=None,
              help="Mass of the part [kg] (into a package new-package wrote: default the "
                   "model's body mass).")
@click.option("--density", "density_kg_m3", type=float, default=None,
              help="Density [kg/m^3] (default 1000 when neither --mass nor --density is given).")
@click.option("--recenter", default="none", show_default=True,
              type=click.Choice(["none", "com", "bbox"]),
              help="Move the mesh origin to its centre of mass or bounding-box centre.")
@click.option("--collision", default="same", show_default=True, metavar="hull|simplify:N|same",
              help="Collision mesh: convex hull, decimated to N faces, or the visual mesh.")
@click.option("--snippet", "snippet_file", type=click.Path(path_type=Path, dir_okay=False),
              default=None, help="Write the URDF/xacro snippet here instead of printing it.")
@click.option("--force", is_flag=True, help="Overwrite existing output files.")
@click.option("--set-body", is_flag=True,
              help="Make the mesh the body of the package's model (a package new-package "
                   "wrote): set mesh_file, body_com_xyz, body_inertia (and mass, with "
                   "--mass or --density) in its xacro file, keeping a numbered backup. "
                   "Without it those lines are printed.")
def command(mesh, package_dir, name, units, from_frame, mass_kg, density_kg_m3, recenter,
            collision, snippet_file, force, set_body=False) -> int:
    """Import a CAD STL into a package: metres, FLU axes, inertia about the COM.

    Writes DIR/meshes/NAME.stl (binary, metres, FLU), optionally NAME_collision.stl, and
    prints the <link> snippet (visual, collision and <inertial>) to paste into a URDF or
    xacro; into a package new-package wrote, also the lines that make the mesh the model's
    body (--set-body writes them). Existing files are never overwritten without --force.
    """
    # Progress is for a person watching a terminal; in a pipe it is one more stderr line.
    big = (sys.stderr.isatty() and mesh.is_file()
           and mesh.stat().st_size >= PROGRESS_MIN_BYTES)
    kwargs = dict(name=name, units=units, from_frame=from_frame, mass_kg=mass_kg,
                  density_kg_m3=density_kg_m3, recenter=recenter, collision=collision,
                  snippet_file=snippet_file, force=force, set_body=set_body)
    if big:
        with click.progressbar(length=len(STAGES) - 1, label="import-stl", file=sys.stderr) as bar:
            outcome = run_import(mesh, package_dir, progress=_StageBar(bar), **kwargs)
            bar.update(1)
    else:
        outcome = run_import(mesh, package_dir, **kwargs)
    for line in report_lines(outcome):
        click.echo(line)
    if snippet_file is not None:
        click.echo(f"wrote {snippet_file} (URDF/xacro snippet)")
    else:
        click.echo("")
        click.echo(outcome.snippet, nl=False)
    return 0
