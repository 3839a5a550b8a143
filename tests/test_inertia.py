"""Mass properties against textbook formulas, trimesh, hand sums and Pinocchio."""

from pathlib import Path

import numpy as np
import pytest
import trimesh
from hypothesis import given, settings
from hypothesis import strategies as st

from reedtool.errors import ReedtoolError
from reedtool.frames import make_T, rpy_to_matrix
from reedtool.io.stl import read_stl
from reedtool.model import Box, Cylinder, Inertial, Link, Mesh, SourceLoc, Sphere
from reedtool.physics.inertia import (
    MassProperties,
    box_inertia,
    combine,
    compare_link,
    cylinder_inertia,
    declared_mass_properties,
    geometry_mass_properties,
    inertial_xml,
    mesh_mass_properties,
    physically_valid,
    solid_mass_properties,
    sphere_inertia,
    whole_robot,
)

EXAMPLES = Path(__file__).parents[1] / "meshes"
FIXTURES = Path(__file__).parent / "fixtures"
LOC = SourceLoc("test.urdf", 1)


def rel_close(a, b, rel):
    a, b = np.asarray(a, float), np.asarray(b, float)
    return np.max(np.abs(a - b)) <= rel * np.max(np.abs(b))


# ---------------------------------------------------------------- primitives

def test_box_textbook():
    m, (a, b, c) = 2.5, (0.3, 0.2, 0.1)
    expected = np.diag([m * (b**2 + c**2) / 12, m * (a**2 + c**2) / 12, m * (a**2 + b**2) / 12])
    assert rel_close(box_inertia(m, (a, b, c)), expected, 1e-12)


@pytest.mark.parametrize("axis", ["x", "y", "z"])
def test_cylinder_textbook_each_axis(axis):
    m, r, h = 0.7, 0.04, 0.15
    axial, transverse = m * r**2 / 2, m * (3 * r**2 + h**2) / 12
    expected = np.diag([axial if axis == a else transverse for a in "xyz"])
    assert rel_close(cylinder_inertia(m, r, h, axis), expected, 1e-12)


def test_sphere_textbook():
    assert rel_close(sphere_inertia(3.0, 0.2), np.eye(3) * 2 / 5 * 3.0 * 0.04, 1e-12)


def test_cylinder_rejects_unknown_axis():
    with pytest.raises(ValueError):
        cylinder_inertia(1, 1, 1, "w")


# ------------------------------------------------------------- meshes

def test_meshed_box_matches_analytic_and_trimesh():
    mesh = trimesh.creation.box(extents=(0.3, 0.2, 0.1))
    mesh.apply_translation((12.0, -7.0, 3.0))          # far from the origin on purpose
    props = solid_mass_properties(mesh.triangles, density_kg_m3=800.0)
    assert props.volume_m3 == pytest.approx(0.006, rel=1e-12)
    assert props.mass_kg == pytest.approx(4.8, rel=1e-12)
    # Exact-in-decimal box far from the origin: the divergence-theorem sums cancel
    # ~|12 m|/0.1 m, losing 2-3 digits of 16: ~1e-13 m; 1e-12 m holds, 1e-6 is a bug.
    np.testing.assert_allclose(props.com_m, (12.0, -7.0, 3.0), atol=1e-12)
    assert rel_close(props.inertia_kg_m2, box_inertia(4.8, (0.3, 0.2, 0.1)), 1e-3)
    # and agrees with trimesh's own integration of the same triangles
    reference = trimesh.Trimesh(mesh.vertices, mesh.faces, process=False)
    reference.density = 800.0
    assert rel_close(props.inertia_kg_m2, reference.moment_inertia, 1e-6)


def test_finely_meshed_cylinder_matches_analytic():
    mesh = trimesh.creation.cylinder(radius=0.05, height=0.2, sections=256)
    unit = solid_mass_properties(mesh.triangles)
    props = unit.scaled_to_mass(1.3)
    assert rel_close(props.inertia_kg_m2, cylinder_inertia(1.3, 0.05, 0.2, "z"), 1e-3)
    # 256-gon vs circle: area ratio sin(2pi/256)*256/(2pi) = 1 - 1.0e-4; 1e-3 holds it.
    assert unit.volume_m3 == pytest.approx(np.pi * 0.05**2 * 0.2, rel=1e-3)


