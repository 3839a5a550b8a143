"""A `GzPort` (scaffold.gz_port) -> the files of a Gazebo Sim model directory.

    <name>/model.sdf          SDF 1.9: links, joints, folded-link frames, gz systems
    <name>/model.config       name, version, the SDF file
    <name>/meshes/...         every mesh file the model uses, copied; URIs relative
    <name>/worlds/<name>.sdf  physics, the world systems the model needs, the model included

Numbers the port computes (poses, folded inertials) are written with the shortest text
that reads back as the same float, so reading the port gives the original numbers.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path, PurePosixPath

import numpy as np
from lxml import etree

from reedtool.scaffold.gz_port import Element, GzPort, PortRow, _num, _pose_text

SDF_VERSION = "1.9"
# sdformat's "no limit" for a revolute joint (how sdformat writes a URDF continuous joint,
# and what PX4's gz models use for rotor joints).
UNBOUNDED = "1e+16"


@dataclass
class WrittenFile:
    path: PurePosixPath            # relative to the output directory
    data: bytes


@dataclass
class PortFiles:
    files: list[WrittenFile]
    lines: dict            # id(Element) or ('link' | 'joint', name) -> its line in model.sdf


def _to_xml(element: Element, parent=None):
    node = etree.Element(element.tag, element.attrib) if parent is None else \
        etree.SubElement(parent, element.tag, element.attrib)
    node.text = element.text
    for child in element.children:
        _to_xml(child, node)
    return node


def _sub(parent, tag: str, text: object | None = None, **attrib: str):
    node = etree.SubElement(parent, tag, attrib)
    if text is not None:
        node.text = str(text)
    return node


def _inertial(parent, inertials) -> None:
    """One <inertial>: the part as written, or the folded parts combined about their COM."""
    from reedtool.physics.inertia import combine_inertials

    if not inertials:
        return
    if len(inertials) == 1:
        T_link_part, inertial = inertials[0]
        T_link_com = T_link_part @ inertial.T_link_com
        inertia = inertial.inertia_kg_m2
        mass = inertial.mass_kg
    else:
        total = combine_inertials(inertials)
        T_link_com = np.eye(4)
        T_link_com[:3, 3] = total.com_m
        inertia, mass = total.inertia_kg_m2, total.mass_kg
    node = _sub(parent, "inertial")
    _sub(node, "pose", _pose_text(T_link_com))
    _sub(node, "mass", _num(mass))
    tensor = _sub(node, "inertia")
    for key, (i, j) in (("ixx", (0, 0)), ("ixy", (0, 1)), ("ixz", (0, 2)), ("iyy", (1, 1)),
                        ("iyz", (1, 2)), ("izz", (2, 2))):
        _sub(tensor, key, _num(inertia[i, j]))


def _geometry(parent, geometry, mesh_uris: dict[str, str]) -> None:
    from reedtool.model import Box, Cylinder, Mesh, Sphere

    node = _sub(parent, "geometry")
    if isinstance(geometry, Box):
        _sub(_sub(node, "box"), "size", " ".join(_num(v) for v in geometry.size_m))
    elif isinstance(geometry, Cylinder):
        cylinder = _sub(node, "cylinder")
        _sub(cylinder, "radius", _num(geometry.radius_m))
        _sub(cylinder, "length", _num(geometry.length_m))
    elif isinstance(geometry, Sphere):
        _sub(_sub(node, "sphere"), "radius", _num(geometry.radius_m))
    elif isinstance(geometry, Mesh):
        mesh = _sub(node, "mesh")
        _sub(mesh, "uri", mesh_uris[geometry.uri])
        if not np.array_equal(geometry.scale, np.ones(3)):
            _sub(mesh, "scale", " ".join(_num(v) for v in geometry.scale))


def mesh_targets(port: GzPort) -> dict[str, str]:
    """Source mesh URI -> the relative URI in the port (meshes/<file>, names made unique)."""
    out: dict[str, str] = {}
    used: set[str] = set()
    for uri, mesh in port.meshes.items():
        base = PurePosixPath(uri.split("://", 1)[-1]).name or "mesh"
        name, index = base, 1
        while name in used:
            stem, dot, suffix = base.partition(".")
            name = f"{stem}_{index}{dot}{suffix}"
            index += 1
        used.add(name)
        out[uri] = f"meshes/{name}"
    return out


def model_sdf(port: GzPort, source: str, mesh_uris: dict[str, str],
              extra_plugins: list[Element] = ()) -> tuple[bytes, dict[int, int]]:
    """model.sdf, and the line of every Element written (by id) for the report."""
    root = etree.Element("sdf", version=SDF_VERSION)
    root.append(etree.Comment(f" {port.name}: ported from {source} by reedtool migrate. "
                              "Constants as the source wrote them; see the migrate report. "))
    model = _sub(root, "model", name=port.name)
    written: list[tuple[Element, object]] = []
    for link in port.links:
        node = _sub(model, "link", name=link.name)
        if link.parent is not None:
            _sub(node, "pose", _pose_text(link.T_parent_link), relative_to=link.parent)
        _inertial(node, link.inertials)
        for kind, shapes in (("collision", link.collisions), ("visual", link.visuals)):
            names: set[str] = set()
            for index, (T_link_geom, shape) in enumerate(shapes):
                if shape.geometry is None:
                    continue
                name = shape.name if shape.name and shape.name not in names else f"{kind}_{index}"
                names.add(name)
                element = _sub(node, kind, name=name)
                if not np.array_equal(T_link_geom, np.eye(4)):
                    _sub(element, "pose", _pose_text(T_link_geom))
                _geometry(element, shape.geometry, mesh_uris)
        for sensor in link.sensors:
            written.append((sensor, _to_xml(sensor, node)))
    for frame in port.frames:
        node = _sub(model, "frame", name=frame.name, attached_to=frame.attached_to)
        _sub(node, "pose", _pose_text(frame.T_link_frame), relative_to=frame.attached_to)
    for joint in port.joints:
        sdf_type = {"continuous": "revolute"}.get(joint.type, joint.type)
        node = _sub(model, "joint", name=joint.name, type=sdf_type)
        _sub(node, "parent", joint.parent)
        _sub(node, "child", joint.child)
        if joint.type != "fixed":
            axis = _sub(node, "axis")
            _sub(axis, "xyz", " ".join(_num(v) for v in joint.axis))
            limit = _sub(axis, "limit")
            if joint.type == "continuous" or joint.limit is None:
                _sub(limit, "lower", "-" + UNBOUNDED)
                _sub(limit, "upper", UNBOUNDED)
            else:
                lower, upper, effort, velocity = joint.limit
                for tag, value in (("lower", lower), ("upper", upper), ("effort", effort),
                                   ("velocity", velocity)):
                    if value is not None:
                        _sub(limit, tag, _num(value))
    for plugin in [*port.plugins, *extra_plugins]:
        written.append((plugin, _to_xml(plugin, model)))
    etree.indent(root, space="  ")
    data = etree.tostring(root, xml_declaration=True, encoding="utf-8", pretty_print=True)
    reread = etree.fromstring(data)
    tree = root.getroottree()
    lines = {id(element): reread.xpath(tree.getpath(node))[0].sourceline
             for element, node in written}
    for kind in ("link", "joint"):
        for node in reread.iterfind(f"./model/{kind}"):
            lines[(kind, node.get("name"))] = node.sourceline
    return data, lines


def model_config(port: GzPort, source: str) -> bytes:
    root = etree.Element("model")
    _sub(root, "name", port.name)
    _sub(root, "version", "1.0")
    _sub(root, "sdf", "model.sdf", version=SDF_VERSION)
    _sub(root, "description", f"{port.name}, ported from {source} by reedtool migrate.")
    etree.indent(root, space="  ")
    return etree.tostring(root, xml_declaration=True, encoding="utf-8", pretty_print=True)


def world_sdf(port: GzPort) -> bytes:
    """A world with the systems the model needs and the model included (model://<name>:
    put the output directory on GZ_SIM_RESOURCE_PATH)."""
    root = etree.Element("sdf", version=SDF_VERSION)
    world = _sub(root, "world", name=f"{port.name}_world")
    physics = _sub(world, "physics", name="4ms", type="ignored")
    # 4 ms steps, as gz-sim's own multicopter examples use with these motor models.
    _sub(physics, "max_step_size", "0.004")
    _sub(physics, "real_time_factor", "1.0")
    _sub(world, "gravity", "0 0 -9.80665")
    for filename, name in port.world_systems:
        _sub(world, "plugin", filename=filename, name=name)
    light = _sub(world, "light", type="directional", name="sun")
    _sub(light, "cast_shadows", "true")
    _sub(light, "pose", "0 0 10 0 0 0")
    _sub(light, "diffuse", "0.8 0.8 0.8 1")
    _sub(light, "direction", "-0.5 0.1 -0.9")
    ground = _sub(world, "model", name="ground_plane")
    _sub(ground, "static", "true")
    link = _sub(ground, "link", name="link")
    for kind in ("collision", "visual"):
        plane = _sub(_sub(_sub(link, kind, name=kind), "geometry"), "plane")
        _sub(plane, "normal", "0 0 1")
        _sub(plane, "size", "100 100")
    include = _sub(world, "include")
    _sub(include, "uri", f"model://{port.name}")
    _sub(include, "pose", "0 0 0.3 0 0 0")
    etree.indent(root, space="  ")
    return etree.tostring(root, xml_declaration=True, encoding="utf-8", pretty_print=True)


def port_files(port: GzPort, source: str, extra_plugins: list[Element] = (),
               extra_files: list[WrittenFile] = ()) -> tuple[PortFiles, list[PortRow]]:
    """Every file of the model directory (paths relative to it), the mesh rows, and the
    model.sdf line of every element written."""
    from reedtool.io.fileio import read_bytes

    uris = mesh_targets(port)
    rows: list[PortRow] = []
    files = []
    for uri, mesh in port.meshes.items():
        if mesh.path is not None and Path(mesh.path).is_file():
            files.append(WrittenFile(PurePosixPath(uris[uri]),
                                     read_bytes(Path(mesh.path), what="mesh", max_bytes=None)))
            rows.append(PortRow(_mesh_loc(port, uri), f"mesh {uri}", "mapped", uris[uri],
                                "copied; referenced relative to model.sdf"))
        else:
            rows.append(PortRow(_mesh_loc(port, uri), f"mesh {uri}", "dropped", uris[uri],
                                f"not found ({mesh.resolve_error or 'no file'}): referenced "
                                f"as {uris[uri]} but not copied; put the file there"))
    sdf, lines = model_sdf(port, source, uris, list(extra_plugins))
    files += [WrittenFile(PurePosixPath("model.sdf"), sdf),
              WrittenFile(PurePosixPath("model.config"), model_config(port, source)),
              WrittenFile(PurePosixPath("worlds", f"{port.name}.sdf"), world_sdf(port)),
              *extra_files]
    return PortFiles(files, lines), rows


def _mesh_loc(port: GzPort, uri: str):
    for link in port.links:
        for _T, shape in [*link.visuals, *link.collisions]:
            if getattr(shape.geometry, "uri", None) == uri:
                return shape.loc
    return port.links[0].loc


def elements_text(elements: list[Element], indent: int = 0) -> str:
    """Elements as indented XML text (for a template to place inside a <gazebo> block)."""
    out = []
    for element in elements:
        node = _to_xml(element)
        etree.indent(node, space="  ", level=indent // 2)
        out.append(" " * indent + etree.tostring(node, encoding="unicode").rstrip())
    return "\n".join(out)
