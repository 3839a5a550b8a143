"""The one robot model every check, inertia computation and simulation reads.

Plain dataclasses in the spirit of yourdfpy, plus what yourdfpy lacks: a source location
on every element. Poses are 4x4 homogeneous transforms named `T_a_b` ("pose of frame b
expressed in frame a"). All quantities are SI (m, kg, kg*m^2, rad, s).

Only `urdf_io` builds these objects from XML; nothing else parses URDF.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property
from pathlib import Path
from typing import Iterator, Union

import numpy as np


@dataclass(frozen=True)
class SourceLoc:
    """Where an element came from, in the file the user edits.

    `file`/`line` is the line to change: the element itself, or, for an element produced
    by a macro, the innermost macro call in a user file. `macro_file`/`macro_line` is the
    element's line inside the macro body when it came from one. `urdf_line` is the line in
    the expanded URDF text, when there was an expansion.
    """

    file: str
    line: int | None = None
    macro_file: str | None = None
    macro_line: int | None = None
    urdf_line: int | None = None

    def __str__(self) -> str:
        return f"{self.file}:{self.line}" if self.line else self.file

    @property
    def macro(self) -> str | None:
        if self.macro_file is None:
            return None
        return f"{self.macro_file}:{self.macro_line}" if self.macro_line else self.macro_file


UNKNOWN_LOC = SourceLoc(file="<unknown>")


# ---------------------------------------------------------------- geometry

@dataclass(eq=False)  # identity: fields hold numpy arrays
class Box:
    size_m: np.ndarray  # (3,) full edge lengths along x, y, z of the geometry frame


@dataclass
class Cylinder:
    radius_m: float
    length_m: float  # along the geometry frame's z axis (URDF convention)


@dataclass
class Sphere:
    radius_m: float


@dataclass(eq=False)  # identity: fields hold numpy arrays
class Mesh:
    uri: str                       # as written: package://, file://, relative or absolute
    path: Path | None              # resolved file, None when it could not be resolved
    scale: np.ndarray = field(default_factory=lambda: np.ones(3))
    resolve_error: str | None = None  # why `path` is None


Geometry = Union[Box, Cylinder, Sphere, Mesh]


@dataclass(eq=False)  # identity: fields hold numpy arrays
class Visual:
    geometry: Geometry | None
    T_link_geom: np.ndarray
    loc: SourceLoc
    name: str | None = None
    material: str | None = None


@dataclass(eq=False)  # identity: fields hold numpy arrays
class Collision:
    geometry: Geometry | None
    T_link_geom: np.ndarray
    loc: SourceLoc
    name: str | None = None


INERTIA_KEYS = ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")
INERTIA_INDEX = {"ixx": (0, 0), "ixy": (0, 1), "ixz": (0, 2), "iyy": (1, 1), "iyz": (1, 2),
                 "izz": (2, 2)}


def inertia_tensor(values: dict[str, float]) -> np.ndarray:
    """The symmetric 3x3 tensor from URDF/SDF's six numbers (keys INERTIA_KEYS)."""
    return np.array([[values["ixx"], values["ixy"], values["ixz"]],
                     [values["ixy"], values["iyy"], values["iyz"]],
                     [values["ixz"], values["iyz"], values["izz"]]], dtype=float)


def inertia_values(inertia_kg_m2) -> dict[str, float]:
    """URDF/SDF's six numbers of a 3x3 tensor (keys INERTIA_KEYS): inertia_tensor's inverse."""
    I = np.asarray(inertia_kg_m2, dtype=float)
    return {key: float(I[INERTIA_INDEX[key]]) for key in INERTIA_KEYS}


@dataclass(eq=False)  # identity: fields hold numpy arrays
class Inertial:
    mass_kg: float
    T_link_com: np.ndarray         # pose of the inertial (COM) frame in the link frame
    inertia_kg_m2: np.ndarray      # (3, 3) about the COM, in the inertial frame's axes
    loc: SourceLoc
    mass_loc: SourceLoc | None = None
    inertia_loc: SourceLoc | None = None

    @property
    def com_m(self) -> np.ndarray:
        return self.T_link_com[:3, 3]

    def inertia_in_link_axes(self) -> np.ndarray:
        """Tensor about the COM, expressed in the link frame's axes."""
        R = self.T_link_com[:3, :3]
        return R @ self.inertia_kg_m2 @ R.T


@dataclass(eq=False)  # identity: fields hold numpy arrays
class Link:
    name: str
    loc: SourceLoc
    inertial: Inertial | None = None
    visuals: list[Visual] = field(default_factory=list)
    collisions: list[Collision] = field(default_factory=list)

    def geometry_for_mass(self) -> tuple[Geometry, np.ndarray] | None:
        """The geometry mass properties are derived from: first collision, else first visual.

        Returns (geometry, T_link_geom) or None when the link has no geometry.
        """
        for shape in [*self.collisions, *self.visuals]:
            if shape.geometry is not None:
                return shape.geometry, shape.T_link_geom
        return None


JOINT_TYPES = ("revolute", "continuous", "prismatic", "fixed", "floating", "planar")


@dataclass
class JointLimit:
    lower: float | None
    upper: float | None
    effort: float | None
    velocity: float | None
    loc: SourceLoc


