"""A robot as a 3-D trimesh scene, as Gazebo would place it: `reedtool view`'s one picture.

The scene graph has one node per link, named by the link, parented by the joint tree
with the joint's transform at zero joint positions, so a glTF viewer shows the kinematic
tree and `scene.graph.get(link, base_link)` is `T_base_link`. Where the link tree comes
from depends on the model:

- URDF and xacro: yourdfpy reads the URDF text (the expansion reedtool made, so
  `$(find)` and `package://` are already reedtool's), builds the link tree, the primitive
  shapes and their material colours. Its `filename_handler` maps each mesh URI to the
  file reedtool's package resolution found.
- SDF: the tree is reedtool's own reading, with link poses exactly as
  `physics.kinematics` computes them, and the same primitive shapes.

Mesh files are read by reedtool (`io.meshes`) in both cases, in metres as Gazebo sizes
them: trimesh keeps a COLLADA `<unit>` as metadata and would draw a centimetre mesh 100x
too big, which is exactly the mistake this picture exists to show.

Around the robot, as children of the base link: a disc at each rotor across its thrust
axis, coloured by spin direction (the `layout` picture's colours) with an arrow along
the spin (or, with `disc_style="outline"`, a ring, so the frame and the motor mounts
under it show through), the thrust axis, the centre of mass, the base frame's axes, a
scale bar, and a FRONT arrow along +x as long as an arm, above the body. Labels (FRONT,
each rotor's motor number as the autopilot counts it) are positions and texts in
`ViewScene.labels`: glTF has no text, so each format draws them its own way (HTML
hotspots, PNG text).
Above the base link a root node turns ROS's z-up into glTF's y-up (glTF 2.0, 3.4), so
viewers show the robot standing.

This module draws and computes nothing about the robot: the link poses, rotors, centre of
mass and the links findings name come from workflows/view.py.
"""

from __future__ import annotations

import contextlib
import logging
import math
from dataclasses import dataclass, field

import numpy as np

ROOT_NODE = "gltf_y_up"
# glTF is y-up (x right, y up, z towards the viewer); ROS is z-up: x stays, z -> y, y -> -z.
T_GLTF_ROS = np.array([[1.0, 0.0, 0.0, 0.0],
                       [0.0, 0.0, 1.0, 0.0],
                       [0.0, -1.0, 0.0, 0.0],
                       [0.0, 0.0, 0.0, 1.0]])

# The layout picture's spin colours (ccw / cw seen from above along the thrust axis).
SPIN_RGBA = {1: (31, 119, 180, 255), -1: (230, 126, 34, 255), 0: (127, 127, 127, 255)}
SEVERITY_RGBA = {"error": (214, 39, 40, 255), "warning": (255, 191, 0, 255),
                 "info": (23, 190, 207, 255)}
DEFAULT_RGBA = (178, 178, 178, 255)
# What yourdfpy raises on a URDF it cannot read (a bad number, a missing attribute).
YOURDFPY_ERRORS = (ValueError, TypeError, KeyError, AttributeError, IndexError)
DECORATION_PREFIXES = ("rotor_disc/", "spin_arrow/", "thrust_axis/", "com", "base_axes/",
                       "scale_bar", "front_arrow")
DISC_STYLES = ("filled", "outline")
FRONT_RGBA = (200, 30, 30, 255)


@dataclass
class Framing:
    """The robot's extent, for the scale bar and the caption (numbers, not pixels)."""

    bounds_m: np.ndarray            # (2, 3) min and max corner in the base frame
    scale_bar_m: float              # a 1-2-5 length near a quarter of the largest extent

    @property
    def extent_m(self) -> np.ndarray:
        return self.bounds_m[1] - self.bounds_m[0]

    def caption(self) -> str:
        x, y, z = (float(v) for v in self.extent_m)
        return (f"bounding box {length_text(x)} x {length_text(y)} x {length_text(z)} "
                f"(x forward, y left, z up); scale bar {length_text(self.scale_bar_m)}")


