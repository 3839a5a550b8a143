"""A RotorS-style hexacopter (firefly-like) with resolvable COLLADA meshes, for benchmarks.

`write_case(directory)` writes a package `bench_hexa_description` (package.xml, urdf/,
meshes/*.dae) that includes the rotors_description bundled with reedtool, the way RotorS's
firefly.xacro does; returns (model path, package search dirs). The .dae files are
generated here: a body box and a propeller blade, exported in millimetres with
<unit meter="0.001"/> like the meshes RotorS and PX4 ship.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
ROTORS_DESCRIPTION_PARENT = ROOT / "reedtool" / "ros_packages"


def _box(size):
    half = np.asarray(size, float) / 2
    c = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)]) * half
    faces = [(0, 1, 3), (0, 3, 2), (4, 6, 7), (4, 7, 5), (0, 4, 5), (0, 5, 1),
             (2, 3, 7), (2, 7, 6), (0, 2, 6), (0, 6, 4), (1, 5, 7), (1, 7, 3)]
    return c[np.array(faces)]


def _dae(triangles) -> str:
    tri = np.asarray(triangles, float)
    n = len(tri) * 3
    floats = " ".join(f"{v:g}" for v in tri.reshape(-1))
    return f"""<?xml version="1.0" encoding="utf-8"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
  <asset><unit name="millimeter" meter="0.001"/><up_axis>Z_UP</up_axis></asset>
  <library_geometries><geometry id="g"><mesh>
    <source id="p"><float_array id="pa" count="{n * 3}">{floats}</float_array>
      <technique_common><accessor source="#pa" count="{n}" stride="3"/></technique_common></source>
    <vertices id="v"><input semantic="POSITION" source="#p"/></vertices>
    <triangles count="{len(tri)}"><input semantic="VERTEX" source="#v" offset="0"/>
      <p>{" ".join(map(str, range(n)))}</p></triangles>
  </mesh></geometry></library_geometries>
  <library_visual_scenes><visual_scene id="s"><node id="n"><instance_geometry url="#g"/></node>
  </visual_scene></library_visual_scenes>
  <scene><instance_visual_scene url="#s"/></scene>
</COLLADA>
"""


def _rotor(i: int, arm_m: float) -> str:
    angle = math.radians(30 + 60 * i)
    direction = "ccw" if i % 2 == 0 else "cw"
    return f"""
  <xacro:vertical_rotor robot_namespace="${{namespace}}" suffix="rotor{i}" direction="{direction}"
      motor_constant="8.54858e-06" moment_constant="0.016" parent="${{namespace}}/base_link"
      mass_rotor="0.005" radius_rotor="0.1" time_constant_up="0.0125" time_constant_down="0.025"
      max_rot_velocity="838" motor_number="{i}" rotor_drag_coefficient="8.06428e-05"
      rolling_moment_coefficient="1e-06" color="Blue" use_own_mesh="true"
      mesh="package://bench_hexa_description/meshes/prop_{direction}.dae">
    <origin xyz="{arm_m * math.cos(angle):.6f} {arm_m * math.sin(angle):.6f} 0.037" rpy="0 0 0"/>
    <xacro:box_inertia x="0.1" y="0.015" z="0.003" mass="${{0.005 * rotor_velocity_slowdown_sim}}"/>
  </xacro:vertical_rotor>"""


def write_case(directory: Path) -> tuple[Path, list[Path]]:
    package = Path(directory) / "bench_hexa_description"
    (package / "urdf").mkdir(parents=True, exist_ok=True)
    (package / "meshes").mkdir(exist_ok=True)
    (package / "package.xml").write_text(
        '<?xml version="1.0"?>\n<package format="2"><name>bench_hexa_description</name>'
        "<version>0.0.0</version><description>benchmark</description>"
        '<maintainer email="a@b.c">a</maintainer><license>BSD</license></package>\n')
    (package / "meshes" / "hexa.dae").write_text(_dae(_box((340, 340, 90))))
    for name in ("prop_ccw", "prop_cw"):
        (package / "meshes" / f"{name}.dae").write_text(_dae(_box((200, 18, 4))))
    rotors = "".join(_rotor(i, 0.215) for i in range(6))
    model = package / "urdf" / "bench_hexa.xacro"
    model.write_text(f"""<?xml version="1.0"?>
<robot name="bench_hexa" xmlns:xacro="http://ros.org/wiki/xacro">
  <xacro:arg name="namespace" default="bench_hexa"/>
  <xacro:property name="namespace" value="$(arg namespace)"/>
  <xacro:property name="rotor_velocity_slowdown_sim" value="10"/>
  <xacro:include filename="$(find rotors_description)/urdf/multirotor_base.xacro"/>
  <xacro:multirotor_base_macro robot_namespace="${{namespace}}" mass="1.5" body_width="0.34"
      body_height="0.09" use_mesh_file="true"
      mesh_file="package://bench_hexa_description/meshes/hexa.dae">
    <xacro:box_inertia x="0.34" y="0.34" z="0.09" mass="1.5"/>
  </xacro:multirotor_base_macro>{rotors}
</robot>
""")
    return model, [Path(directory), ROTORS_DESCRIPTION_PARENT]


def write_ament_index_shim(directory: Path, package_dirs: list[Path]) -> Path:
    """A stand-in `ament_index_python` (what a sourced ROS 2 workspace provides) so the pip
    `xacro` resolves $(find PKG) among `package_dirs`; put the returned dir on PYTHONPATH."""
    shim = Path(directory) / "ament_shim" / "ament_index_python"
    shim.mkdir(parents=True, exist_ok=True)
    roots = [str(p) for p in package_dirs]
    (shim / "__init__.py").write_text(f"""import os
ROOTS = {roots!r}


class PackageNotFoundError(KeyError):
    pass


def get_package_share_directory(name, print_warning=True):
    for root in ROOTS:
        if os.path.isfile(os.path.join(root, name, "package.xml")):
            return os.path.join(root, name)
    raise PackageNotFoundError(name)
""")
    (shim / "packages.py").write_text("from ament_index_python import *  # noqa\n")
    return shim.parent
