"""Mesh references (S115, S130, S131), mesh units (I206/I210), zero mass (I207/I208) and the
headline cases of issue 13: each exits 1 from `validate` and from `inertia`.

Models and meshes are written into tmp_path here; sizes are hand-derived.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from cli_helpers import run_cli
from mesh_helpers import box_triangles, dae_text, write_dae, write_obj, write_stl

from reedtool.checks.runner import Selection, run_checks
from reedtool.io.loader import load_robot

TESTS = Path(__file__).parent
SMARTCAR = (TESTS / "fixtures" / "smartcar" / "fixed" / "smartcar_description" / "urdf"
            / "smartcar.urdf.xacro")

# A 0.4 x 0.3 x 0.1 m, 1.5 kg body: solid-box inertia m (b^2 + c^2) / 12 ...
M, SIZE = 1.5, (0.4, 0.3, 0.1)
IXX, IYY, IZZ = (M * (SIZE[1] ** 2 + SIZE[2] ** 2) / 12, M * (SIZE[0] ** 2 + SIZE[2] ** 2) / 12,
                 M * (SIZE[0] ** 2 + SIZE[1] ** 2) / 12)


def body_urdf(visuals: list[str], *, collision: str = '<box size="0.4 0.3 0.1"/>',
              mass: float = M, inertia=(IXX, IYY, IZZ), plugin: str = "") -> str:
    visual_xml = "".join(f"<visual><geometry>{v}</geometry></visual>" for v in visuals)
    ixx, iyy, izz = inertia
    return f"""<?xml version="1.0"?>
<robot name="body">
  <link name="base_link">
    <inertial><mass value="{mass}"/>
      <inertia ixx="{ixx}" ixy="0" ixz="0" iyy="{iyy}" iyz="0" izz="{izz}"/></inertial>
    {visual_xml}
    <collision><geometry>{collision}</geometry></collision>
  </link>{plugin}
</robot>
"""


def write_model(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "model.urdf"
    path.write_text(text)
    return path


def codes(path: Path) -> list[str]:
    return sorted(f.code for f in run_checks(load_robot(path)))


def exits(path: Path) -> tuple[int, int]:
    """(validate exit, inertia exit)."""
    return run_cli("validate", path)[0], run_cli("inertia", path)[0]


# ------------------------------------------------------------------ the crash


def test_two_visuals_sharing_one_mesh_do_not_crash(tmp_path):
    """x500_base's shape: the same mesh file in two visuals (and scale arrays on both)."""
    write_stl(tmp_path / "body.stl", box_triangles(SIZE))
    mesh = '<mesh filename="body.stl" scale="1 1 1"/>'
    path = write_model(tmp_path, body_urdf([mesh, mesh], collision=mesh))
    assert codes(path) == []
    assert exits(path) == (0, 0)


# ------------------------------------------------------------------ formats and URIs


@pytest.mark.parametrize("name", ["body.STEP", "body.SLDPRT", "body"])
def test_cad_formats_are_errors(tmp_path, name):
    (tmp_path / name).write_bytes(b"ISO-10303-21;\n")
    path = write_model(tmp_path, body_urdf([f'<mesh filename="{name}"/>']))
    assert codes(path) == ["S130"]
    assert exits(path) == (1, 1)


def test_upper_case_stl_is_an_stl(tmp_path):
    write_stl(tmp_path / "body.STL", box_triangles(SIZE))
    assert codes(write_model(tmp_path, body_urdf(['<mesh filename="body.STL"/>']))) == []


GZ_PLUGIN = ('<gazebo><plugin filename="gz-sim-joint-state-publisher-system" '
             'name="gz::sim::systems::JointStatePublisher"/></gazebo>')
CLASSIC_PLUGIN = ('<gazebo><plugin filename="libgazebo_ros_joint_state_publisher.so" '
                  'name="jsp"/></gazebo>')


def test_glb_is_for_gz_sim_only(tmp_path):
    (tmp_path / "body.glb").write_bytes(b"glTF")
    mesh = '<mesh filename="body.glb"/>'
    assert codes(write_model(tmp_path, body_urdf([mesh], plugin=GZ_PLUGIN))) == []
    assert codes(write_model(tmp_path, body_urdf([mesh], plugin=CLASSIC_PLUGIN))) == ["S130"]


