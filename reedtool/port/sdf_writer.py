"""A `GzPort` (port.gz_port) -> the files of a Gazebo Sim model directory.

    <name>/model.sdf          SDF 1.9: links, joints, folded-link frames, gz systems
    <name>/model.config       name, version, the SDF file
    <name>/meshes/...         every mesh file of the model's packages, copied; URIs
                              relative (a file from outside them is referenced where it
                              is, unless --copy-outside-files)
    <name>/worlds/<name>.sdf  physics, the world systems the model needs, the model included

Numbers the port computes (poses, folded inertials) are written with the shortest text
that reads back as the same float, so reading the port gives the original numbers.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path, PurePosixPath

import numpy as np
from lxml import etree

from reedtool.io.limits import sdf_limit_text
from reedtool.io.sdf_write import (
    SDF_VERSION,
    geometry_element,
    ground_plane_element,
    inertial_element,
    physics_element,
    pose_text,
    sdf_bytes,
    sub,
    sun_element,
)
from reedtool.io.xml_numbers import float_text
from reedtool.port.gz_port import Element, GzPort, PortRow


@dataclass
class WrittenFile:
    path: PurePosixPath            # relative to the output directory
    data: bytes


@dataclass
class PortFiles:
    files: list[WrittenFile]
    lines: dict            # id(Element) or ('link' | 'joint', name) -> its line in model.sdf


def to_xml(element: Element, parent=None):
    """The lxml tree of a port `Element` (under `parent` when given), for both writers."""
    node = etree.Element(element.tag, element.attrib) if parent is None else \
        etree.SubElement(parent, element.tag, element.attrib)
    node.text = element.text
    for child in element.children:
        to_xml(child, node)
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
    inertial_element(parent, mass, T_link_com, inertia)


def _reference_in_place(uri: str, path: Path, target_dir) -> str:
    """A file left where it is, named as the source named it: an absolute reference stays
    an absolute file:// URI, a relative one the same file relative to the new model
    directory (so validate sees the same kind of reference on both sides)."""
    import os

    real = path.resolve()
    if target_dir is None or uri.strip().startswith(("file://", "/")):
        return real.as_uri()
    return PurePosixPath(os.path.relpath(real, Path(target_dir).absolute())).as_posix()


def mesh_targets(port: GzPort) -> dict[str, str]:
    """Source mesh URI -> the relative URI in the port (meshes/<file>, names made unique);
    a file from outside the model's packages keeps its place (an absolute file:// URI)
    unless the user asked to copy it (--copy-outside-files)."""
    out: dict[str, str] = {}
    used: set[str] = set()
    for uri, mesh in port.meshes.items():
        if uri in port.outside_files and not port.copy_outside_files:
            out[uri] = _reference_in_place(uri, Path(mesh.path), port.target_dir)
            continue
        base = PurePosixPath(uri.split("://", 1)[-1]).name or "mesh"
        name, index = base, 1
        while name in used:
            stem, dot, suffix = base.partition(".")
            name = f"{stem}_{index}{dot}{suffix}"
            index += 1
        used.add(name)
        out[uri] = f"meshes/{name}"
    return out


SCOPE = "::"


def scope_of(name: str) -> str:
    """The nested model a scoped name lives in ("" for the top model): `gps0::link` ->
    `gps0`. SDF 1.8+ refuses `::` in a name, so the port writes scopes as nested models."""
    return name.rpartition(SCOPE)[0]


def local_name(name: str, scope: str) -> str:
    """`name` as written inside `scope` (a reference into a nested model keeps its `::`)."""
    return name[len(scope) + len(SCOPE):] if scope and name.startswith(scope + SCOPE) else name


def flat_name(name: str) -> str:
    """A name without `::` for an element that cannot live in its nested model."""
    return name.replace(SCOPE, "__")


def _within(name: str, scope: str) -> bool:
    return not scope or name.startswith(scope + SCOPE)


def _common_scope(a: str, b: str) -> str:
    parts = []
    for x, y in zip(scope_of(a).split(SCOPE), scope_of(b).split(SCOPE)):
        if x != y or not x:
            break
        parts.append(x)
    return SCOPE.join(parts)


class _Scopes:
    """The top <model> and the nested <model>s the port's scoped names need, each posed
    in its parent model at the first link written in it."""

    def __init__(self, model, T_model_link: dict[str, np.ndarray]):
        self.nodes = {"": model}
        self.T_model_scope = {"": np.eye(4)}
        self.T_model_link = T_model_link

    def node(self, scope: str, T_model_first: np.ndarray):
        if scope not in self.nodes:
            parent = scope_of(scope)
            parent_node = self.node(parent, T_model_first)
            node = sub(parent_node, "model", name=local_name(scope, parent))
            T_parent_scope = np.linalg.inv(self.T_model_scope[parent]) @ T_model_first
            if not np.array_equal(T_parent_scope, np.eye(4)):
                sub(node, "pose", pose_text(T_parent_scope))
            self.nodes[scope] = node
            self.T_model_scope[scope] = T_model_first
        return self.nodes[scope]

    def pose_in_scope(self, scope: str, name: str) -> np.ndarray:
        return np.linalg.inv(self.T_model_scope[scope]) @ self.T_model_link[name]


# Plugin parameters that name a joint or link of the plugin's own model (io.sdf reads a
# nested model's plugin with them scoped).
_SCOPED_PARAMS = ("jointName", "linkName", "joint_name", "link_name", "bodyName", "body_name")


def _named(element: Element):
    for child in element.children:
        if child.tag in _SCOPED_PARAMS and child.text and child.text.strip():
            yield child
        yield from _named(child)


def _plugin_scope(plugin: Element, nested: dict) -> str:
    """The nested model a plugin belongs in: the deepest one written that holds every
    joint and link it names (gz-sim's systems look names up in their own model only:
    PX4 Classic's iris_* variants include the iris, motor plugins and all)."""
    names = [child.text.strip() for child in _named(plugin)]
    if not names:
        return ""
    scopes = [scope for scope in nested if scope and all(n.startswith(scope + SCOPE)
                                                         for n in names)]
    return max(scopes, key=len, default="")


def _unscoped(plugin: Element, scope: str) -> Element:
    """A copy of `plugin` whose joint and link names are written inside `scope`."""
    import copy

    out = copy.deepcopy(plugin)
    for child in _named(out):
        child.text = local_name(child.text.strip(), scope)
    return out


def _link_poses(port: GzPort) -> dict[str, np.ndarray]:
    """T_model_link of every port link (links are listed parents first)."""
    out: dict[str, np.ndarray] = {}
    for link in port.links:
        out[link.name] = np.eye(4) if link.parent is None else \
            out[link.parent] @ link.T_parent_link
    return out


def model_sdf(port: GzPort, source: str, mesh_uris: dict[str, str],
              extra_plugins: list[Element] = ()) -> tuple[bytes, dict[int, int]]:
    """model.sdf, and the line of every Element written (by id) for the report.

    A scoped name (`gps0::link`, from an included or nested model of the source) is
    written as a nested <model name="gps0"> holding <link name="link">; joints and
    references outside it name it `gps0::link`, as SDF 1.8+ allows. No name is written
    with `::` (libsdformat refuses it from SDF 1.8 on)."""
    root = etree.Element("sdf", version=SDF_VERSION)
    root.append(etree.Comment(f" {port.name}: ported from {source} by reedtool migrate. "
                              "Constants as the source wrote them; see the migrate report. "))
    model = sub(root, "model", name=port.name)
    T_model_link = _link_poses(port)
    scopes = _Scopes(model, T_model_link)
    written: list[tuple[Element, object]] = []
    nodes: dict[tuple[str, str], object] = {}
    for link in port.links:
        scope = scope_of(link.name)
        parent_node = scopes.node(scope, T_model_link[link.name])
        node = sub(parent_node, "link", name=local_name(link.name, scope))
        nodes[("link", link.name)] = node
        if link.parent is not None and scope_of(link.parent) == scope:
            sub(node, "pose", pose_text(link.T_parent_link),
                 relative_to=local_name(link.parent, scope))
        elif link.parent is not None or scope:
            T = scopes.pose_in_scope(scope, link.name)
            if not np.array_equal(T, np.eye(4)):
                sub(node, "pose", pose_text(T))
        _inertial(node, link.inertials)
        for kind, shapes in (("collision", link.collisions), ("visual", link.visuals)):
            names: set[str] = set()
            for index, (T_link_geom, shape) in enumerate(shapes):
                if shape.geometry is None:
                    continue
                name = shape.name if shape.name and shape.name not in names else f"{kind}_{index}"
                name = flat_name(name)
                names.add(name)
                element = sub(node, kind, name=name)
                if not np.array_equal(T_link_geom, np.eye(4)):
                    sub(element, "pose", pose_text(T_link_geom))
                geometry_element(element, shape.geometry, lambda mesh: mesh_uris[mesh.uri])
        for sensor in link.sensors:
            written.append((sensor, to_xml(sensor, node)))
    for frame in port.frames:
        # A frame lives in its own nested model when that model is written and holds the
        # link it is attached to; else in the link's scope under a flat name.
        scope = scope_of(frame.name)
        if scope not in scopes.nodes or not _within(frame.attached_to, scope):
            scope = scope_of(frame.attached_to)
            name = flat_name(frame.name)
        else:
            name = local_name(frame.name, scope)
        attached = local_name(frame.attached_to, scope)
        node = sub(scopes.nodes[scope], "frame", name=name, attached_to=attached)
        sub(node, "pose", pose_text(frame.T_link_frame), relative_to=attached)
    for joint in port.joints:
        scope = scope_of(joint.name)
        if scope in scopes.nodes and _within(joint.parent, scope) and _within(joint.child, scope):
            name = local_name(joint.name, scope)
        else:
            scope = _common_scope(joint.parent, joint.child)
            name = flat_name(local_name(joint.name, scope))
        sdf_type = {"continuous": "revolute"}.get(joint.type, joint.type)
        node = sub(scopes.nodes[scope], "joint", name=name, type=sdf_type)
        nodes[("joint", joint.name)] = node
        sub(node, "parent", local_name(joint.parent, scope))
        sub(node, "child", local_name(joint.child, scope))
        child = local_name(joint.child, scope)
        moved = joint.T_child_jointframe is not None and \
            not np.array_equal(joint.T_child_jointframe, np.eye(4))
        if moved:
            # The joint frame where the source put it (the axis line passes there); the
            # axis stays in the child link frame, as the plan holds it.
            sub(node, "pose", pose_text(joint.T_child_jointframe), relative_to=child)
        if joint.type != "fixed":
            axis = sub(node, "axis")
            sub(axis, "xyz", " ".join(float_text(v) for v in joint.axis),
                 **({"expressed_in": child} if moved else {}))
            limit = sub(axis, "limit")
            values = (None, None, None, None) if joint.limit is None else joint.limit
            if joint.type == "continuous":      # no position limit; effort/velocity kept
                values = (None, None, *values[2:])
            for tag, value in zip(("lower", "upper", "effort", "velocity"), values):
                text = sdf_limit_text(tag, value)
                if text is not None:
                    sub(limit, tag, text)
    for plugin in [*port.plugins, *extra_plugins]:
        scope = _plugin_scope(plugin, scopes.nodes)
        written.append((plugin, to_xml(_unscoped(plugin, scope) if scope else plugin,
                                        scopes.nodes[scope])))
    scoped = [el.get("name") for el in root.iter() if isinstance(el.tag, str)
              and el.tag != "plugin" and SCOPE in (el.get("name") or "")]
    if scoped:
        # libsdformat refuses these from SDF 1.8 on: never write a port Gazebo will not load.
        raise RuntimeError(f"the port would name an element {scoped[0]!r}: a reedtool bug")
    data = sdf_bytes(root)
    reread = etree.fromstring(data)
    tree = root.getroottree()
    lines = {id(element): reread.xpath(tree.getpath(node))[0].sourceline
             for element, node in written}
    for key, node in nodes.items():
        lines[key] = reread.xpath(tree.getpath(node))[0].sourceline
    return data, lines


def model_config(port: GzPort, source: str) -> bytes:
    root = etree.Element("model")
    sub(root, "name", port.name)
    sub(root, "version", "1.0")
    sub(root, "sdf", "model.sdf", version=SDF_VERSION)
    sub(root, "description", f"{port.name}, ported from {source} by reedtool migrate.")
    return sdf_bytes(root)


def world_sdf(port: GzPort) -> bytes:
    """A world with the systems the model needs and the model included (model://<name>:
    put the output directory on GZ_SIM_RESOURCE_PATH)."""
    root = etree.Element("sdf", version=SDF_VERSION)
    world = sub(root, "world", name=f"{port.name}_world")
    physics_element(world)
    sub(world, "gravity", "0 0 -9.80665")
    for filename, name in port.world_systems:
        sub(world, "plugin", filename=filename, name=name)
    if any(sensor.attrib.get("type") == "navsat" for link in port.links
           for sensor in link.sensors):
        # gz-sim's NavSat system publishes nothing without it.
        from reedtool.port.gz_port import DEFAULT_HOME

        latitude, longitude, elevation = port.home or DEFAULT_HOME
        where = sub(world, "spherical_coordinates")
        sub(where, "surface_model", "EARTH_WGS84")
        sub(where, "world_frame_orientation", "ENU")
        sub(where, "latitude_deg", float_text(latitude))
        sub(where, "longitude_deg", float_text(longitude))
        sub(where, "elevation", float_text(elevation))
        sub(where, "heading_deg", "0")
    sun_element(world)
    ground_plane_element(world)
    include = sub(world, "include")
    sub(include, "uri", f"model://{port.name}")
    sub(include, "pose", "0 0 0.3 0 0 0")
    return sdf_bytes(root)


def port_files(port: GzPort, source: str, extra_plugins: list[Element] = (),
               extra_files: list[WrittenFile] = ()) -> tuple[PortFiles, list[PortRow]]:
    """Every file of the model directory (paths relative to it), the mesh rows, and the
    model.sdf line of every element written."""
    from reedtool.io.fileio import read_bytes

    uris = mesh_targets(port)
    rows: list[PortRow] = []
    files = []
    for uri, mesh in port.meshes.items():
        outside = port.outside_files.get(uri)
        if outside is not None and not port.copy_outside_files:
            rows.append(PortRow(_mesh_loc(port, uri), f"mesh {uri}", "mapped", uris[uri],
                                f"not copied: {outside}; referenced where it is (this "
                                "machine only); pass --copy-outside-files to copy it into "
                                "the port"))
            continue
        if mesh.path is not None and Path(mesh.path).is_file():
            files.append(WrittenFile(PurePosixPath(uris[uri]),
                                     read_bytes(Path(mesh.path), what="mesh", max_bytes=None)))
            rows.append(PortRow(_mesh_loc(port, uri), f"mesh {uri}", "mapped", uris[uri],
                                "copied; referenced relative to model.sdf" + (
                                    f" (--copy-outside-files: {outside})" if outside else "")))
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
        node = to_xml(element)
        etree.indent(node, space="  ", level=indent // 2)
        out.append(" " * indent + etree.tostring(node, encoding="unicode").rstrip())
    return "\n".join(out)
