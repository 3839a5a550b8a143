"""SDF writing, the pair of io/sdf.py: the elements every SDF reedtool writes is made of.

The gz port's model.sdf and world (port/sdf_writer.py) and PX4's world
(port/px4_gz_contract.py) are built from these with lxml. Numbers are written with the
shortest text that reads back as the same float (io/xml_numbers.py), so reading a written
file gives the numbers back; "no limit" as sdformat spells it (io/limits.py).
"""

from __future__ import annotations

from typing import Callable

import numpy as np
from lxml import etree

from reedtool.io.xml_numbers import float_text, pose_values, vector_text
from reedtool.model import inertia_values

SDF_VERSION = "1.9"


def sub(parent, tag: str, text: object | None = None, **attrib: str):
    """A child element with its text (None: empty) and attributes."""
    node = etree.SubElement(parent, tag, attrib)
    if text is not None:
        node.text = str(text)
    return node


def pose_text(T: np.ndarray) -> str:
    """A 4x4 transform as SDF `<pose>` text: x y z roll pitch yaw, each as `float_text`."""
    xyz, rpy = pose_values(T)
    return f"{vector_text(xyz)} {vector_text(rpy)}"


def inertial_element(parent, mass_kg: float, T_link_com: np.ndarray, inertia_kg_m2):
    """<inertial>: the COM frame as <pose>, <mass>, the tensor about the COM in that frame."""
    node = sub(parent, "inertial")
    sub(node, "pose", pose_text(T_link_com))
    sub(node, "mass", float_text(mass_kg))
    tensor = sub(node, "inertia")
    for key, value in inertia_values(inertia_kg_m2).items():
        sub(tensor, key, float_text(value))
    return node


def geometry_element(parent, geometry, mesh_uri: Callable[[object], str]):
    """<geometry> of a box, cylinder, sphere or mesh (its <uri> from `mesh_uri`, <scale>
    only when not 1 1 1); an empty <geometry> for any other shape."""
    from reedtool.model import Box, Cylinder, Mesh, Sphere

    node = sub(parent, "geometry")
    if isinstance(geometry, Box):
        sub(sub(node, "box"), "size", vector_text(geometry.size_m))
    elif isinstance(geometry, Cylinder):
        cylinder = sub(node, "cylinder")
        sub(cylinder, "radius", float_text(geometry.radius_m))
        sub(cylinder, "length", float_text(geometry.length_m))
    elif isinstance(geometry, Sphere):
        sub(sub(node, "sphere"), "radius", float_text(geometry.radius_m))
    elif isinstance(geometry, Mesh):
        mesh = sub(node, "mesh")
        sub(mesh, "uri", mesh_uri(geometry))
        if not np.array_equal(geometry.scale, np.ones(3)):
            sub(mesh, "scale", vector_text(geometry.scale))
    return node


# ------------------------------------------------------------------ a world's parts

def physics_element(world, max_step_size_s: str = "0.004"):
    """<physics> stepping 4 ms at real time: the rate of gz-sim's multicopter examples and
    of PX4's default world (its IMU and lockstep expect 250 Hz)."""
    physics = sub(world, "physics", name="4ms", type="ignored")
    sub(physics, "max_step_size", max_step_size_s)
    sub(physics, "real_time_factor", "1.0")
    return physics


def sun_element(world):
    """The directional light gz-sim's example worlds have."""
    light = sub(world, "light", type="directional", name="sun")
    sub(light, "cast_shadows", "true")
    sub(light, "pose", "0 0 10 0 0 0")
    sub(light, "diffuse", "0.8 0.8 0.8 1")
    sub(light, "direction", "-0.5 0.1 -0.9")
    return light


def ground_plane_element(world):
    """A static 100 m x 100 m ground plane (collision and visual)."""
    ground = sub(world, "model", name="ground_plane")
    sub(ground, "static", "true")
    link = sub(ground, "link", name="link")
    for kind in ("collision", "visual"):
        plane = sub(sub(sub(link, kind, name=kind), "geometry"), "plane")
        sub(plane, "normal", "0 0 1")
        sub(plane, "size", "100 100")
    return ground


def sdf_bytes(root) -> bytes:
    """A whole document (SDF, or model.config): declaration, indented, UTF-8."""
    etree.indent(root, space="  ")
    return etree.tostring(root, xml_declaration=True, encoding="utf-8", pretty_print=True)