@pytest.mark.parametrize("uri", ["package://pkg/../../../etc/passwd", "file:///etc/passwd",
                                 "/proc/self/environ", "package://pkg/meshes/../../x.stl"])
def test_uri_leaving_its_package_or_into_system_files(tmp_path, uri):
    path = write_model(tmp_path, body_urdf([f'<mesh filename="{uri}"/>']))
    assert codes(path) == ["S131"]
    # Gazebo follows such a path on this machine: a warning (reedtool does not open it),
    # so the run passes unless --strict.
    assert exits(path) == (0, 0)
    assert run_cli("validate", path, "--strict")[0] == 1


def test_dots_inside_the_package_are_fine(tmp_path):
    package = tmp_path / "pkg"
    (package / "meshes").mkdir(parents=True)
    (package / "urdf").mkdir()
    (package / "package.xml").write_text("<package><name>pkg</name></package>")
    write_stl(package / "meshes" / "body.stl", box_triangles(SIZE))
    path = write_model(tmp_path, body_urdf(['<mesh filename="package://pkg/urdf/../meshes/body.stl"/>']))
    found = run_checks(load_robot(path, package_paths=[tmp_path]))
    assert sorted(f.code for f in found) == []


@pytest.mark.parametrize("name, content", [
    ("body.dae", b"<COLLADA><asset>"),                                    # truncated XML
    ("body.dae", dae_text(box_triangles(SIZE)).replace("<p>0 1 2", "<p>0 1 999").encode()),
    ("body.stl", b"solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 zz\n"),
    ("body.obj", b"v 0 0 0\nv 1 0 0\nf 1 2 7\n"),
])
def test_corrupt_mesh_content_is_an_error(tmp_path, name, content):
    (tmp_path / name).write_bytes(content)
    path = write_model(tmp_path, body_urdf([f'<mesh filename="{name}"/>']))
    assert codes(path) == ["S115"]


# ------------------------------------------------------------------ units


WING_MM = (1530.0, 200.0, 30.0)  # a 1.53 m wing exported in millimetres


def test_dae_wing_in_mm_with_its_unit_is_quiet(tmp_path):
    write_dae(tmp_path / "wing.dae", box_triangles(WING_MM), meter=0.001)
    path = write_model(tmp_path, body_urdf(['<mesh filename="wing.dae"/>']))
    assert codes(path) == []
    assert exits(path) == (0, 0)


def test_dae_really_in_mm_is_found(tmp_path):
    write_dae(tmp_path / "wing.dae", box_triangles(WING_MM), meter=1.0)
    path = write_model(tmp_path, body_urdf(['<mesh filename="wing.dae"/>']))
    findings = run_checks(load_robot(path))
    assert [f.code for f in findings] == ["I210"]
    assert "1530 m across" in findings[0].message
    assert exits(path) == (1, 1)


def test_stl_body_in_mm_is_an_error_in_validate_and_inertia(tmp_path):
    write_stl(tmp_path / "body.stl", box_triangles(np.array(SIZE) * 1000))
    path = write_model(tmp_path, body_urdf(['<mesh filename="body.stl"/>']))
    assert codes(path) == ["I210"]
    assert exits(path) == (1, 1)


def test_obj_is_read_as_metres(tmp_path):
    write_obj(tmp_path / "body.obj", box_triangles(SIZE))
    assert codes(write_model(tmp_path, body_urdf(['<mesh filename="body.obj"/>']))) == []
    write_obj(tmp_path / "body.obj", box_triangles(np.array(SIZE) * 1000))
    assert codes(write_model(tmp_path, body_urdf(['<mesh filename="body.obj"/>']))) == ["I210"]


def test_a_large_mesh_on_a_large_robot_is_only_a_warning(tmp_path):
    """30 m across, the robot's own box 1 m: 30x, inside the 50x certainty margin -> I206."""
    write_stl(tmp_path / "plane.stl", box_triangles((30.0, 30.0, 0.1)))
    path = write_model(tmp_path, body_urdf(['<mesh filename="plane.stl"/>'],
                                           collision='<box size="1 0.3 0.1"/>',
                                           inertia=(M * (0.09 + 0.01) / 12, M * 1.01 / 12,
                                                    M * 1.09 / 12)))
    assert codes(path) == ["I206"]
    assert exits(path) == (0, 0)