def test_l_bracket_equals_two_analytic_boxes_combined():
    # The L (mm, NED): plate x 0..60, z 0..5 and upright x 0..5, z 5..30, both y 0..40.
    triangles = read_stl(EXAMPLES / "l_bracket_mm_ned.stl").triangles / 1000.0
    density = 2700.0
    plate_size, upright_size = (0.060, 0.040, 0.005), (0.005, 0.040, 0.025)
    parts = []
    for size, centre in ((plate_size, (0.030, 0.020, 0.0025)), (upright_size, (0.0025, 0.020, 0.0175))):
        m = density * np.prod(size)
        parts.append(MassProperties(m, np.array(centre), box_inertia(m, size)))
    expected = combine(parts)
    props = solid_mass_properties(triangles, density)
    # The bracket's coordinates are whole mm (exact in the STL's float32), divided by
    # 1000: the volume is exact up to the sums' rounding (~1e-15); 1e-9 is margin.
    assert props.volume_m3 == pytest.approx(17000e-9, rel=1e-9)
    assert props.mass_kg == pytest.approx(expected.mass_kg, rel=1e-9)
    # COM components down to 0.0025 m: rtol 1e-7 is 2.5e-10 m, well above the
    # sums' rounding (~1e-16 m) and far below a misplaced part (mm).
    np.testing.assert_allclose(props.com_m, expected.com_m, rtol=1e-7)
    assert rel_close(props.inertia_kg_m2, expected.inertia_kg_m2, 1e-6)
    assert expected.inertia_kg_m2[0, 2] != 0.0                  # asymmetric: a real product term


@settings(max_examples=15, deadline=None)
@given(st.floats(-np.pi, np.pi), st.floats(-1.5, 1.5), st.floats(-np.pi, np.pi),
       st.tuples(*[st.floats(-0.5, 0.5)] * 3))
def test_rotating_a_mesh_rotates_its_tensor(roll, pitch, yaw, shift):
    triangles = read_stl(EXAMPLES / "l_bracket_mm_ned.stl").triangles / 1000.0
    R = rpy_to_matrix((roll, pitch, yaw))
    base = solid_mass_properties(triangles, 1000.0)
    moved = solid_mass_properties(triangles @ R.T + np.array(shift), 1000.0)
    # Rotation and shift change only rounding: coordinates up to 0.5 m + 0.06 m, sums
    # over ~40 triangles cancel to ~1e-14 relative; 1e-9 holds any CPU's order of sums.
    assert moved.mass_kg == pytest.approx(base.mass_kg, rel=1e-9)
    np.testing.assert_allclose(moved.com_m, R @ base.com_m + shift, atol=1e-12)
    assert rel_close(moved.inertia_kg_m2, R @ base.inertia_kg_m2 @ R.T, 1e-8)


def test_open_mesh_uses_its_convex_hull():
    closed = read_stl(EXAMPLES / "l_bracket_mm_ned.stl").triangles / 1000.0
    open_ = read_stl(FIXTURES / "meshes" / "l_bracket_open.stl").triangles / 1000.0
    props = mesh_mass_properties(open_)
    assert props.from_hull
    hull_area_m2 = (60 * 5 + 5 * 25 + 0.5 * 55 * 25) * 1e-6
    # Whole-mm hull of whole-mm points: rounding only (~1e-15); 1e-9 is margin.
    assert props.volume_m3 == pytest.approx(hull_area_m2 * 0.040, rel=1e-9)
    assert not mesh_mass_properties(closed).from_hull


def test_inside_out_mesh_is_flipped_not_negative():
    triangles = read_stl(EXAMPLES / "l_bracket_mm_ned.stl").triangles / 1000.0
    flipped = mesh_mass_properties(triangles[:, ::-1])
    # As above: the same triangles reversed, rounding only.
    assert flipped.volume_m3 == pytest.approx(17000e-9, rel=1e-9)
    assert not flipped.from_hull


