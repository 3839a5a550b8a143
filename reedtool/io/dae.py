"""COLLADA (.dae), read far enough for extents, units and triangles: lxml + numpy only.

What Gazebo's COLLADA loader does with a file, reedtool does here: positions of every
`<geometry>` placed by the `<visual_scene>` nodes that instance it (`<matrix>`,
`<translate>`, `<rotate>`, `<scale>`, nested nodes, `<instance_node>`), the `<up_axis>`
turned to Z up, and the `<asset><unit meter=>` applied (Gazebo scales by it: a file
exported in millimetres with meter="0.001" is the right size). Materials, normals,
texture coordinates, animation and skinning are not read.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from reedtool.errors import ReedtoolError

HINT = "export it again as COLLADA (.dae) or STL"


@dataclass
class DaeFile:
    triangles: np.ndarray           # (n, 3, 3) in the file's units, scene transforms applied
    metres_per_unit: float          # <asset><unit meter=>; 1.0 when not declared
    unit_declared: bool
    up_axis: str                    # X_UP | Y_UP | Z_UP
    notes: list[str] = field(default_factory=list)

    @property
    def triangles_m(self) -> np.ndarray:
        return self.triangles * self.metres_per_unit


def _local(tag) -> str:
    return tag.rsplit("}", 1)[-1] if isinstance(tag, str) else ""


def _children(node, name: str):
    return [c for c in node if _local(c.tag) == name]


def _first(node, name: str):
    for c in node:
        if _local(c.tag) == name:
            return c
    return None


def _parse_numbers(text: str, dtype) -> np.ndarray:
    """Whitespace-separated numbers, parsed by numpy in C (a mesh's index and position
    arrays are most of a COLLADA file: 10^5 numbers each). What numpy's fast parser does
    not take whole (a bad token, `nan`, an overflow) is parsed word by word as before, so
    the result and the refusal of a bad number do not depend on the path taken."""
    if not text.strip():
        return np.zeros(0, dtype=dtype)       # numpy reads blank text as one number
    import warnings

    try:
        with warnings.catch_warnings():
            # numpy < 2.3 warns where later versions raise on text it cannot read whole.
            warnings.simplefilter("error", DeprecationWarning)
            return np.fromstring(text, dtype=dtype, sep=" ")
    except (ValueError, DeprecationWarning):
        return np.array(text.split(), dtype=dtype)


def _numbers(node, source, dtype, what: str) -> np.ndarray:
    """The element's numbers; a text that is not numbers is one error naming its line."""
    try:
        return _parse_numbers(node.text or "", dtype)
    except ValueError as exc:
        raise ReedtoolError(f"bad {what} in <{_local(node.tag)}>", file=source,
                            line=node.sourceline, hint=HINT) from exc


def _floats(node, source) -> np.ndarray:
    return _numbers(node, source, np.float64, "number")


def _ints(node, source) -> np.ndarray:
    return _numbers(node, source, np.int64, "index")


_IDENTITY = np.eye(4)


def _transformed(triangles: np.ndarray, R: np.ndarray, t=None) -> np.ndarray:
    """(n, 3, 3) corners rotated (and moved): one (3n x 3) product, not n small ones."""
    out = (triangles.reshape(-1, 3) @ R.T).reshape(triangles.shape)
    return out + t if t is not None else out

# Gazebo works Z up; a Y-up (or X-up) file is turned so its up axis becomes +Z.
_UP_AXIS_ROTATION = {
    "Z_UP": np.eye(3),
    "Y_UP": np.array([[1.0, 0, 0], [0, 0, -1], [0, 1, 0]]),     # +90 deg about x: y -> z
    "X_UP": np.array([[0, -1.0, 0], [1, 0, 0], [0, 0, 1]]),     # +90 deg about z: x -> y
}


def _rotation(axis, angle_deg: float) -> np.ndarray:
    axis = np.asarray(axis, dtype=float)
    norm = float(np.linalg.norm(axis))
    if norm == 0.0:
        return np.eye(3)
    x, y, z = axis / norm
    c, s = math.cos(math.radians(angle_deg)), math.sin(math.radians(angle_deg))
    C = 1 - c
    return np.array([[c + x * x * C, x * y * C - z * s, x * z * C + y * s],
                     [y * x * C + z * s, c + y * y * C, y * z * C - x * s],
                     [z * x * C - y * s, z * y * C + x * s, c + z * z * C]])