@dataclass
class RotorDisc:
    name: str
    node: str                       # the disc's node in the scene
    T_base_disc: np.ndarray         # disc centre at the rotor, z along the thrust axis
    radius_m: float
    turning_sign: int               # +1 ccw, -1 cw about the thrust axis, 0 unknown
    rgba: tuple[int, int, int, int]


@dataclass
class Label:
    """A text at a point of the base frame: 'FRONT', or a rotor's motor number."""

    text: str
    position_m: np.ndarray
    kind: str                       # "front" or "rotor"


@dataclass
class ViewScene:
    scene: object                   # trimesh.Scene, root ROOT_NODE, then the base link
    base_link: str
    T_base_link: dict[str, np.ndarray]
    framing: Framing
    source: str                     # "yourdfpy" (URDF/xacro) or "reedtool" (SDF)
    discs: list[RotorDisc] = field(default_factory=list)
    com_m: np.ndarray | None = None
    link_severity: dict[str, str] = field(default_factory=dict)
    notes: list[str] = field(default_factory=list)   # what could not be drawn, and why
    name: str = ""                  # the robot's
    labels: list[Label] = field(default_factory=list)


def length_text(length_m: float) -> str:
    return f"{length_m:.3g} m"


def nice_length(length_m: float) -> float:
    """The largest 1, 2 or 5 x 10^k not above `length_m` (a scale bar's length)."""
    if not (math.isfinite(length_m) and length_m > 0):
        return 1.0
    exponent = math.floor(math.log10(length_m))
    mantissa = length_m / 10.0 ** exponent
    if mantissa < 1.0:        # log10 rounding just below a power of ten
        exponent, mantissa = exponent - 1, mantissa * 10.0
    step = 5 if mantissa >= 5 else 2 if mantissa >= 2 else 1
    return step * 10.0 ** exponent


# ------------------------------------------------------------------- geometry

def _mesh_from_triangles(triangles_m: np.ndarray):
    import trimesh

    vertices = np.asarray(triangles_m, dtype=float).reshape(-1, 3)
    faces = np.arange(len(vertices)).reshape(-1, 3)
    return trimesh.Trimesh(vertices=vertices, faces=faces, process=True)


def mesh_file_geometry(path, scale) -> object:
    """A mesh file as Gazebo sizes it (COLLADA <unit> applied), then `<mesh scale>`.
    A flat or open mesh is drawn as it is (mass properties are not asked of it here);
    triangles with a non-finite corner are left out, an empty mesh is refused."""
    from reedtool.errors import ReedtoolError
    from reedtool.io.meshes import read_mesh

    triangles = read_mesh(path).triangles_m * np.asarray(scale, dtype=float).reshape(1, 1, 3)
    triangles = triangles[np.all(np.isfinite(triangles), axis=(1, 2))]
    if not len(triangles):
        raise ReedtoolError("the mesh has no triangles with finite corners", file=path)
    return _mesh_from_triangles(triangles)


def primitive(kind: str, **size):
    """The trimesh primitive yourdfpy makes for a URDF shape (so both paths agree)."""
    import trimesh

    if kind == "box":
        return trimesh.primitives.Box(extents=size["size_m"]).to_mesh()
    if kind == "cylinder":
        return trimesh.primitives.Cylinder(radius=size["radius_m"],
                                           height=size["length_m"]).to_mesh()
    return trimesh.primitives.Sphere(radius=size["radius_m"]).to_mesh()


def _paint(mesh, rgba) -> None:
    mesh.visual.face_colors = np.tile(np.asarray(rgba, dtype=np.uint8), (len(mesh.faces), 1))


# --------------------------------------------------------------- the two trees