# ----------------------------------------------------- frames and combining

def test_transformed_moves_com_and_rotates_tensor():
    I_b = np.diag([1.0, 2.0, 3.0])
    props = MassProperties(2.0, np.array([0.1, 0.0, 0.0]), I_b)
    T_a_b = make_T(rpy_to_matrix((0, 0, np.pi / 2)), (1.0, 2.0, 3.0))
    moved = props.transformed(T_a_b)
    # cos(pi/2) = 6e-17 times 0.1 m: the COM is off by < 1e-17 m; 1e-15 holds it.
    np.testing.assert_allclose(moved.com_m, (1.0, 2.1, 3.0), atol=1e-15)
    # a 90 deg yaw swaps the x and y moments
    np.testing.assert_allclose(moved.inertia_kg_m2, np.diag([2.0, 1.0, 3.0]), atol=1e-15)


def test_combine_two_point_masses_by_hand():
    # two 1 kg point masses at x = +-1: COM at 0, Iyy = Izz = 2, Ixx = 0
    a = MassProperties(1.0, np.array([1.0, 0, 0]), np.zeros((3, 3)))
    b = MassProperties(1.0, np.array([-1.0, 0, 0]), np.zeros((3, 3)))
    total = combine([a, b])
    # Exact: 1.0 + 1.0.
    assert total.mass_kg == 2.0
    # Exact: +1 and -1 m at 1 kg sum to 0; Steiner terms of 0/1 values are exact.
    np.testing.assert_allclose(total.com_m, 0.0)
    np.testing.assert_allclose(total.inertia_kg_m2, np.diag([0.0, 2.0, 2.0]))
    assert MassProperties.combine([a, b]).mass_kg == 2.0


def test_combine_two_half_boxes_is_the_whole_box():
    m, size = 3.0, (0.4, 0.2, 0.1)
    half = (0.2, 0.2, 0.1)
    halves = [MassProperties(m / 2, np.array([s * 0.1, 0, 0]), box_inertia(m / 2, half))
              for s in (-1, 1)]
    assert rel_close(combine(halves).inertia_kg_m2, box_inertia(m, size), 1e-12)


def test_combine_nothing_is_massless():
    empty = combine([])
    # Exact: nothing summed is 0.0.
    assert empty.mass_kg == 0.0 and empty.volume_m3 is None


# ---------------------------------------------------------- URDF geometry

def test_geometry_primitives_in_the_link_frame():
    T = make_T(rpy_to_matrix((np.pi / 2, 0, 0)), (0.1, 0.2, 0.3))
    cyl = geometry_mass_properties(Cylinder(0.025, 0.02), T, 0.1)
    # Exact: the COM of a centred primitive is the frame's translation, copied.
    np.testing.assert_allclose(cyl.com_m, (0.1, 0.2, 0.3))
    # roll 90 deg turns the cylinder's z axis onto y
    assert rel_close(cyl.inertia_kg_m2, cylinder_inertia(0.1, 0.025, 0.02, "y"), 1e-12)
    box = geometry_mass_properties(Box(np.array([0.3, 0.2, 0.1])), np.eye(4), 2.0)
    assert rel_close(box.inertia_kg_m2, box_inertia(2.0, (0.3, 0.2, 0.1)), 1e-12)
    sph = geometry_mass_properties(Sphere(0.1), np.eye(4), 1.0)
    assert rel_close(sph.inertia_kg_m2, sphere_inertia(1.0, 0.1), 1e-12)
    # One closed form each way: a few ulps; approx's default rel 1e-6 is a ceiling.
    assert sph.volume_m3 == pytest.approx(4 / 3 * np.pi * 0.001)