def _node_transform(node, source) -> np.ndarray:
    """The node's local 4x4 transform: its transform elements composed in document order."""
    T = np.eye(4)
    for child in node:
        kind = _local(child.tag)
        if kind not in ("matrix", "translate", "rotate", "scale"):
            continue
        values = _floats(child, source)
        step = np.eye(4)
        if kind == "matrix" and values.size == 16:
            step = values.reshape(4, 4)
        elif kind == "translate" and values.size == 3:
            step[:3, 3] = values
        elif kind == "rotate" and values.size == 4:
            step[:3, :3] = _rotation(values[:3], values[3])
        elif kind == "scale" and values.size == 3:
            step[:3, :3] = np.diag(values)
        else:
            raise ReedtoolError(f"<{kind}> has {values.size} numbers", file=source,
                                line=child.sourceline, hint=HINT)
        T = T @ step
    return T


def _geometry_triangles(geometry, source) -> np.ndarray:
    """Triangles of one <geometry><mesh> in its own frame (fan-triangulated polygons)."""
    mesh = _first(geometry, "mesh")
    if mesh is None:
        return np.zeros((0, 3, 3))
    # Only the positions are read: normals and texture coordinates are as large again and
    # nothing here needs them, so a <source> is parsed when a primitive uses it.
    source_nodes = {src.get("id"): src for src in _children(mesh, "source")
                    if _first(src, "float_array") is not None}
    parsed: dict[str, np.ndarray] = {}

    def positions_of(ref: str) -> np.ndarray | None:
        if ref not in parsed:
            src = source_nodes.get(ref)
            if src is None:
                return None
            values = _floats(_first(src, "float_array"), source)
            stride = 3
            accessor = src.find(".//{*}accessor")
            if accessor is not None and accessor.get("stride", "").isdigit():
                stride = max(int(accessor.get("stride")), 3)
            usable = values.size - values.size % stride
            parsed[ref] = values[:usable].reshape(-1, stride)[:, :3]
        return parsed[ref]
    vertices = {}
    for v in _children(mesh, "vertices"):
        for inp in _children(v, "input"):
            if inp.get("semantic") == "POSITION":
                vertices[v.get("id")] = (inp.get("source") or "").lstrip("#")
    parts = []
    for prim in mesh:
        kind = _local(prim.tag)
        if kind not in ("triangles", "polylist", "polygons"):
            continue
        inputs = _children(prim, "input")
        stride = 1 + max((int(i.get("offset", "0")) for i in inputs), default=0)
        vertex_input = next((i for i in inputs if i.get("semantic") == "VERTEX"), None)
        if vertex_input is None:
            continue
        ref = (vertex_input.get("source") or "").lstrip("#")
        positions = positions_of(vertices.get(ref, ref))
        if positions is None:
            raise ReedtoolError(f"<{kind}> refers to positions '#{ref}' the file does not hold",
                                file=source, line=prim.sourceline, hint=HINT)
        offset = int(vertex_input.get("offset", "0"))
        polygons: list[np.ndarray] = []
        if kind == "polygons":
            polygons = [_ints(p, source).reshape(-1, stride)[:, offset]
                        for p in _children(prim, "p")]
        else:
            p = _first(prim, "p")
            if p is None:
                continue
            indices = _ints(p, source)
            if indices.size % stride:
                raise ReedtoolError(f"<{kind}> index list is not a multiple of {stride}",
                                    file=source, line=p.sourceline, hint=HINT)
            corner = indices.reshape(-1, stride)[:, offset]
            if kind == "triangles":
                if corner.size % 3:
                    raise ReedtoolError("<triangles> index count is not a multiple of 3",
                                        file=source, line=p.sourceline, hint=HINT)
                polygons = [corner.reshape(-1, 3)]
            else:
                vcount_node = _first(prim, "vcount")
                counts = _ints(vcount_node, source) if vcount_node is not None else np.array([])
                if int(counts.sum()) != corner.size:
                    raise ReedtoolError("<polylist> vcount does not match its index list",
                                        file=source, line=prim.sourceline, hint=HINT)
                polygons = np.split(corner, np.cumsum(counts)[:-1]) if counts.size else []
        for polygon in polygons:
            polygon = np.asarray(polygon)
            if polygon.ndim == 2:                      # already (n, 3) triangles
                faces = polygon
            elif polygon.size >= 3:                   # fan: (0, i, i + 1)
                faces = np.column_stack([np.full(polygon.size - 2, polygon[0]),
                                         polygon[1:-1], polygon[2:]])
            else:
                continue
            if faces.size and (faces.min() < 0 or faces.max() >= len(positions)):
                raise ReedtoolError(f"<{kind}> index {int(faces.max())} is outside the "
                                    f"{len(positions)} positions", file=source,
                                    line=prim.sourceline, hint=HINT)
            parts.append(positions[faces])
    return np.concatenate(parts) if parts else np.zeros((0, 3, 3))


