"""A RotorS-shaped repository in one `reedtool validate` run against `check_urdf` file by file.

    python benchmarks/bench_validate_many.py [--runs R] [--jobs J] [--keep DIR]

Target (issue 27, item 4): validating the repository in one run takes at most half the
wall time of check_urdf run on each of the same URDF files (check_urdf parses one file per
process; reedtool also resolves and reads every mesh and runs ~100 rules per model).

The repository is written here, in the shape of ethz-asl/rotors_simulator's
rotors_description (the numbers below were read from it; the geometry is generated):

- 11 expanded multirotor models (.urdf): quadrotors, hexacopters, an octocopter, one with
  a visual-inertial sensor mount, with RotorS's motor, IMU and odometry plugins; rotor
  counts 4-8, arms 0.13-0.4 m, masses 0.4-4 kg, all different robots;
- their COLLADA meshes: one body per model of 4,000-18,000 triangles (RotorS's bodies
  and core meshes hold 13,800-17,400, 1.1-1.3 MB with normals), written with a NORMAL
  input beside VERTEX (two indices per corner) and Y_UP as RotorS's exports are, some in
  millimetres with `<unit meter="0.001">`; two small propellers (200 and 300 triangles,
  as RotorS's propeller_cw/ccw.dae) shared by most models; two large propellers of
  15,000 triangles (as neo11's) used three times each by two models; an arm mesh (2,500
  triangles, as omav's tilt arm) used four times by the octocopter;
- 3 of the team's own URDFs with primitive shapes only.

Both sides run in turn (A B A B ...) R times after one unmeasured warm-up each; each
pair's ratio is taken and the median printed, for wall time and for CPU time (user +
sys of the child processes, from getrusage), which holds on a machine busy with other work.

Recorded (2-core machine shared with other work, load average 5-7; whole-process
figures, medians of 9 pairs after a warm-up, bytecode cached as in a user's install;
reedtool validate, one process, against check_urdf per file):

    reedtool                                               wall ratio   cpu ratio
    before (COLLADA numbers parsed word by word, normals
      too; a mesh read again by the inertia rules)           0.78x        0.68x
    now (index/position arrays parsed by numpy in C,
      normals skipped, each mesh read and measured once)     0.48x        0.49x

This script's own pairs printed 0.41x-0.47x wall and 0.50x-0.51x CPU in the same hour.
--jobs 2 on that machine: serial by the load cap (1.01x wall of --jobs 1); two workers
forced: 1.35x wall, 1.31x CPU (docs/validate.md).
"""

from __future__ import annotations

import argparse
import math
import os
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
BIN = Path(sys.executable).parent
USER_ENV = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
ROTORS_DESCRIPTION_PARENT = ROOT / "reedtool" / "ros_packages"
PACKAGE = "fleet_description"

# ------------------------------------------------------------------ meshes


def _ellipsoid(radii, segments: int, rings: int):
    """A closed UV ellipsoid: (positions, normals, triangles as position indices)."""
    theta = np.linspace(0.0, math.pi, rings + 1)[1:-1]
    phi = np.linspace(0.0, 2 * math.pi, segments, endpoint=False)
    t, p = np.meshgrid(theta, phi, indexing="ij")
    unit = np.stack([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)], -1).reshape(-1, 3)
    unit = np.vstack([[0, 0, 1], unit, [0, 0, -1]])
    positions = unit * np.asarray(radii, float)
    normals = unit / np.asarray(radii, float)
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    faces = []
    ring = lambda r, s: 1 + r * segments + s % segments   # noqa: E731 - index helper
    for s in range(segments):
        faces.append((0, ring(0, s), ring(0, s + 1)))
        last = rings - 2
        faces.append((len(unit) - 1, ring(last, s + 1), ring(last, s)))
    for r in range(rings - 2):
        for s in range(segments):
            a, b, c, d = ring(r, s), ring(r, s + 1), ring(r + 1, s), ring(r + 1, s + 1)
            faces += [(a, c, b), (b, c, d)]
    return positions, normals, np.asarray(faces, dtype=np.int64)