def test_geometry_mesh_is_scaled_and_given_the_mass():
    path = EXAMPLES / "l_bracket_mm_ned.stl"
    mesh = Mesh(uri="package://x/l.stl", path=path, scale=np.array([0.001, 0.001, 0.001]))
    props = geometry_mass_properties(mesh, np.eye(4), 0.05)
    reference = solid_mass_properties(read_stl(path).triangles / 1000.0).scaled_to_mass(0.05)
    # Exact: the declared mass is passed through, not computed.
    assert props.mass_kg == 0.05
    assert rel_close(props.inertia_kg_m2, reference.inertia_kg_m2, 1e-9)
    # Whole-mm triangles scaled by 0.001: rounding only; default rel 1e-6 is a ceiling.
    assert props.volume_m3 == pytest.approx(17000e-9)


def test_geometry_mesh_errors():
    with pytest.raises(ReedtoolError, match="could not be resolved"):
        geometry_mass_properties(Mesh("package://nope/x.stl", None, resolve_error="no package 'nope'"),
                                 np.eye(4), 1.0)
    with pytest.raises(ReedtoolError, match="cannot read mesh"):
        geometry_mass_properties(Mesh("x.stl", Path("/nonexistent/x.stl")), np.eye(4), 1.0)


def test_declared_properties_rotate_the_tensor_into_link_axes():
    R = rpy_to_matrix((0, 0, np.pi / 2))
    inertial = Inertial(2.0, make_T(R, (0.1, 0, 0)), np.diag([1.0, 2.0, 3.0]), LOC)
    props = declared_mass_properties(Link("l", LOC, inertial=inertial))
    # R I R^T with cos(pi/2) = 6e-17: off-diagonal terms ~6e-17 * 3 kg m^2 < 1e-15.
    np.testing.assert_allclose(props.inertia_kg_m2, np.diag([2.0, 1.0, 3.0]), atol=1e-15)
    # Exact: the inertial origin's translation, copied.
    np.testing.assert_allclose(props.com_m, (0.1, 0, 0))
    assert declared_mass_properties(Link("empty", LOC)) is None


def test_physical_validity():
    assert physically_valid(np.diag([1.0, 1.0, 1.0]))
    assert physically_valid(np.diag([1.0, 1.0, 2.0]))          # thin disc: A + B = C
    assert not physically_valid(np.diag([1.0, 1.0, 3.0]))      # A + B < C
    assert not physically_valid(np.diag([1.0, 0.0, 1.0]))
    assert not physically_valid(np.diag([1.0, np.nan, 1.0]))


def test_inertial_xml_is_parsed_back_by_yourdfpy():
    import io

    import yourdfpy

    props = MassProperties(0.05, np.array([0.0219, -0.02, -0.0069]),
                           np.array([[1e-5, 0, -4e-6], [0, 2e-5, 0], [-4e-6, 0, 2.5e-5]]))
    xml = f'<robot name="r"><link name="a">{inertial_xml(props)}</link></robot>'
    urdf = yourdfpy.URDF.load(io.BytesIO(xml.encode()))
    inertial = urdf.robot.links[0].inertial
    # Exact: written with 10 digits and parsed: 0.05 round-trips.
    assert inertial.mass == 0.05
    # Written with repr-precision numbers and parsed back by another library:
    # at most one rounding each way (1e-16); 1e-9 is margin.
    np.testing.assert_allclose(inertial.inertia, props.inertia_kg_m2, rtol=1e-9)
    # Written and parsed back: the default rtol 1e-7 is a ceiling over a 1-ulp round trip.
    np.testing.assert_allclose(inertial.origin[:3, 3], props.com_m)


# -------------------------------------------------- link verdicts and whole robot

def _link(mass, inertia, geometry=None, T_geom=np.eye(4), com=(0, 0, 0)):
    from reedtool.model import Collision

    link = Link("l", LOC, inertial=Inertial(mass, make_T(None, com), np.asarray(inertia, float), LOC))
    if geometry is not None:
        link.collisions.append(Collision(geometry, T_geom, LOC))
    return link


