"""Everything rules share, computed once per run and only when a rule asks for it.

Rules never recompute physics or re-import heavy modules: kinematics, rotor discovery,
whole-robot mass properties, allocation and trim are cached properties here, and the
modules that compute them (reedtool.physics.kinematics, .rotors, .inertia, .allocation, .trim)
are imported inside the property so a run that selects only structure rules stays light.

Physics needs a sound tree. `tree_ok` is decided here from the model alone; rules that
need poses or rotors return nothing when it is False (the structure rules say why).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property
from typing import TYPE_CHECKING, Any, Sequence

import numpy as np

from reedtool.model import Joint, Link, Robot

if TYPE_CHECKING:
    from reedtool.physics.rotors import Rotor


@dataclass
class Tree:
    """The kinematic tree as the joints declare it, tolerant of every structural mistake."""

    parent_joint: dict[str, Joint] = field(default_factory=dict)   # child link -> joint
    extra_parents: dict[str, list[Joint]] = field(default_factory=dict)  # 2nd, 3rd... parents
    roots: list[str] = field(default_factory=list)
    cycles: list[list[str]] = field(default_factory=list)        # link names around each cycle
    dangling: list[Joint] = field(default_factory=list)          # parent or child not a link


def build_tree(robot: Robot) -> Tree:
    tree = Tree()
    links = robot.link_map
    for joint in robot.joints:
        if joint.parent not in links or joint.child not in links:
            tree.dangling.append(joint)
            continue
        if joint.child in tree.parent_joint:
            tree.extra_parents.setdefault(joint.child, []).append(joint)
        else:
            tree.parent_joint[joint.child] = joint
    tree.roots = [name for name in links if name not in tree.parent_joint]

    # Walk up from every link; meeting a link already on the current path is a cycle.
    state: dict[str, int] = {}  # 1: on the current path, 2: done
    for start in links:
        path: list[str] = []
        name: str | None = start
        while name is not None and state.get(name) is None:
            state[name] = 1
            path.append(name)
            joint = tree.parent_joint.get(name)
            name = joint.parent if joint else None
        if name is not None and state.get(name) == 1:
            tree.cycles.append(path[path.index(name):])
        for visited in path:
            state[visited] = 2
    return tree


# What a mesh file's triangles are worth (damaged, empty, NaN: a reason; "" fine), judged
# once per process for every model of a run that names the file. The file itself is read
# once per process by io.meshes.read_mesh, keyed by the same identity.
SHARED_MESHES_MAX = 64
_shared_mesh_errors: dict[tuple, str] = {}   # file identity -> why not usable ("": fine)


def _remember(cache: dict, key: tuple | None, value) -> None:
    if key is None:
        return
    if len(cache) >= SHARED_MESHES_MAX:
        cache.pop(next(iter(cache)))      # the oldest first
    cache[key] = value


class CheckContext:
    def __init__(self, robot: Robot, controllers: Sequence[Any] = (),
                 flight_params: Sequence[Any] = (), arguments: Any = None):
        self.robot = robot
        # Autopilot parameter files (validate --airframe / --autopilot-params):
        # reedtool.flightstack.px4.Px4Params and .ardupilot.ArduPilotParams.
        self.flight_params = list(flight_params)
        # Controller tables read from files (validate --controller), reedtool.flightstack.controller_tables.
        self.controllers = list(controllers)
        # reedtool.io.xacro_args.ArgumentUse: the xacro arguments given and known; None
        # when the caller did not say (the argument rules then find nothing).
        self.arguments = arguments
        self._geometry_props: dict[str, Any] = {}
        self._mesh_bounds: dict[str, Any] = {}
        self._mesh_errors: dict[str, str] = {}     # path -> why it is not a usable mesh
        self._mesh_files: dict[str, Any] = {}      # path -> MeshFile | ReedtoolError | None

    # ------------------------------------------------------------ structure

    @cached_property
    def tree(self) -> Tree:
        return build_tree(self.robot)

    @cached_property
    def tree_ok(self) -> bool:
        """One root, no cycle, no dangling joint, unique names: poses are well defined."""
        tree = self.tree
        unique = (len(self.robot.link_map) == len(self.robot.links)
                  and len(self.robot.joint_map) == len(self.robot.joints))
        return (len(tree.roots) == 1 and not tree.cycles and not tree.dangling
                and not tree.extra_parents and unique)

    def parent_joint(self, link_name: str) -> Joint | None:
        return self.tree.parent_joint.get(link_name)

    def is_moving(self, link: Link) -> bool:
        """A link Gazebo simulates as its own body: the child of a non-fixed joint."""
        joint = self.parent_joint(link.name)
        return joint is not None and joint.moves

    # ------------------------------------------------------------ physics

    @cached_property
    def link_poses(self) -> dict[str, np.ndarray]:
        from reedtool.physics.kinematics import link_poses

        return link_poses(self.robot) if self.tree_ok else {}

    @cached_property
    def rotors(self) -> list["Rotor"]:
        if not self.tree_ok:
            return []
        from reedtool.physics.rotors import discover_rotors

        return discover_rotors(self.robot)

    @cached_property
    def lift_rotors(self) -> list["Rotor"]:
        """The rotors that hold the robot up: propulsion rotors (pushers) left out."""
        return [r for r in self.rotors if r.role == "lift"]

    @cached_property
    def articulated_rotors(self) -> dict[str, str]:
        """Lift rotor name -> the first moving joint between it and the base other than its
        own spin joint (a tilt servo, a folding arm, a leg). Such a rotor's flight pose is
        set by that joint; the zero pose the hover rules would judge is not the vehicle's."""
        out: dict[str, str] = {}
        for rotor in self.lift_rotors:
            spin = self.robot.joint_map.get(rotor.joint or "")
            link = spin.parent if spin is not None else None
            seen = set()
            while link is not None and link not in seen:
                seen.add(link)
                joint = self.parent_joint(link)
                if joint is None:
                    break
                if joint.moves and joint.limit is not None \
                        and joint.limit.upper - joint.limit.lower > 1e-9:
                    out[rotor.name] = joint.name
                    break
                link = joint.parent
        return out

    @cached_property
    def omnidirectional(self) -> bool:
        """Reversible or every-direction rotors: hover uses the 6-DoF allocation."""
        from reedtool.physics.rotors import is_omnidirectional

        return is_omnidirectional(self.lift_rotors)

    @cached_property
    def controller_tables(self) -> list:
        """Every controller rotor table: velocity-control plugins in the model, then files."""
        from reedtool.flightstack.controller_tables import velocity_control_tables

        return velocity_control_tables(self.robot) + self.controllers

    @cached_property
    def rotor_count_declarations(self) -> list:
        from reedtool.physics.rotors import declared_rotor_counts

        return declared_rotor_counts(self.robot)

    @cached_property
    def whole_robot(self):
        """Mass, COM (base frame) and inertia of the whole robot (reedtool.physics.inertia)."""
        from reedtool.physics.inertia import whole_robot

        return whole_robot(self.robot)

    @cached_property
    def allocation(self) -> np.ndarray:
        """(4, n) map from rotor thrusts [N] to [thrust, roll, pitch, yaw] about the COM."""
        from reedtool.physics.allocation import allocation_matrix

        return allocation_matrix(self.lift_rotors, self.whole_robot.com_m)

    @cached_property
    def wrench_allocation(self) -> np.ndarray:
        """(6, n) map from lift-rotor thrusts to force and torque about the COM."""
        from reedtool.physics.allocation import wrench_matrix

        return wrench_matrix(self.lift_rotors, self.whole_robot.com_m)

    @cached_property
    def trim(self):
        from reedtool.physics.trim import solve_trim, solve_trim_6dof

        whole = self.whole_robot
        solve = solve_trim_6dof if self.omnidirectional else solve_trim
        return solve(whole.mass_kg, whole.com_m, self.lift_rotors)

    @cached_property
    def simulator(self) -> str:
        """"classic" when the model's plugins are Gazebo classic ones (lib*.so: gazebo_ros,
        RotorS, PX4 classic) and none is a gz-sim system; else "gz" (the more permissive
        mesh loader, so an undecided model is not held to classic's formats)."""
        classic = False
        for _block, plugin in self.robot.plugins():
            text = f"{plugin.filename or ''} {plugin.name or ''}".lower()
            if any(mark in text for mark in ("gz-sim", "gz::sim", "ignition-gazebo",
                                             "ignition::gazebo", "gz_sim", "ign_gazebo")):
                return "gz"
            filename = (plugin.filename or "").rsplit("/", 1)[-1]
            classic = classic or (filename.startswith("lib") and filename.endswith(".so"))
        return "classic" if classic else "gz"

    @cached_property
    def link_comparisons(self) -> list:
        """physics.inertia.compare_links: one verdict per link (parallel to robot.links),
        the same `reedtool inertia` prints."""
        from reedtool.physics.inertia import compare_links

        return compare_links(self.robot)

    @cached_property
    def lumped_links(self) -> set[str]:
        """URDF links Gazebo merges into their parent (physics.inertia.lumped_urdf_links)."""
        from reedtool.physics.inertia import lumped_urdf_links

        return lumped_urdf_links(self.robot)

    def lumped_tensor(self, link_name: str):
        """Inertia tensor (about its COM) of the body Gazebo makes of `link_name` and the
        links merged with it (fixed joints lumped into their parent); None without poses."""
        from reedtool.physics.inertia import combine, declared_mass_properties

        poses = self.link_poses
        if link_name not in poses:
            return None

        def group_root(name: str) -> str:
            while name in self.lumped_links:
                name = self.parent_joint(name).parent
            return name

        root = group_root(link_name)
        T_root_base = np.linalg.inv(poses[root])
        parts = []
        for link in self.robot.links:
            declared = declared_mass_properties(link)
            if declared is None or link.name not in poses or group_root(link.name) != root:
                continue
            parts.append(declared.transformed(T_root_base @ poses[link.name]))
        return combine(parts).inertia_kg_m2 if parts else None

    @cached_property
    def placeholder_links(self) -> set[str]:
        """Links too light to change how the robot flies (physics.inertia.placeholder_links)."""
        from reedtool.physics.inertia import placeholder_links

        return placeholder_links(self.robot) if self.tree_ok else set()

    def geometry_mass_properties(self, link: Link):
        """Mass properties of the link's own geometry at its declared mass, in the link frame.

        None when the link has no geometry, no positive mass, or the geometry cannot be
        measured (an unresolved or empty mesh: the structure rules report those).
        """
        if link.name in self._geometry_props:
            return self._geometry_props[link.name]
        result = None
        mass = link.inertial.mass_kg if link.inertial else None
        if mass is not None and np.isfinite(mass) and mass > 0:
            from reedtool.errors import ReedtoolError
            from reedtool.physics.inertia import link_geometry

            try:
                # Every collision shape (else visual) at one density: the body I204 judges.
                found = link_geometry(link, mass)
                result = found.body if found is not None else None
            except ReedtoolError:
                result = None
        self._geometry_props[link.name] = result
        return result

    def mesh_file(self, mesh):
        """The resolved mesh file read once per run (reedtool.io.meshes.MeshFile), or the
        ReedtoolError saying why it cannot be read; None when unresolved or not a file."""
        if mesh.path is None:
            return None
        key = str(mesh.path)
        if key not in self._mesh_files:
            from reedtool.errors import ReedtoolError
            from reedtool.io.meshes import LIGHT_SUFFIXES, read_mesh
            from reedtool.resolve.references import uri_problem

            if mesh.path.suffix.lower() not in LIGHT_SUFFIXES or not mesh.path.is_file() \
                    or uri_problem(mesh.uri, mesh.path):
                self._mesh_files[key] = None   # only the light readers run in validate
            else:
                try:
                    self._mesh_files[key] = read_mesh(key)    # read once per process
                except ReedtoolError as exc:
                    self._mesh_files[key] = exc
        return self._mesh_files[key]

    def mesh_error(self, mesh) -> str | None:
        """Why a resolved STL/DAE/OBJ file holds no usable mesh (damaged, empty, NaN), or None.

        A flat mesh is fine here: a plane is a valid visual, it only has no volume.
        """
        from reedtool.errors import ReedtoolError

        read = self.mesh_file(mesh)
        if read is None:
            return None
        if isinstance(read, ReedtoolError):
            return read.message
        from reedtool.io.meshes import file_identity

        key = str(mesh.path)
        shared = file_identity(mesh.path)
        if key not in self._mesh_errors and shared in _shared_mesh_errors:
            self._mesh_errors[key] = _shared_mesh_errors[shared]
        if key not in self._mesh_errors:
            from reedtool.io.fileio import MAX_MESH_COORDINATE
            from reedtool.io.meshes import check_triangles, triangle_areas

            error = ""
            triangles = read.triangles
            try:
                if len(triangles) == 0 or not np.isfinite(triangles).all() \
                        or float(triangle_areas(triangles).sum()) == 0.0 \
                        or float(np.abs(triangles).max()) > MAX_MESH_COORDINATE:
                    check_triangles(triangles, key)   # raises with the reason
            except ReedtoolError as exc:
                error = exc.message
            self._mesh_errors[key] = error
            _remember(_shared_mesh_errors, shared, error)
        return self._mesh_errors[key] or None

    def mesh_bounds(self, mesh) -> np.ndarray | None:
        """(2, 3) min/max corners of a mesh in metres in its own frame, as Gazebo sizes it:
        the file's unit (COLLADA <unit>) and the `<mesh scale>` applied; None if unreadable."""
        if mesh.path is None or self.mesh_error(mesh):
            return None
        key = str(mesh.path)
        if key not in self._mesh_bounds:
            read = self.mesh_file(mesh)
            if read is None:        # a format only trimesh reads: not measured in validate
                bounds = None
            else:
                bounds = read.bounds_m()
            self._mesh_bounds[key] = bounds
        bounds = self._mesh_bounds[key]
        if bounds is None:
            return None
        scaled = bounds * np.asarray(mesh.scale, dtype=float)
        return np.vstack([scaled.min(axis=0), scaled.max(axis=0)])