def _mesh_paths(robot, collision: bool) -> dict[str, object]:
    """Mesh URI -> the file reedtool's package resolution found (None: unresolved)."""
    from reedtool.model import Mesh

    paths = {}
    for link in robot.links:
        for shape in (link.collisions if collision else link.visuals):
            if isinstance(shape.geometry, Mesh):
                paths.setdefault(shape.geometry.uri, shape.geometry.path)
                paths.setdefault(shape.geometry.uri.strip(), shape.geometry.path)
    return paths


def _mesh_errors(robot) -> dict[str, str]:
    """Mesh URI -> why it has no file (not found, or withheld: workflows.view)."""
    from reedtool.model import Mesh

    return {shape.geometry.uri.strip(): shape.geometry.resolve_error
            for link in robot.links for shape in [*link.visuals, *link.collisions]
            if isinstance(shape.geometry, Mesh) and shape.geometry.resolve_error}


def _yourdfpy_scene(robot, collision: bool, T_base_link: dict, notes: list[str]):
    """URDF/xacro: yourdfpy's scene (link tree, primitives, colours), meshes added by us."""
    import io

    import trimesh
    import yourdfpy

    paths = _mesh_paths(robot, collision)

    def filename_handler(fname: str) -> str:
        path = paths.get(fname)
        return str(path) if path is not None else fname

    with _quiet(yourdfpy.urdf._logger):
        urdf = yourdfpy.URDF.load(io.BytesIO(robot.urdf_xml.encode("utf-8")),
                                  build_scene_graph=not collision, load_meshes=False,
                                  build_collision_scene_graph=collision,
                                  load_collision_meshes=False, force_collision_mesh=False,
                                  filename_handler=filename_handler)
    for link in robot.links:
        if link.name not in T_base_link:
            notes.append(f"link '{link.name}' is not connected to '{urdf.base_link}': "
                         f"yourdfpy draws it at the base frame")
    built = urdf.collision_scene if collision else urdf.scene
    scene = trimesh.Scene(base_frame=ROOT_NODE)
    scene.graph.update(frame_from=ROOT_NODE, frame_to=urdf.base_link, matrix=T_GLTF_ROS)
    shapes_of: dict[str, int] = {}
    for parent, child, attributes in built.graph.to_edgelist():
        geometry_name = attributes.get("geometry")
        if geometry_name is not None:
            number = shapes_of[parent] = shapes_of.get(parent, -1) + 1
            child = f"{parent}/{'collision' if collision else 'visual'}_{number}"
            mesh = built.geometry[geometry_name]
            if isinstance(mesh, trimesh.primitives.Primitive):
                mesh = mesh.to_mesh()
            if collision or not _has_own_colour(mesh):
                _paint(mesh, DEFAULT_RGBA)
            scene.add_geometry(mesh, node_name=child, geom_name=child,
                               parent_node_name=parent, transform=np.asarray(attributes["matrix"]))
        else:
            scene.graph.update(frame_from=parent, frame_to=child,
                               matrix=np.asarray(attributes.get("matrix", np.eye(4))))
    # Meshes: yourdfpy resolves each file through reedtool's handler; reedtool reads it.
    for link in urdf.robot.links:
        for number, shape in enumerate(link.collisions if collision else link.visuals):
            geometry = shape.geometry
            if geometry is None or geometry.mesh is None:
                continue
            path = urdf._filename_handler(fname=geometry.mesh.filename)
            if paths.get(geometry.mesh.filename) is None:
                why = _mesh_errors(robot).get(geometry.mesh.filename.strip()) or "not found"
                notes.append(f"link '{link.name}': mesh '{geometry.mesh.filename}' not shown "
                             f"({why})")
                continue
            mesh = _read_mesh(path, geometry.mesh.scale, link.name, notes)
            if mesh is None:
                continue
            if not collision:
                yourdfpy.urdf.apply_visual_color(mesh, shape, urdf._material_map)
                if not _has_own_colour(mesh):
                    _paint(mesh, DEFAULT_RGBA)
            else:
                _paint(mesh, DEFAULT_RGBA)
            origin = shape.origin if shape.origin is not None else np.eye(4)
            scene.add_geometry(mesh, node_name=f"{link.name}/mesh_{number}",
                               geom_name=f"{link.name}/mesh_{number}",
                               parent_node_name=link.name, transform=origin)
    T_scene = {link.name: np.asarray(urdf.get_transform(link.name, urdf.base_link,
                                                        collision_geometry=collision))
               for link in urdf.robot.links}
    return scene, urdf.base_link, T_scene


