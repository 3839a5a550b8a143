"""`import-stl`'s output: the <link> snippet (visual, collision, <inertial>) to paste
into a URDF or xacro, and the report of what was read, assumed, computed and written.
Formats workflows.import_mesh's outcome; computes nothing."""

from __future__ import annotations


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


def _vector(v) -> str:
    # Sub-picometre values are round-off, not geometry: show them as 0.
    return "(" + ", ".join(f"{(0.0 if abs(x) < 1e-12 else float(x)) + 0.0:.6g}" for x in v) + ")"


def report_lines(outcome) -> list[str]:
    from reedtool.io.xml_numbers import clean_tensor

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