def _numbers(values, fmt: str) -> str:
    return " ".join(fmt % v for v in np.asarray(values).reshape(-1))


def write_dae(path: Path, radii_m, triangles: int, *, millimetres: bool = False,
              y_up: bool = True) -> int:
    """An exported mesh of about `triangles` triangles; returns its size in bytes."""
    rings = max(4, int(math.sqrt(triangles / 2)))
    segments = max(3, triangles // (2 * rings))
    positions, normals, faces = _ellipsoid(radii_m, segments, rings)
    if y_up:        # the file's up axis is y: Gazebo turns +y to +z
        positions, normals = positions[:, [0, 2, 1]] * [1, 1, -1], normals[:, [0, 2, 1]] * [1, 1, -1]
        faces = faces[:, ::-1]
    scale = 1000.0 if millimetres else 1.0
    # Each corner: its position index, then its normal index (RotorS's exports: offset 0
    # VERTEX, offset 1 NORMAL).
    corners = np.stack([faces, faces], axis=-1).reshape(-1)
    unit = '<unit name="millimeter" meter="0.001"/>' if millimetres else ""
    text = f"""<?xml version="1.0" encoding="utf-8"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
  <asset><contributor><authoring_tool>bench</authoring_tool></contributor>{unit}
    <up_axis>{'Y_UP' if y_up else 'Z_UP'}</up_axis></asset>
  <library_geometries><geometry id="body-mesh" name="body"><mesh>
    <source id="body-positions"><float_array id="body-positions-array" count="{positions.size}">{_numbers(positions * scale, '%.6g')}</float_array>
      <technique_common><accessor source="#body-positions-array" count="{len(positions)}" stride="3"><param name="X" type="float"/><param name="Y" type="float"/><param name="Z" type="float"/></accessor></technique_common></source>
    <source id="body-normals"><float_array id="body-normals-array" count="{normals.size}">{_numbers(normals, '%.6f')}</float_array>
      <technique_common><accessor source="#body-normals-array" count="{len(normals)}" stride="3"><param name="X" type="float"/><param name="Y" type="float"/><param name="Z" type="float"/></accessor></technique_common></source>
    <vertices id="body-vertices"><input semantic="POSITION" source="#body-positions"/></vertices>
    <triangles count="{len(faces)}"><input semantic="VERTEX" source="#body-vertices" offset="0"/><input semantic="NORMAL" source="#body-normals" offset="1"/>
      <p>{_numbers(corners, '%d')}</p></triangles>
  </mesh></geometry></library_geometries>
  <library_visual_scenes><visual_scene id="Scene" name="Scene"><node id="body" name="body">
    <matrix>1 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1</matrix><instance_geometry url="#body-mesh"/></node>
  </visual_scene></library_visual_scenes>
  <scene><instance_visual_scene url="#Scene"/></scene>
</COLLADA>
"""
    path.write_text(text)
    return len(text)


# ------------------------------------------------------------------ models

# name, rotors, arm (m), mass (kg), body half sizes (m), body triangles, body in mm, props,
# extra ("vi": a sensor mount with its camera mesh, "arms": the arm mesh on every arm)
MODELS = [
    ("quad_alpha", 4, 0.17, 0.72, (0.09, 0.09, 0.04), 8000, False, "small", ""),
    ("quad_bravo", 4, 0.13, 0.45, (0.06, 0.06, 0.03), 4200, True, "small", ""),
    ("quad_charlie", 4, 0.22, 1.52, (0.12, 0.08, 0.05), 18000, False, "small", ""),
    ("quad_delta", 4, 0.21, 1.00, (0.10, 0.10, 0.06), 13800, False, "small", ""),
    ("quad_echo", 4, 0.18, 0.42, (0.15, 0.15, 0.03), 6000, True, "small", ""),
    ("hexa_foxtrot", 6, 0.215, 1.50, (0.12, 0.12, 0.05), 16000, False, "small", ""),
    ("hexa_golf", 6, 0.215, 1.56, (0.12, 0.12, 0.05), 16000, False, "small", "vi"),
    ("hexa_hotel", 6, 0.30, 3.60, (0.16, 0.16, 0.07), 17400, False, "large", ""),
    ("hexa_india", 6, 0.26, 2.80, (0.14, 0.14, 0.06), 15000, True, "large", ""),
    ("octo_juliet", 8, 0.40, 4.00, (0.18, 0.18, 0.08), 17400, False, "small", "arms"),
    ("quad_kilo", 4, 0.19, 0.90, (0.10, 0.07, 0.05), 10000, False, "small", ""),
]


def _rotor(i: int, count: int, arm_m: float, prop_mesh: str, mass_kg: float) -> str:
    angle = math.radians(180.0 / count + 360.0 * i / count)
    direction = "ccw" if i % 2 == 0 else "cw"
    # Motor constant from the hover need: thrust-to-weight 2 at max_rot_velocity 838 rad/s.
    motor_constant = 2 * mass_kg * 9.81 / count / 838.0 ** 2
    return f"""
  <xacro:vertical_rotor robot_namespace="${{namespace}}" suffix="rotor{i}" direction="{direction}"
      motor_constant="{motor_constant:.6g}" moment_constant="0.016" parent="${{namespace}}/base_link"
      mass_rotor="0.005" radius_rotor="0.1" time_constant_up="0.0125" time_constant_down="0.025"
      max_rot_velocity="838" motor_number="{i}" rotor_drag_coefficient="8.06428e-05"
      rolling_moment_coefficient="1e-06" color="Blue" use_own_mesh="true"
      mesh="package://{PACKAGE}/meshes/{prop_mesh}_{direction}.dae">
    <origin xyz="{arm_m * math.cos(angle):.6f} {arm_m * math.sin(angle):.6f} 0.037" rpy="0 0 0"/>
    <xacro:box_inertia x="0.1" y="0.015" z="0.003" mass="${{0.005 * rotor_velocity_slowdown_sim}}"/>
  </xacro:vertical_rotor>"""


def _arm(i: int, count: int, arm_m: float) -> str:
    angle = 180.0 / count + 360.0 * i / count
    return f"""
  <link name="${{namespace}}/arm_{i}">
    <inertial><mass value="0.02"/><inertia ixx="2e-5" ixy="0" ixz="0" iyy="2e-4" iyz="0" izz="2e-4"/></inertial>
    <visual><geometry><mesh filename="package://{PACKAGE}/meshes/arm.dae" scale="1 1 1"/></geometry></visual>
  </link>
  <joint name="${{namespace}}/arm_{i}_joint" type="fixed">
    <origin xyz="{arm_m / 2 * math.cos(math.radians(angle)):.6f} {arm_m / 2 * math.sin(math.radians(angle)):.6f} 0" rpy="0 0 {math.radians(angle):.6f}"/>
    <parent link="${{namespace}}/base_link"/><child link="${{namespace}}/arm_{i}"/>
  </joint>"""


VI_SENSOR = f"""
  <xacro:sensor_mount link_name="${{namespace}}/vi_sensor_link" joint_name="${{namespace}}/vi_sensor_joint"
      parent_link="${{namespace}}/base_link" mass="0.13" size="0.05">
    <origin xyz="0.1 0 -0.03" rpy="0 0.2 0"/>
  </xacro:sensor_mount>
  <link name="${{namespace}}/vi_camera_link">
    <inertial><mass value="0.01"/><inertia ixx="1e-6" ixy="0" ixz="0" iyy="1e-6" iyz="0" izz="1e-6"/></inertial>
    <visual><geometry><mesh filename="package://{PACKAGE}/meshes/vi_camera.dae" scale="1 1 1"/></geometry></visual>
  </link>
  <joint name="${{namespace}}/vi_camera_joint" type="fixed">
    <origin xyz="0.015 0.055 0.0065" rpy="0 0 0"/>
    <parent link="${{namespace}}/vi_sensor_link"/><child link="${{namespace}}/vi_camera_link"/>
  </joint>"""


def _model_xacro(name, rotors, arm_m, mass_kg, half_m, props, extra) -> str:
    body = [2 * h for h in half_m]
    parts = "".join(_rotor(i, rotors, arm_m, props, mass_kg) for i in range(rotors))
    if extra == "arms":
        parts += "".join(_arm(i, rotors, arm_m) for i in range(rotors))
    if extra == "vi":
        parts += VI_SENSOR
    return f"""<?xml version="1.0"?>
<robot name="{name}" xmlns:xacro="http://ros.org/wiki/xacro">
  <xacro:arg name="namespace" default="{name}"/>
  <xacro:property name="namespace" value="$(arg namespace)"/>
  <xacro:property name="rotor_velocity_slowdown_sim" value="10"/>
  <xacro:include filename="$(find rotors_description)/urdf/multirotor_base.xacro"/>
  <xacro:include filename="$(find rotors_description)/urdf/component_snippets.xacro"/>
  <xacro:multirotor_base_macro robot_namespace="${{namespace}}" mass="{mass_kg}"
      body_width="{body[0]:.4f}" body_height="{body[2]:.4f}" use_mesh_file="true"
      mesh_file="package://{PACKAGE}/meshes/{name}.dae">
    <xacro:box_inertia x="{body[0]:.4f}" y="{body[1]:.4f}" z="{body[2]:.4f}" mass="{mass_kg}"/>
  </xacro:multirotor_base_macro>{parts}
  <xacro:ground_truth_imu_and_odometry namespace="${{namespace}}" parent_link="${{namespace}}/base_link"/>
</robot>
"""


def _own_urdf(name: str, arm_m: float, mass_kg: float) -> str:
    """A team's own hand-written quadrotor: primitive shapes, no meshes, no plugins."""
    ixx = mass_kg * (0.04 ** 2 + 0.2 ** 2) / 12
    links = [f"""  <link name="base_link">
    <inertial><mass value="{mass_kg}"/><inertia ixx="{ixx:.6g}" ixy="0" ixz="0" iyy="{ixx:.6g}" iyz="0" izz="{2 * ixx:.6g}"/></inertial>
    <visual><geometry><box size="0.2 0.2 0.04"/></geometry></visual>
    <collision><geometry><box size="0.2 0.2 0.04"/></geometry></collision>
  </link>"""]
    for i in range(4):
        angle = math.radians(45 + 90 * i)
        links.append(f"""  <link name="prop_{i}">
    <inertial><mass value="0.01"/><inertia ixx="1e-6" ixy="0" ixz="0" iyy="1e-5" iyz="0" izz="1e-5"/></inertial>
    <visual><geometry><cylinder radius="0.06" length="0.005"/></geometry></visual>
  </link>
  <joint name="prop_{i}_joint" type="continuous">
    <origin xyz="{arm_m * math.cos(angle):.5f} {arm_m * math.sin(angle):.5f} 0.03"/>
    <axis xyz="0 0 1"/><parent link="base_link"/><child link="prop_{i}"/>
  </joint>""")
    return f'<?xml version="1.0"?>\n<robot name="{name}">\n' + "\n".join(links) + "\n</robot>\n"


def write_repository(directory: Path) -> tuple[Path, list[Path], list[Path], int]:
    """(the URDFs' directory, the URDF files, package search dirs, COLLADA bytes)."""
    sys.path.insert(0, str(ROOT))
    from reedtool.io.loader import load_robot

    package = directory / "src" / PACKAGE
    meshes = package / "meshes"
    meshes.mkdir(parents=True)
    (package / "urdf").mkdir()
    (package / "package.xml").write_text(
        f'<?xml version="1.0"?>\n<package format="2"><name>{PACKAGE}</name>'
        "<version>0.0.0</version><description>benchmark</description>"
        '<maintainer email="a@b.c">a</maintainer><license>BSD</license></package>\n')
    size = 0
    size += write_dae(meshes / "small_cw.dae", (0.1, 0.012, 0.003), 200)
    size += write_dae(meshes / "small_ccw.dae", (0.1, 0.012, 0.003), 300)
    size += write_dae(meshes / "large_cw.dae", (0.13, 0.015, 0.004), 15000, millimetres=True)
    size += write_dae(meshes / "large_ccw.dae", (0.13, 0.015, 0.004), 15000, millimetres=True)
    size += write_dae(meshes / "arm.dae", (0.2, 0.015, 0.015), 2500)
    size += write_dae(meshes / "vi_camera.dae", (0.01, 0.01, 0.01), 340)
    package_dirs = [directory / "src", ROTORS_DESCRIPTION_PARENT]
    out = directory / "models"
    out.mkdir()
    files = []
    for name, rotors, arm_m, mass_kg, half_m, tris, mm, props, extra in MODELS:
        size += write_dae(meshes / f"{name}.dae", half_m, tris, millimetres=mm)
        xacro = package / "urdf" / f"{name}.xacro"
        xacro.write_text(_model_xacro(name, rotors, arm_m, mass_kg, half_m, props, extra))
        files.append(out / f"{name}.urdf")
        files[-1].write_text(load_robot(xacro, {}, package_dirs).urdf_xml)
    for i, (arm_m, mass_kg) in enumerate([(0.12, 0.6), (0.16, 0.9), (0.25, 1.8)]):
        files.append(out / f"own_{i}.urdf")
        files[-1].write_text(_own_urdf(f"own_{i}", arm_m, mass_kg))
    return out, files, package_dirs, size


def run_once(argv_list: list[list[str]]) -> tuple[float, float]:
    """(wall s, child CPU s) of running the processes one after the other."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    for argv in argv_list:
        subprocess.run(argv, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                       check=False, env=USER_ENV)
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return wall, cpu


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=5)
    parser.add_argument("--jobs", type=int, default=1, help="reedtool validate --jobs")
    parser.add_argument("--keep", type=Path, help="write the repository here and keep it")
    args = parser.parse_args()
    check_urdf = shutil.which("check_urdf", path=str(BIN)) or shutil.which("check_urdf")
    if check_urdf is None:
        print("check_urdf not found (pip install pin): no comparison")
        return 1
    with tempfile.TemporaryDirectory() as tmp:
        where = args.keep or Path(tmp)
        models, files, package_dirs, dae_bytes = write_repository(where)
        ours = [[str(BIN / "reedtool"), "validate", str(models),
                 *([f"--jobs={args.jobs}"] if args.jobs != 1 else []),
                 *[f"--package-path={d}" for d in package_dirs]]]
        theirs = [[check_urdf, str(f)] for f in files]
        if args.keep:
            print("reedtool:  ", " ".join(ours[0]))
            print("check_urdf:", check_urdf, "FILE  for each of", len(files), "files")
        run_once(ours)
        run_once(theirs)
        pairs = []
        for _ in range(args.runs):
            a, b = run_once(ours), run_once(theirs)
            pairs.append((a, b))
    med = statistics.median
    wall_a, cpu_a = med(a[0] for a, _ in pairs), med(a[1] for a, _ in pairs)
    wall_b, cpu_b = med(b[0] for _, b in pairs), med(b[1] for _, b in pairs)
    wall_ratio = med(a[0] / b[0] for a, b in pairs)
    cpu_ratio = med(a[1] / b[1] for a, b in pairs)
    print(f"{len(files)} URDF models ({len(MODELS)} RotorS-shaped with {dae_bytes / 1e6:.1f} MB "
          f"of COLLADA, 3 own), median of {args.runs} pairs "
          f"(reedtool validate --jobs {args.jobs} in one run | check_urdf per file)")
    print(f"  wall  {wall_a:7.3f} s | {wall_b:7.3f} s   ratio {wall_ratio:.2f}x")
    print(f"  cpu   {cpu_a:7.3f} s | {cpu_b:7.3f} s   ratio {cpu_ratio:.2f}x")
    ok = wall_ratio <= 0.5
    print(f"  target <= 0.5x (wall): {'ok' if ok else 'MISSED'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