@contextlib.contextmanager
def _quiet(logger):
    """yourdfpy logs what it works around; reedtool reports it as notes instead."""
    level = logger.level
    logger.setLevel(logging.CRITICAL)
    try:
        yield
    finally:
        logger.setLevel(level)


def _has_own_colour(mesh) -> bool:
    """True when a material gave the mesh a colour (trimesh's default is uniform grey)."""
    kind = getattr(mesh.visual, "kind", None)
    if kind is None:
        return False
    colours = np.asarray(mesh.visual.face_colors)
    return len(colours) > 0 and not np.all(colours[:, :3] == 102)


def _read_mesh(path, scale, link_name: str, notes: list[str]):
    from reedtool.errors import ReedtoolError

    try:
        return mesh_file_geometry(path, np.ones(3) if scale is None else
                                  np.broadcast_to(np.asarray(scale, dtype=float), (3,)))
    except ReedtoolError as exc:
        notes.append(f"link '{link_name}': mesh not shown ({exc.one_line()})")
        return None


def _tree_joints(robot, base: str) -> list:
    """The joints of the tree from `base`, breadth first, the first joint to reach a link
    kept: the walk physics.kinematics.link_poses makes, so each node's pose is its own."""
    children: dict[str, list] = {}
    for joint in robot.joints:
        if joint.parent is not None and joint.child is not None:
            children.setdefault(joint.parent, []).append(joint)
    placed, queue, tree = {base}, [base], []
    while queue:
        parent = queue.pop(0)
        for joint in children.get(parent, ()):
            if joint.child not in placed:
                placed.add(joint.child)
                tree.append(joint)
                queue.append(joint.child)
    return tree


def _reedtool_scene(robot, collision: bool, T_base_link: dict, notes: list[str]):
    """SDF: the link tree and poses as reedtool reads them, shapes as yourdfpy makes them.
    Each link hangs from its parent by the joint that gave it its pose in `T_base_link`."""
    import trimesh

    from reedtool.model import Box, Cylinder, Mesh, Sphere

    base = robot.base_link
    scene = trimesh.Scene(base_frame=ROOT_NODE)
    scene.graph.update(frame_from=ROOT_NODE, frame_to=base, matrix=T_GLTF_ROS)
    for joint in _tree_joints(robot, base):
        scene.graph.update(frame_from=joint.parent, frame_to=joint.child,
                           matrix=joint.T_parent_joint)
    for link in robot.links:
        if link.name not in T_base_link:
            notes.append(f"link '{link.name}' not shown (not connected to '{base}')")
            continue
        for number, shape in enumerate(link.collisions if collision else link.visuals):
            g = shape.geometry
            if isinstance(g, Box):
                mesh = primitive("box", size_m=np.asarray(g.size_m, dtype=float))
            elif isinstance(g, Cylinder):
                mesh = primitive("cylinder", radius_m=g.radius_m, length_m=g.length_m)
            elif isinstance(g, Sphere):
                mesh = primitive("sphere", radius_m=g.radius_m)
            elif isinstance(g, Mesh):
                if g.path is None:
                    notes.append(f"link '{link.name}': mesh '{g.uri}' not shown "
                                 f"({g.resolve_error or 'not found'})")
                    continue
                mesh = _read_mesh(g.path, g.scale, link.name, notes)
                if mesh is None:
                    continue
            else:
                continue
            _paint(mesh, DEFAULT_RGBA)
            node = f"{link.name}/{'collision' if collision else 'visual'}_{number}"
            scene.add_geometry(mesh, node_name=node, geom_name=node,
                               parent_node_name=link.name, transform=shape.T_link_geom)
    return scene, base, {name: T for name, T in T_base_link.items() if name in robot.link_map}