def parse_dae(data: bytes, source: str | Path = "<dae>") -> DaeFile:
    from lxml import etree

    try:
        root = etree.fromstring(data, etree.XMLParser(resolve_entities=False, no_network=True,
                                                      huge_tree=True))
    except etree.XMLSyntaxError as exc:
        # assimp reads COLLADA with its own lenient XML reader: what TinyXML2 accepts
        # (reedtool.io.tolerant_xml) is read too, silently, as Gazebo's loader does.
        try:
            text = data.decode("utf-8")
        except UnicodeDecodeError:
            raise ReedtoolError(f"not a COLLADA file: {exc.msg}", file=source,
                                line=exc.lineno or None, hint=HINT) from exc
        from reedtool.io.tolerant_xml import parse_tolerant

        root, _tolerated = parse_tolerant(text, source, error="not a COLLADA file", hint=HINT)
    if _local(root.tag) != "COLLADA":
        raise ReedtoolError(f"not a COLLADA file: the root element is <{_local(root.tag)}>",
                            file=source, line=root.sourceline, hint=HINT)
    asset = _first(root, "asset")
    unit_node = _first(asset, "unit") if asset is not None else None
    metres, declared = 1.0, False
    if unit_node is not None and unit_node.get("meter") is not None:
        try:
            metres, declared = float(unit_node.get("meter")), True
        except ValueError as exc:
            raise ReedtoolError(f"<unit meter=\"{unit_node.get('meter')}\"> is not a number",
                                file=source, line=unit_node.sourceline, hint=HINT) from exc
        if not (math.isfinite(metres) and metres > 0):
            raise ReedtoolError(f"<unit meter=\"{unit_node.get('meter')}\"> is not positive",
                                file=source, line=unit_node.sourceline, hint=HINT)
    up_node = _first(asset, "up_axis") if asset is not None else None
    up_axis = (up_node.text or "").strip().upper() if up_node is not None else "Y_UP"
    R_up = _UP_AXIS_ROTATION.get(up_axis, np.eye(3))

    geometries = {g.get("id"): g for g in root.iter("{*}geometry")}
    library_nodes = {n.get("id"): n for lib in root.iter("{*}library_nodes")
                     for n in lib.iter("{*}node") if n.get("id")}
    cache: dict[str, np.ndarray] = {}

    def geometry(ref: str) -> np.ndarray:
        if ref not in cache:
            node = geometries.get(ref)
            cache[ref] = (_geometry_triangles(node, source) if node is not None
                          else np.zeros((0, 3, 3)))
        return cache[ref]

    placed: list[np.ndarray] = []

    def walk(node, T_parent: np.ndarray, depth: int) -> None:
        if depth > 64:
            raise ReedtoolError("COLLADA node nesting deeper than 64 (a cycle?)", file=source,
                                line=node.sourceline, hint=HINT)
        T = T_parent @ _node_transform(node, source)
        for child in node:
            kind = _local(child.tag)
            if kind == "instance_geometry":
                tri = geometry((child.get("url") or "").lstrip("#"))
                if len(tri):
                    # Most exports place their one geometry with an identity matrix.
                    placed.append(tri if np.array_equal(T, _IDENTITY)
                                  else _transformed(tri, T[:3, :3], T[:3, 3]))
            elif kind == "node":
                walk(child, T, depth + 1)
            elif kind == "instance_node":
                target = library_nodes.get((child.get("url") or "").lstrip("#"))
                if target is not None:
                    walk(target, T, depth + 1)

    scene = _first(root, "scene")
    instance = _first(scene, "instance_visual_scene") if scene is not None else None
    scenes = {s.get("id"): s for s in root.iter("{*}visual_scene")}
    chosen = scenes.get((instance.get("url") or "").lstrip("#")) if instance is not None else None
    if chosen is None and scenes:
        chosen = next(iter(scenes.values()))
    if chosen is not None:
        for node in _children(chosen, "node"):
            walk(node, np.eye(4), 0)
    notes = []
    if not placed and geometries:
        # No scene places anything: Gazebo shows nothing, but the geometry is still the part.
        notes.append("no <visual_scene> node instances a geometry; read the geometries as-is")
        placed = [geometry(ref) for ref in geometries]
    triangles = np.concatenate(placed) if placed else np.zeros((0, 3, 3))
    if up_axis in _UP_AXIS_ROTATION and up_axis != "Z_UP":
        triangles = _transformed(triangles, R_up)
    return DaeFile(triangles, metres, declared, up_axis, notes)


def read_dae(path: str | Path) -> DaeFile:
    from reedtool.io.fileio import MAX_MESH_BYTES, read_bytes

    path = Path(path)
    return parse_dae(read_bytes(path, what="mesh file", max_bytes=MAX_MESH_BYTES), path)
