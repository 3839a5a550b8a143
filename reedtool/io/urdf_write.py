"""URDF writing, the pair of io/urdf.py: a `Robot`, or one of its parts, as URDF elements.

Every URDF reedtool produces is built here with lxml: the URDF equivalent of an SDF model
(io/sdf.py, what Pinocchio and yourdfpy read), the ROS 2 form of a gz port
(port/urdf_writer.py) and the <inertial> that `inertia --fix` splices into a user's file
(io/urdf_edit.py). Numbers go through one formatter per use (io/xml_numbers.py): the
shortest round-trip text for generated files, ten digits for a user's own file.

Limits follow urdfdom: `inf` is refused there, so "no limit" is written as -+1e16
(io/limits.py); an absent lower/upper stays absent (urdfdom reads 0, as the source did); a
continuous joint without an effort or velocity limit gets no <limit>.
"""

from __future__ import annotations

from typing import Callable

import numpy as np
from lxml import etree

from reedtool.io.limits import is_no_limit, urdf_limit_text
from reedtool.io.xml_numbers import clean_tensor, float_text, pose_values, short_text, vector_text
from reedtool.model import inertia_values

Number = Callable[[float], str]
# What a mesh is called in the written file (None: the shape is left out).
MeshFilename = Callable[[object], "str | None"]

LIMITED_TYPES = ("revolute", "prismatic", "continuous")


def _sub(parent, tag: str, **attrib: str):
    return etree.Element(tag, attrib) if parent is None else \
        etree.SubElement(parent, tag, attrib)


def origin_element(parent, T: np.ndarray, number: Number = float_text):
    xyz, rpy = pose_values(T)
    return _sub(parent, "origin", xyz=vector_text(xyz, number), rpy=vector_text(rpy, number))


def inertial_element(parent, mass_kg: float, T_link_com: np.ndarray, inertia_kg_m2,
                     number: Number = float_text):
    """<inertial>: the COM frame as <origin>, <mass>, the tensor about the COM in that frame."""
    node = _sub(parent, "inertial")
    origin_element(node, T_link_com, number)
    _sub(node, "mass", value=number(mass_kg))
    _sub(node, "inertia", **inertia_attributes(inertia_kg_m2, number))
    return node


def inertia_attributes(inertia_kg_m2, number: Number = float_text) -> dict[str, str]:
    """The six attributes of <inertia> for a 3x3 tensor."""
    return {key: number(value) for key, value in inertia_values(inertia_kg_m2).items()}


def inertia_text(inertia_kg_m2) -> str:
    """<inertia .../> as a person reads it (ten digits, round-off entries as 0), spliced
    into a user's xacro file in the layout xacro files use (a space before `/>`)."""
    attributes = inertia_attributes(clean_tensor(inertia_kg_m2), short_text)
    return "<inertia " + " ".join(f'{key}="{value}"' for key, value in attributes.items()) + " />"


def inertial_text(mass_kg: float, com_m, inertia_kg_m2, indent: str = "  ") -> str:
    """<inertial> as a person reads it, for a user's own file or to paste: COM origin with
    no rotation, ten significant digits, round-off entries of the tensor written as 0.
    Every line starts with `indent`."""
    T_link_com = np.eye(4)
    T_link_com[:3, 3] = np.asarray(com_m, dtype=float)
    element = inertial_element(None, mass_kg, T_link_com, clean_tensor(inertia_kg_m2),
                               short_text)
    return indent + element_text(element, indent)


def geometry_element(parent, geometry, mesh_filename: MeshFilename,
                     number: Number = float_text):
    """<geometry> of a box, cylinder, sphere or mesh; None (nothing added) for any other
    shape or a mesh `mesh_filename` has no name for."""
    from reedtool.model import Box, Cylinder, Mesh, Sphere

    if isinstance(geometry, Box):
        shape = ("box", {"size": vector_text(geometry.size_m, number)})
    elif isinstance(geometry, Cylinder):
        shape = ("cylinder", {"radius": number(geometry.radius_m),
                              "length": number(geometry.length_m)})
    elif isinstance(geometry, Sphere):
        shape = ("sphere", {"radius": number(geometry.radius_m)})
    elif isinstance(geometry, Mesh) and (filename := mesh_filename(geometry)) is not None:
        shape = ("mesh", {"filename": filename, "scale": vector_text(geometry.scale, number)})
    else:
        return None
    node = _sub(parent, "geometry")
    _sub(node, shape[0], **shape[1])
    return node


def link_element(parent, link, mesh_filename: MeshFilename, number: Number = float_text):
    """<link>: its inertial, then its visuals and collisions (a shape URDF cannot hold is
    left out)."""
    node = _sub(parent, "link", name=link.name)
    if link.inertial is not None:
        inertial = link.inertial
        inertial_element(node, inertial.mass_kg, inertial.T_link_com, inertial.inertia_kg_m2,
                         number)
    for kind, shapes in (("visual", link.visuals), ("collision", link.collisions)):
        for shape in shapes:
            element = etree.Element(kind)
            origin_element(element, shape.T_link_geom, number)
            if geometry_element(element, shape.geometry, mesh_filename, number) is not None:
                node.append(element)
    return node


def joint_element(parent, joint, number: Number = float_text):
    """<joint>: origin, parent, child, axis (not for a fixed joint) and its limit."""
    node = _sub(parent, "joint", name=joint.name, type=joint.type)
    origin_element(node, joint.T_parent_joint, number)
    _sub(node, "parent", link=joint.parent)
    _sub(node, "child", link=joint.child)
    if joint.type != "fixed":
        _sub(node, "axis", xyz=vector_text(joint.axis, number))
    if joint.limit is not None and joint.type in LIMITED_TYPES:
        limit = joint.limit
        # urdfdom requires <limit> of a revolute or prismatic joint; a continuous one has
        # no position limit and carries the element only for a real effort/velocity limit.
        tags = ("lower", "upper", "effort", "velocity")
        if joint.type == "continuous":
            tags = ("effort", "velocity")
            if all(is_no_limit(getattr(limit, tag)) for tag in tags):
                return node
        attrs = {tag: text for tag in tags
                 if (text := urdf_limit_text(tag, getattr(limit, tag), number)) is not None}
        _sub(node, "limit", **attrs)
    return node


def robot_element(robot, mesh_filename: MeshFilename, name: str | None = None,
                  number: Number = float_text):
    """<robot> with every link and every joint that names both its links."""
    root = etree.Element("robot", name=name or robot.name)
    for link in robot.links:
        link_element(root, link, mesh_filename, number)
    for joint in robot.joints:
        if joint.parent is not None and joint.child is not None:
            joint_element(root, joint, number)
    return root


def element_text(element, indent: str = "") -> str:
    """An element as indented text (two spaces a level), every line after the first
    prefixed with `indent` so it sits where it is spliced."""
    etree.indent(element, space="  ")
    text = etree.tostring(element, encoding="unicode")
    return text.replace("\n", "\n" + indent) if indent else text


def urdf_bytes(root) -> bytes:
    """A whole URDF document: declaration, indented, UTF-8."""
    etree.indent(root, space="  ")
    return etree.tostring(root, xml_declaration=True, encoding="utf-8", pretty_print=True)


def equivalent_urdf(robot) -> str:
    """A URDF with the same links, inertials, geometry and joints as `robot` (read from
    an SDF): what Pinocchio and yourdfpy read. Meshes by their resolved path."""
    root = robot_element(robot, lambda mesh: str(mesh.path) if mesh.path is not None else None)
    return element_text(root) + "\n"