# ---------------------------------------------------------------- decorations

def _frame_along(origin: np.ndarray, axis: np.ndarray) -> np.ndarray:
    """A pose at `origin` whose z axis is `axis` (unit), x and y completed right-handed."""
    z = axis / np.linalg.norm(axis)
    helper = np.array([1.0, 0.0, 0.0]) if abs(z[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    x = np.cross(helper, z)
    x /= np.linalg.norm(x)
    T = np.eye(4)
    T[:3, :3] = np.column_stack([x, np.cross(z, x), z])
    T[:3, 3] = origin
    return T


def _height_above(scene, base: str, link: str | None, T_base_disc: np.ndarray) -> float:
    """How far the rotor link's geometry reaches above the disc plane (0 when none)."""
    if link is None:
        return 0.0
    T_disc_base = np.linalg.inv(T_base_disc)
    top = 0.0
    for node in scene.graph.transforms.children.get(link, []):
        if node not in scene.graph.nodes_geometry:
            continue
        T_disc_node = T_disc_base @ scene.graph.get(node, base)[0]
        vertices = np.asarray(scene.geometry[scene.graph[node][1]].vertices, dtype=float)
        top = max(top, float(np.max(vertices @ T_disc_node[2, :3] + T_disc_node[2, 3])))
    return top


def _flat_disc(radius_m: float, lift_m: float, sections: int = 48):
    """A disc parallel to the xy plane at z = lift_m, both sides faced."""
    import trimesh

    theta = np.linspace(0.0, 2.0 * math.pi, sections, endpoint=False)
    vertices = np.vstack([[0.0, 0.0, lift_m], np.column_stack(
        [radius_m * np.cos(theta), radius_m * np.sin(theta), np.full(sections, lift_m)])])
    rim = np.arange(1, sections + 1)
    faces = np.column_stack([np.zeros(sections, dtype=int), rim, np.roll(rim, -1)])
    return trimesh.Trimesh(vertices=vertices, faces=np.vstack([faces, faces[:, ::-1]]),
                           process=False)


def _ring(radius_m: float, lift_m: float, width_fraction: float = 0.08, sections: int = 64):
    """A flat ring (outer radius `radius_m`) at z = lift_m, both sides faced: a disc's outline."""
    import trimesh

    theta = np.linspace(0.0, 2.0 * math.pi, sections, endpoint=False)
    r_in = (1.0 - width_fraction) * radius_m
    outer = np.column_stack([radius_m * np.cos(theta), radius_m * np.sin(theta),
                             np.full(sections, lift_m)])
    inner = np.column_stack([r_in * np.cos(theta), r_in * np.sin(theta),
                             np.full(sections, lift_m)])
    i = np.arange(sections)
    j = np.roll(i, -1)
    faces = np.vstack([np.column_stack([i, j, sections + i]),
                       np.column_stack([j, sections + j, sections + i])])
    return trimesh.Trimesh(vertices=np.vstack([outer, inner]),
                           faces=np.vstack([faces, faces[:, ::-1]]), process=False)


def _spin_arrow(radius_m: float, sign: int, disc_lift_m: float):
    """A flat arc of 240 degrees just above the disc, in the spin's sense, with a head."""
    import trimesh

    r_in, r_out = 0.66 * radius_m, 0.80 * radius_m
    lift = disc_lift_m + 0.01 * radius_m
    theta = math.radians(150.0) + sign * np.linspace(0.0, math.radians(240.0), 33)
    inner = np.column_stack([r_in * np.cos(theta), r_in * np.sin(theta), np.full_like(theta, lift)])
    outer = np.column_stack([r_out * np.cos(theta), r_out * np.sin(theta), np.full_like(theta, lift)])
    vertices = np.vstack([inner, outer])
    n = len(theta)
    faces = [[i, n + i, i + 1] for i in range(n - 1)] + [[i + 1, n + i, n + i + 1]
                                                       for i in range(n - 1)]
    end = theta[-1]
    tangent = np.array([-math.sin(end), math.cos(end), 0.0]) * sign
    radial = np.array([math.cos(end), math.sin(end), 0.0])
    mid = 0.5 * (r_in + r_out) * radial + [0.0, 0.0, lift]
    head = [mid + 0.28 * radius_m * tangent, mid + 0.16 * radius_m * radial,
            mid - 0.16 * radius_m * radial]
    vertices = np.vstack([vertices, head])
    faces.append([2 * n, 2 * n + 1, 2 * n + 2])
    faces = np.asarray(faces)
    if sign < 0:                          # keep the ribbon's normal along +z
        faces = faces[:, ::-1]
    return trimesh.Trimesh(vertices=vertices, faces=np.vstack([faces, faces[:, ::-1]]),
                           process=False)


def _arrow(length_m: float, radius_m: float):
    """A shaft and cone along +z from the origin."""
    import trimesh

    shaft = trimesh.creation.cylinder(radius=radius_m, height=0.8 * length_m,
                                      transform=_translation([0.0, 0.0, 0.4 * length_m]))
    cone = trimesh.creation.cone(radius=2.5 * radius_m, height=0.2 * length_m,
                                 transform=_translation([0.0, 0.0, 0.8 * length_m]))
    return trimesh.util.concatenate([shaft, cone])


def _translation(p) -> np.ndarray:
    T = np.eye(4)
    T[:3, 3] = p
    return T


def _add(scene, mesh, node: str, parent: str, T: np.ndarray, rgba) -> None:
    _paint(mesh, rgba)
    scene.add_geometry(mesh, node_name=node, geom_name=node, parent_node_name=parent,
                       transform=T)


def _decorate(view: ViewScene, robot, rotors, disc_style: str = "filled") -> None:
    """Rotor discs, spin arrows, thrust axes, COM, base axes, scale bar, FRONT and labels."""
    import trimesh

    from reedtool.report.layout_picture import rotor_marks

    scene, base = view.scene, view.base_link
    size_m = float(np.max(view.framing.extent_m))
    rotors = [r for r in rotors
              if np.all(np.isfinite(r.position_m)) and np.all(np.isfinite(r.axis))
              and np.linalg.norm(r.axis) > 0]
    # the disc radius `layout` draws: the rotor link's cylinder, else from the rotor gaps
    marks = rotor_marks(robot, rotors)
    if disc_style == "outline":
        _fade_rotor_links(view, [rotor.link for rotor in rotors if rotor.link])
    for rotor, mark in zip(rotors, marks):
        radius = mark.radius_m
        T_base_disc = _frame_along(np.asarray(rotor.position_m, dtype=float),
                                   np.asarray(rotor.axis, dtype=float))
        rgba = SPIN_RGBA[int(np.sign(rotor.turning_sign))]
        # the disc floats just above the rotor's own geometry, which it would hide
        lift_m = _height_above(scene, base, rotor.link, T_base_disc) + 0.004 * size_m
        disc = _ring(radius, lift_m) if disc_style == "outline" else _flat_disc(radius, lift_m)
        _add(scene, disc, f"rotor_disc/{rotor.name}", base, T_base_disc, rgba)
        # the motor number just outside the disc's rim, on the side away from the centre
        outward = np.asarray(rotor.position_m, dtype=float) * [1.0, 1.0, 0.0]
        outward = outward / np.linalg.norm(outward) if np.linalg.norm(outward) > 1e-9 \
            else np.array([1.0, 0.0, 0.0])
        view.labels.append(Label(str(mark.number), T_base_disc[:3, 3] + 1.15 * radius * outward
                                 + [0.0, 0.0, lift_m], "rotor"))
        if rotor.turning_sign != 0:
            dark = tuple(int(0.6 * c) for c in rgba[:3]) + (255,)
            _add(scene, _spin_arrow(radius, int(np.sign(rotor.turning_sign)), lift_m),
                 f"spin_arrow/{rotor.name}", base, T_base_disc, dark)
        _add(scene, _arrow(0.9 * radius, 0.02 * radius), f"thrust_axis/{rotor.name}",
             base, T_base_disc, (40, 40, 40, 255))
        view.discs.append(RotorDisc(rotor.name, f"rotor_disc/{rotor.name}", T_base_disc,
                                    radius, rotor.turning_sign, rgba))
    if view.com_m is not None:
        _add(scene, trimesh.creation.icosphere(subdivisions=2, radius=0.02 * size_m), "com",
             base, _translation(view.com_m), (0, 0, 0, 255))
    axis_length = 0.25 * size_m
    for name, rotation, rgba in (
            ("x", [[0, 0, 1], [0, 1, 0], [-1, 0, 0]], (220, 40, 40, 255)),
            ("y", [[1, 0, 0], [0, 0, -1], [0, 1, 0]], (40, 170, 40, 255)),
            ("z", np.eye(3), (40, 80, 220, 255))):
        T = np.eye(4)
        T[:3, :3] = rotation               # maps +z onto the axis it draws
        _add(scene, _arrow(axis_length, 0.012 * axis_length), f"base_axes/{name}", base, T,
             rgba)
    _front(view, rotors)
    low = view.framing.bounds_m[0]
    bar = trimesh.creation.box(extents=[view.framing.scale_bar_m, 0.01 * size_m, 0.01 * size_m])
    _add(scene, bar, "scale_bar", base,
         _translation([low[0] + 0.5 * view.framing.scale_bar_m, low[1] - 0.05 * size_m, low[2]]),
         (0, 0, 0, 255))


ROTOR_FADE_ALPHA = 50       # of 255: a propeller stand-in as a veil over what it covers


def _fade_rotor_links(view: ViewScene, links: list[str]) -> None:
    """With outlined discs, the rotor links' own geometry (RotorS' propeller cylinders, a
    prop mesh) is drawn see-through too: otherwise it hides the motor mounts the outline
    is there to show."""
    scene = view.scene
    for node in list(scene.graph.nodes_geometry):
        if node.startswith(DECORATION_PREFIXES):
            continue
        if scene.graph.transforms.parents.get(node) not in links:
            continue
        _, geometry_name = scene.graph[node]
        mesh = scene.geometry[geometry_name].copy()
        colours = np.asarray(mesh.visual.face_colors).copy()
        colours[:, 3] = np.minimum(colours[:, 3], ROTOR_FADE_ALPHA)
        mesh.visual.face_colors = colours
        scene.geometry[geometry_name] = mesh


def _front(view: ViewScene, rotors) -> None:
    """A red arrow along +x, as long as the longest arm (from the base origin), just above
    the body's top, and a FRONT label at its tip: which way the vehicle faces, at a glance."""
    reach = [float(np.hypot(*np.asarray(r.position_m, dtype=float)[:2])) for r in rotors]
    reach = [r for r in reach if math.isfinite(r) and r > 0]
    size_m = float(np.max(view.framing.extent_m))
    length_m = max(reach) if reach else 0.5 * size_m
    top_m = float(view.framing.bounds_m[1][2]) + 0.02 * size_m
    T = np.eye(4)
    T[:3, :3] = [[0, 0, 1], [0, 1, 0], [-1, 0, 0]]          # +z onto +x
    T[:3, 3] = [0.0, 0.0, top_m]
    _add(view.scene, _arrow(length_m, 0.025 * length_m), "front_arrow", view.base_link, T,
         FRONT_RGBA)
    view.labels.append(Label("FRONT", np.array([1.08 * length_m, 0.0, top_m]), "front"))


# -------------------------------------------------------------------- findings

def _colour_findings(view: ViewScene) -> None:
    scene = view.scene
    for node in scene.graph.nodes_geometry:
        if node.startswith(DECORATION_PREFIXES):
            continue
        parent = scene.graph.transforms.parents.get(node)
        severity = view.link_severity.get(parent) or view.link_severity.get(node)
        if severity is None:
            continue
        _, geometry_name = scene.graph[node]
        mesh = scene.geometry[geometry_name].copy()
        _paint(mesh, SEVERITY_RGBA[severity])
        scene.geometry[geometry_name] = mesh


# ---------------------------------------------------------------------- build

def robot_bounds(scene, exclude=DECORATION_PREFIXES) -> np.ndarray | None:
    """(2, 3) corners of the robot's geometry (decorations excluded) in the base frame."""
    points = []
    base = next(iter(scene.graph.transforms.children.get(ROOT_NODE, [])), None)
    for node in scene.graph.nodes_geometry:
        if node.startswith(exclude):
            continue
        T_base_node = scene.graph.get(node, base)[0]
        mesh = scene.geometry[scene.graph[node][1]]
        vertices = np.asarray(mesh.vertices, dtype=float)
        points.append(vertices @ T_base_node[:3, :3].T + T_base_node[:3, 3])
    if not points:
        return None
    allp = np.vstack(points)
    return np.array([allp.min(axis=0), allp.max(axis=0)])


def build_scene(robot, T_base_link: dict[str, np.ndarray], rotors=(), *,
                com_m: np.ndarray | None = None, collision: bool = False,
                link_severity: dict[str, str] | None = None,
                disc_style: str = "filled") -> ViewScene:
    """`robot` as a ViewScene: URDF/xacro through yourdfpy, SDF with `T_base_link` (the
    link poses reedtool computes), with a disc for each of `rotors`, the COM `com_m`, and
    the links of `link_severity` coloured by their worst finding."""
    notes: list[str] = []
    scene = None
    if robot.source_format == "urdf" and robot.urdf_xml:
        try:
            scene, base, T_scene = _yourdfpy_scene(robot, collision, T_base_link, notes)
            source = "yourdfpy"
        except YOURDFPY_ERRORS as exc:
            # reedtool records content errors and reads on; yourdfpy stops at the first
            notes.append(f"yourdfpy cannot read this URDF ({type(exc).__name__}: {exc}): "
                         f"drawn from reedtool's reading; `reedtool validate` names the "
                         f"problem")
    if scene is None:
        scene, base, T_scene = _reedtool_scene(robot, collision, T_base_link, notes)
        source = "reedtool"
    bounds = robot_bounds(scene)
    if bounds is None:
        # no geometry at all: frame the link origins (and 5 cm around them)
        origins = np.array([T[:3, 3] for T in T_scene.values()] or [np.zeros(3)])
        bounds = np.array([origins.min(axis=0) - 0.05, origins.max(axis=0) + 0.05])
        notes.append("the model has no geometry to show: framed its link origins")
    framing = Framing(bounds, nice_length(float(np.max(bounds[1] - bounds[0])) / 4.0))
    view = ViewScene(scene, base, T_scene, framing, source, com_m=com_m, notes=notes,
                     link_severity=dict(link_severity or {}), name=robot.name)
    if view.link_severity:
        _colour_findings(view)
    _decorate(view, robot, rotors, disc_style)
    return view


def glb_bytes(view: ViewScene) -> bytes:
    """The scene as binary glTF (one node per link, named by the link)."""
    return view.scene.export(file_type="glb")
