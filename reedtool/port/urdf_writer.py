"""The ROS 2 form of a port (`migrate --urdf`): the original's links and joints as URDF, with
the port's gz-sim systems in `<gazebo>` elements, as `new-package --sim gz` writes them.

robot_state_publisher reads it for the TF tree; `ros_gz_sim create -file` (or `-topic
robot_description`) spawns it, and Gazebo's URDF conversion folds the massless fixed links
the way model.sdf has them folded. The links and joints are the original's, unfolded (a
massless root link keeps KDL quiet), written by io/urdf_write.py; the Classic `<gazebo>`
blocks are replaced by the port's. Meshes are referenced as `package://<name>/meshes/<file>`:
install the model directory as a ROS package named <name> (new-package --sim gz makes a
complete one).
"""

from __future__ import annotations

from lxml import etree

from reedtool.io.urdf_write import robot_element, urdf_bytes
from reedtool.port.gz_port import Element, GzPort
from reedtool.port.sdf_writer import to_xml


def ros2_urdf(robot, port: GzPort, mesh_uris: dict[str, str],
              extra_plugins: list[Element] = ()) -> bytes:
    def mesh_filename(mesh) -> str:
        target = mesh_uris[mesh.uri]
        if target.startswith("file://"):
            return target            # a file from outside, left where it is
        if target.startswith("../") and port.target_dir is not None:
            # package:// cannot climb out of the package: the same file, absolutely.
            from pathlib import Path

            return (Path(port.target_dir).absolute() / target).resolve().as_uri()
        return f"package://{port.name}/{target}"

    root = robot_element(robot, mesh_filename, name=port.name)
    root.insert(0, etree.Comment(f" {port.name}: the ROS 2 form of the gz-sim port written by "
                                 "reedtool migrate (model.sdf is the same model). "))
    gazebo = etree.SubElement(root, "gazebo")
    for plugin in [*port.plugins, *extra_plugins]:
        to_xml(plugin, gazebo)
    for link in port.links:
        if link.sensors:
            block = etree.SubElement(root, "gazebo", reference=link.name)
            for sensor in link.sensors:
                to_xml(sensor, block)
    return urdf_bytes(root)