@dataclass(eq=False)  # identity: fields hold numpy arrays
class Joint:
    name: str
    type: str
    parent: str | None
    child: str | None
    T_parent_joint: np.ndarray     # pose of the joint (= child link) frame in the parent link
    axis: np.ndarray               # (3,) in the joint frame, as declared (not normalised)
    loc: SourceLoc
    limit: JointLimit | None = None
    axis_loc: SourceLoc | None = None
    origin_loc: SourceLoc | None = None
    # SDF only: the joint frame in the child link frame, when the file poses the joint
    # away from the child's origin (the axis line passes there). URDF has no such frame.
    T_child_jointframe: np.ndarray | None = None

    @property
    def moves(self) -> bool:
        return self.type != "fixed"


# ------------------------------------------------------- gazebo extensions

@dataclass
class XmlNode:
    """A generic element kept from a <gazebo> extension (plugin parameters, materials).

    Plugin blocks are free-form XML; keeping them as a small tree with locations lets
    rotor discovery and checks read them without touching lxml.
    """

    tag: str
    attrib: dict[str, str]
    text: str | None
    children: list["XmlNode"]
    loc: SourceLoc

    def find(self, tag: str) -> "XmlNode | None":
        return next((c for c in self.children if c.tag == tag), None)

    def findall(self, tag: str) -> list["XmlNode"]:
        return [c for c in self.children if c.tag == tag]

    def findtext(self, tag: str, default: str | None = None) -> str | None:
        node = self.find(tag)
        if node is None or node.text is None:
            return default
        return node.text.strip()

    def iter(self) -> Iterator["XmlNode"]:
        yield self
        for child in self.children:
            yield from child.iter()


def library_name(filename: str | None) -> str:
    """A plugin's library file name without directory, 'lib' prefix or '.so' suffix."""
    base = (filename or "").rsplit("/", 1)[-1]
    if base.startswith("lib"):
        base = base[3:]
    if base.endswith(".so"):
        base = base[:-3]
    return base


# Motor-model plugins, the one table every stage reads (rotor discovery, migrate's port,
# which model of an SDF world is the vehicle): library (see `library_name`) -> rotor family.
MOTOR_PLUGINS = {
    "rotors_gazebo_motor_model": "rotors",
    "gazebo_motor_model": "px4",
    "gz-sim-multicopter-motor-model-system": "gz",
    "ignition-gazebo-multicopter-motor-model-system": "gz",
}
MOTOR_PLUGIN_NAMES = {"gz::sim::systems::MulticopterMotorModel": "gz",
                      "ignition::gazebo::systems::MulticopterMotorModel": "gz"}


def motor_plugin_family(filename: str | None, name: str | None) -> str | None:
    """'rotors', 'px4' or 'gz' for a motor-model plugin (by its filename, or a gz system's
    class name), else None."""
    return MOTOR_PLUGINS.get(library_name(filename)) or MOTOR_PLUGIN_NAMES.get(name or "")


@dataclass
class Plugin:
    name: str | None
    filename: str | None
    node: XmlNode                  # the <plugin> element; parameters are its children
    loc: SourceLoc

    def param(self, tag: str) -> str | None:
        return self.node.findtext(tag)

    def param_loc(self, tag: str) -> SourceLoc:
        child = self.node.find(tag)
        return child.loc if child is not None else self.loc

    @property
    def library(self) -> str:
        """Library file name without directory, 'lib' prefix or '.so' suffix."""
        return library_name(self.filename)


@dataclass
class GazeboBlock:
    reference: str | None          # link or joint name, None for robot-level blocks
    loc: SourceLoc
    plugins: list[Plugin] = field(default_factory=list)
    elements: list[XmlNode] = field(default_factory=list)  # everything but plugins


# ---------------------------------------------------------------- robot

@dataclass
class ParseIssue:
    """Something the loader could not read as URDF; `validate` reports these as findings."""

    kind: str                      # e.g. "bad-number", "missing-attribute", "unknown-element"
    message: str
    loc: SourceLoc
    subject: str | None = None


@dataclass
class Robot:
    name: str
    loc: SourceLoc
    links: list[Link] = field(default_factory=list)
    joints: list[Joint] = field(default_factory=list)
    gazebo: list[GazeboBlock] = field(default_factory=list)
    parse_issues: list[ParseIssue] = field(default_factory=list)
    source_file: Path | None = None      # the file the user passed (URDF, xacro or SDF)
    source_format: str = "urdf"          # "urdf" (also from xacro) or "sdf": Gazebo converts
                                         # only the former, with fixed-joint lumping
    urdf_xml: str | None = None          # the URDF text the model was read from
    static: bool = False                 # SDF <static>: scenery Gazebo never moves (a
                                         # runway, a warehouse), not a vehicle

    # Lookups keep the first element of a name; duplicates stay visible in the lists.
    @cached_property
    def link_map(self) -> dict[str, Link]:
        out: dict[str, Link] = {}
        for link in self.links:
            out.setdefault(link.name, link)
        return out

    @cached_property
    def joint_map(self) -> dict[str, Joint]:
        out: dict[str, Joint] = {}
        for joint in self.joints:
            out.setdefault(joint.name, joint)
        return out

    def plugins(self) -> Iterator[tuple[GazeboBlock, Plugin]]:
        for block in self.gazebo:
            for plugin in block.plugins:
                yield block, plugin

    def root_links(self) -> list[str]:
        children = {j.child for j in self.joints}
        return [link.name for link in self.links if link.name not in children]

    @property
    def base_link(self) -> str:
        """The root link; the base frame of rotor positions and whole-robot properties.

        A URDF whose root is a massless `world`-like dummy connected by a fixed joint is
        common; the base frame is still the root, which is what Gazebo and Pinocchio use.
        """
        roots = self.root_links()
        if not roots:
            raise ValueError(f"robot '{self.name}' has no root link")
        return roots[0]