def test_mesh_as_inertia_geometry_uses_the_dae_unit(tmp_path):
    """`inertia` on a mesh-only link: the 0.001 unit gives the box tensor, hand-derived."""
    write_dae(tmp_path / "body.dae", box_triangles(np.array(SIZE) * 1000), meter=0.001)
    path = write_model(tmp_path, body_urdf(['<mesh filename="body.dae"/>'],
                                           collision='<mesh filename="body.dae"/>'))
    from reedtool.physics.inertia import compare_links

    (comparison,) = compare_links(load_robot(path))
    assert comparison.verdict == "ok"
    # Mesh integral of a box vs the box formula: exact up to rounding of the sums
    # (~1e-15); 1e-9 is margin.
    assert np.diag(comparison.derived.inertia_kg_m2) == pytest.approx([IXX, IYY, IZZ], rel=1e-9)


# ------------------------------------------------------------------ mass


def test_zero_whole_robot_mass_is_an_error(tmp_path):
    for mass in ("0", "-0.0"):
        path = write_model(tmp_path, body_urdf([], mass=mass))
        assert codes(path) == ["I207", "I208"]
        assert exits(path) == (1, 1)


def test_massless_frame_with_zero_inertia_stays_quiet(tmp_path):
    text = body_urdf([]).replace("</robot>", """
  <joint name="cam_joint" type="fixed"><parent link="base_link"/><child link="cam"/></joint>
  <link name="cam"><inertial><mass value="0"/>
    <inertia ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0"/></inertial></link>
</robot>""")
    assert codes(write_model(tmp_path, text)) == []


# ------------------------------------------------------------------ seed 001


def test_seed_001_inertias_exit_1_from_validate_and_inertia():
    findings = run_checks(load_robot(SMARTCAR), Selection(select=("I2",)))
    wheels = {f.subject for f in findings if f.code == "I209" and f.severity == "error"}
    assert {w for w in wheels if w.endswith("_wheel")} == {
        "left_front_wheel", "right_front_wheel", "left_back_wheel", "right_back_wheel"}
    assert run_cli("inertia", SMARTCAR)[0] == 1


def test_workspace_dirs_are_not_system_dirs():
    from reedtool.resolve.references import uri_problem

    for uri in ("file:///root/ws/src/pkg/meshes/a.stl", "/var/lib/jenkins/ws/meshes/a.dae",
                "file:///opt/ros/noetic/share/pkg/meshes/a.dae", "/usr/share/pkg/a.obj"):
        assert uri_problem(uri) is None, uri
    assert uri_problem("file:///etc/../etc/passwd") is not None
    assert uri_problem("package://pkg/meshes/a.stl", Path("/etc/passwd")) is not None


def test_x500_shaped_sdf_two_visuals_one_mesh(tmp_path):
    """PX4 x500_base: base_link with two visuals naming the same COLLADA file (in mm with
    its unit), SDF with gz-sim systems; quiet, no crash."""
    write_dae(tmp_path / "base.dae", box_triangles((470, 470, 120)), meter=0.001)
    ixx = 2.0 * (0.47 ** 2 + 0.12 ** 2) / 12
    izz = 2.0 * (0.47 ** 2 + 0.47 ** 2) / 12
    (tmp_path / "model.sdf").write_text(f"""<?xml version="1.0"?>
<sdf version="1.9"><model name="x500_like">
  <link name="base_link">
    <inertial><mass>2.0</mass><inertia><ixx>{ixx}</ixx><iyy>{ixx}</iyy><izz>{izz}</izz>
      <ixy>0</ixy><ixz>0</ixz><iyz>0</iyz></inertia></inertial>
    <visual name="body"><geometry><mesh><uri>base.dae</uri><scale>1 1 1</scale></mesh></geometry></visual>
    <visual name="body_shadow"><pose>0 0 0.001 0 0 0</pose>
      <geometry><mesh><uri>base.dae</uri><scale>1 1 1</scale></mesh></geometry></visual>
    <collision name="c"><geometry><box><size>0.47 0.47 0.12</size></box></geometry></collision>
  </link>
  <plugin filename="gz-sim-joint-state-publisher-system"
          name="gz::sim::systems::JointStatePublisher"/>
</model></sdf>
""")
    assert codes(tmp_path / "model.sdf") == []


def test_unreadable_mass_is_s101_only(tmp_path):
    """<mass value="one">: the 0 the reader keeps is a default, not a declared zero."""
    path = write_model(tmp_path, body_urdf([], mass="one"))
    assert codes(path) == ["S101"]