def test_compare_link_verdicts():
    size = np.array([0.3, 0.2, 0.1])
    good = box_inertia(2.0, size)
    assert compare_link(_link(2.0, good, Box(size))).verdict == "ok"
    assert compare_link(_link(2.0, good * 1.8, Box(size))).verdict == "differs"
    # trace ratio 3 / trace(box): 100x and beyond is way-off (error), 10x-100x implausible.
    trace_box = float(np.trace(good))
    assert compare_link(_link(2.0, np.eye(3) * 200 * trace_box / 3, Box(size))).verdict == "way-off"
    assert compare_link(_link(2.0, good * 20, Box(size))).verdict == "implausible"
    # Smaller is a real distribution (mass gathered inside) down to any share: 1/200 is
    # only implausible, 1/20 merely differs.
    assert compare_link(_link(2.0, good / 200, Box(size))).verdict == "implausible"
    assert compare_link(_link(2.0, good / 20, Box(size))).verdict == "differs"
    assert compare_link(_link(2.0, np.diag([1.0, 1.0, 3.0]), Box(size))).verdict == "invalid"
    assert compare_link(_link(2.0, good, Box(size), com=(0.5, 0, 0))).verdict == "com-off"
    assert compare_link(_link(0.0, good, Box(size))).verdict == "massless-inertia"
    assert compare_link(_link(0.0, np.zeros((3, 3)), Box(size))).verdict == "massless"
    assert compare_link(_link(0.0, np.zeros((3, 3)), Box(size)),
                        moving=True).verdict == "massless-moving"
    assert compare_link(_link(-1.0, good, Box(size))).verdict == "negative-mass"
    assert compare_link(_link(2.0, good)).verdict == "no-geometry"
    assert compare_link(Link("frame", LOC)).verdict == "no-inertial"
    broken = compare_link(_link(2.0, good, Mesh("package://nope/x.stl", None, resolve_error="gone")))
    assert broken.verdict == "geometry-error"


def test_whole_robot_equals_pinocchio_on_multilink_fixture():
    from reedtool.io.loader import load_robot
    from reedtool.physics.pinocchio_bridge import whole_robot_pinocchio

    robot = load_robot(FIXTURES / "inertia" / "multilink.urdf")
    own = whole_robot(robot)
    pin = whole_robot_pinocchio(robot)
    # Four additions of decimal masses: 3 roundings of ~2 kg values, < 1e-15 kg.
    assert own.mass_kg == pytest.approx(1.5 + 0.35 + 0.07 + 0.2, abs=1e-15)
    assert abs(own.mass_kg - pin.mass_kg) <= 1e-12
    assert np.max(np.abs(own.com_m - pin.com_m)) <= 1e-12
    assert np.max(np.abs(own.inertia_kg_m2 - pin.inertia_kg_m2)) <= 1e-12
    # not trivially at the origin: the fixture's offsets and rotations matter
    assert np.linalg.norm(own.com_m) > 0.01


def test_whole_robot_with_a_massless_world_root_matches_pinocchio():
    from reedtool.io.urdf import parse_urdf
    from reedtool.physics.pinocchio_bridge import whole_robot_pinocchio

    xml = """<robot name="w"><link name="world"/>
      <joint name="j" type="fixed"><parent link="world"/><child link="body"/>
        <origin xyz="1 2 3" rpy="0.3 0 0"/></joint>
      <link name="body"><inertial><origin xyz="0 0.1 0"/><mass value="2"/>
        <inertia ixx="1" iyy="2" izz="3" ixy="0" ixz="0" iyz="0"/></inertial></link></robot>"""
    robot = parse_urdf(xml, Path("w.urdf"))
    own, pin = whole_robot(robot), whole_robot_pinocchio(robot)
    assert robot.base_link == "world"
    # Pinocchio's and our sums of the same products in other orders: a few ulps of
    # metre-sized values (~1e-15); 1e-12 allows any CPU's summation order.
    np.testing.assert_allclose(own.com_m, pin.com_m, atol=1e-12)
    expected_com = np.array([1, 2, 3]) + rpy_to_matrix((0.3, 0, 0)) @ [0, 0.1, 0]
    # Hand formula vs the sum over links: a few ulps of 3 m (~1e-15).
    np.testing.assert_allclose(own.com_m, expected_com, atol=1e-12)
    # Exact: one link's mass, no sum.
    assert pin.mass_kg == 2.0
