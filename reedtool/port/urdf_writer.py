"""The ROS 2 form of a port (`migrate --urdf`): the original's links and joints as URDF, with
the port's gz-sim systems in `<gazebo>` elements, as `new-package --sim gz` writes them.

robot_state_publisher reads it for the TF tree; `ros_gz_sim create -file` (or `-topic
robot_description`) spawns it, and Gazebo's URDF conversion folds the massless fixed links
the way model.sdf has them folded. The links and joints are the original's, unfolded (a
massless root link keeps KDL quiet); the Classic `<gazebo>` blocks are replaced by the
port's. Meshes are referenced as `package://<name>/meshes/<file>`: install the model
directory as a ROS package named <name> (new-package --sim gz makes a complete one).
"""

from __future__ import annotations

import numpy as np
from lxml import etree

from reedtool.port.gz_port import Element, GzPort, float_text
from reedtool.port.sdf_writer import to_xml


def _origin(parent, T: np.ndarray) -> None:
    from reedtool.frames import matrix_to_rpy

    etree.SubElement(parent, "origin", xyz=" ".join(float_text(v) for v in T[:3, 3]),
                     rpy=" ".join(float_text(v) for v in matrix_to_rpy(T[:3, :3])))


def _geometry(parent, geometry, mesh_uri) -> bool:
    from reedtool.model import Box, Cylinder, Mesh, Sphere

    node = etree.SubElement(parent, "geometry")
    if isinstance(geometry, Box):
        etree.SubElement(node, "box", size=" ".join(float_text(v) for v in geometry.size_m))
    elif isinstance(geometry, Cylinder):
        etree.SubElement(node, "cylinder", radius=float_text(geometry.radius_m),
                         length=float_text(geometry.length_m))
    elif isinstance(geometry, Sphere):
        etree.SubElement(node, "sphere", radius=float_text(geometry.radius_m))
    elif isinstance(geometry, Mesh):
        etree.SubElement(node, "mesh", filename=mesh_uri(geometry.uri),
                         scale=" ".join(float_text(v) for v in geometry.scale))
    else:
        return False
    return True


def ros2_urdf(robot, port: GzPort, mesh_uris: dict[str, str],
              extra_plugins: list[Element] = ()) -> bytes:
    root = etree.Element("robot", name=port.name)
    root.append(etree.Comment(f" {port.name}: the ROS 2 form of the gz-sim port written by "
                              "reedtool migrate (model.sdf is the same model). "))

    def mesh_uri(uri: str) -> str:
        target = mesh_uris[uri]
        if target.startswith("file://"):
            return target            # a file from outside, left where it is
        if target.startswith("../") and port.target_dir is not None:
            # package:// cannot climb out of the package: the same file, absolutely.
            from pathlib import Path

            return (Path(port.target_dir).absolute() / target).resolve().as_uri()
        return f"package://{port.name}/{target}"

    for link in robot.links:
        node = etree.SubElement(root, "link", name=link.name)
        if link.inertial is not None:
            inertial = etree.SubElement(node, "inertial")
            _origin(inertial, link.inertial.T_link_com)
            etree.SubElement(inertial, "mass", value=float_text(link.inertial.mass_kg))
            I = link.inertial.inertia_kg_m2
            etree.SubElement(inertial, "inertia", ixx=float_text(I[0, 0]), ixy=float_text(I[0, 1]),
                             ixz=float_text(I[0, 2]), iyy=float_text(I[1, 1]), iyz=float_text(I[1, 2]),
                             izz=float_text(I[2, 2]))
        for kind, shapes in (("visual", link.visuals), ("collision", link.collisions)):
            for shape in shapes:
                if shape.geometry is None:
                    continue
                element = etree.SubElement(node, kind)
                _origin(element, shape.T_link_geom)
                if not _geometry(element, shape.geometry, mesh_uri):
                    node.remove(element)
    for joint in robot.joints:
        node = etree.SubElement(root, "joint", name=joint.name, type=joint.type)
        _origin(node, joint.T_parent_joint)
        etree.SubElement(node, "parent", link=joint.parent)
        etree.SubElement(node, "child", link=joint.child)
        if joint.type != "fixed":
            etree.SubElement(node, "axis", xyz=" ".join(float_text(v) for v in joint.axis))
        if joint.limit is not None and joint.type in ("revolute", "prismatic"):
            limit = joint.limit
            attrs = {key: float_text(value) for key, value in (
                ("lower", limit.lower), ("upper", limit.upper), ("effort", limit.effort),
                ("velocity", limit.velocity)) if value is not None}
            etree.SubElement(node, "limit", attrs)
    gazebo = etree.SubElement(root, "gazebo")
    for plugin in [*port.plugins, *extra_plugins]:
        to_xml(plugin, gazebo)
    for link in port.links:
        if link.sensors:
            block = etree.SubElement(root, "gazebo", reference=link.name)
            for sensor in link.sensors:
                to_xml(sensor, block)
    etree.indent(root, space="  ")
    return etree.tostring(root, xml_declaration=True, encoding="utf-8", pretty_print=True)
