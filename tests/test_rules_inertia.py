"""Inertia rules (I2xx): codes per fixture, and the hint's tensor against the textbook formula."""

from __future__ import annotations

import re
from pathlib import Path

import pytest
from rule_helpers import FIXTURES, codes

from reedtool.checks.runner import Selection, run_checks
from reedtool.io.loader import load_robot

CASES = [
    ("I201_bad_negative_mass.urdf", ["I201"]),
    ("I201_bad_zero_mass.urdf", ["I201"]),
    ("I202_bad_zero_moment.urdf", ["I202"]),
    ("I202_bad_products.urdf", ["I202"]),
    ("I203_bad_triangle.urdf", ["I203"]),
    ("I204_bad_twenty_times.urdf", ["I204"]),
    ("I206_bad_large_mat.urdf", ["I206"]),
    ("I207_bad_zero_total_mass.urdf", ["I207"]),
    ("I208_bad_massless_inertia.urdf", ["I208"]),
    ("I209_bad_placeholder.urdf", ["I209"]),
    ("I204_bad_too_small_arm.urdf", ["I204"]),
    ("I205_bad_com.urdf", ["I205"]),
    ("I210_bad_mm_mesh.urdf", ["I210"]),
    # Good: zero mass on a fixed frame, a thin but valid cylinder, a mesh in metres.
    ("clean_arm.urdf", []),
    ("clean_car.urdf", []),
]


@pytest.mark.parametrize("name,expected", CASES, ids=[c[0] for c in CASES])
def test_inertia_rule_codes(name, expected):
    assert codes(name) == expected


def _attrs(text: str) -> dict[str, float]:
    return {k: float(v) for k, v in re.findall(r'(i[xyz]{2})="([^"]+)"', text)}


def test_placeholder_hint_gives_the_cylinder_tensor():
    (finding,) = run_checks(load_robot(FIXTURES / "I209_bad_placeholder.urdf"))
    m, r, h = 0.5, 0.05, 0.3  # link1: solid cylinder along z
    expected = {"ixx": m * (3 * r * r + h * h) / 12, "iyy": m * (3 * r * r + h * h) / 12,
                "izz": m * r * r / 2, "ixy": 0.0, "ixz": 0.0, "iyz": 0.0}
    # The hint prints the tensor for a user to paste, rounded to its printed digits;
    # 1e-5 holds that rounding (the zero products compare exactly).
    assert _attrs(finding.hint) == pytest.approx(expected, rel=1e-5)


def test_triangle_threshold_is_relative_to_the_largest_moment():
    from reedtool.checks import inertia_rules

    # A flat plate: izz = ixx + iyy exactly; hand-rounding it stays within tolerance.
    assert 0.0833 + 0.0833 >= 0.1667 - inertia_rules.TRIANGLE_REL_TOL * 0.1667
    # The seed's body (0.0347563 + 0.0458929 < 0.0977) is far outside it.
    assert 0.0347563 + 0.0458929 < 0.0977 * (1 - inertia_rules.TRIANGLE_REL_TOL)


def test_mm_mesh_hint_suggests_millimetre_scale():
    (finding,) = run_checks(load_robot(FIXTURES / "I210_bad_mm_mesh.urdf"))
    assert 'scale="0.001 0.001 0.001"' in finding.hint
    assert "60 m" in finding.message  # the 60 mm camera read as metres


INERTIA_FIXTURES = Path(__file__).parent / "fixtures" / "inertia"


def test_placeholder_links_are_not_compared(tmp_path):
    """Control surfaces of 1e-8 kg (20,000x their plate, COM beyond it) and a 1e-15 kg sonar
    frame: each is under 0.1 % of the robot's mass and smallest moment, so no inertia or
    COM finding and the verdict says why. By hand: 1e-6 / Ixx_base 0.0433 = 2.3e-5 < 1e-3.
    The same elevon at 0.1 kg is no placeholder: I204/I209 and I205 speak again."""
    from reedtool.physics.inertia import compare_links

    robot = load_robot(INERTIA_FIXTURES / "placeholder_surface.urdf")
    assert [f.code for f in run_checks(robot, Selection(select=("I",)))] == []
    verdicts = {c.link: c.verdict for c in compare_links(robot)}
    assert verdicts["left_elevon"] == verdicts["sonar_link"] == "placeholder"
    heavy = (INERTIA_FIXTURES / "placeholder_surface.urdf").read_text().replace(
        '<mass value="0.00000001"/>', '<mass value="0.1"/>')
    path = tmp_path / "heavy.urdf"
    path.write_text(heavy)
    found = {f.code for f in run_checks(load_robot(path), Selection(select=("I",)))
             if f.subject == "left_elevon"}
    assert "I205" in found and found & {"I204", "I209"}


def test_placeholder_geometry_is_not_compared(tmp_path):
    """omav's shape: 0.0004 kg·m² on a 5 mm box of 0.28 kg. Holding 0.28 kg in
    (0.005 m)³ = 1.25e-7 m³ takes 2.24e6 kg/m³, a hundred times osmium's 22,590: the box
    is a placeholder standing for the tilt unit, not its body, so the tensor is not judged
    against it (issue 27: a false I204). The same unit on a 5 cm box (2,240 kg/m³, a
    plausible part) is judged again: 0.28·2·0.05²/12 = 1.17e-4 per axis, the declared
    0.0004 is 3.4x that: plausible, no finding; at 0.04 kg·m² (343x) I204 or I209 speaks."""
    from reedtool.physics.inertia import compare_links

    robot = load_robot(INERTIA_FIXTURES / "tilt_unit_placeholder_box.urdf")
    assert [f.code for f in run_checks(robot, Selection(select=("I",)))] == []
    verdicts = {c.verdict for c in compare_links(robot)}
    assert "placeholder-geometry" in verdicts
    text = (INERTIA_FIXTURES / "tilt_unit_placeholder_box.urdf").read_text()
    assert 'size="0.005 0.005 0.005"' in text
    real = text.replace('size="0.005 0.005 0.005"', 'size="0.05 0.05 0.05"')
    path = tmp_path / "real_box.urdf"
    path.write_text(real)
    assert [f.code for f in run_checks(load_robot(path), Selection(select=("I",)))] == []
    path.write_text(real.replace('ixx="0.0004" ixy="0" ixz="0" iyy="0.0004" iyz="0" izz="0.0004"',
                                 'ixx="0.04" ixy="0" ixz="0" iyy="0.04" iyz="0" izz="0.04"'))
    found = {f.code for f in run_checks(load_robot(path), Selection(select=("I",)))}
    assert found & {"I204", "I209"}


@pytest.mark.parametrize("factor, expected", [(1 / 20, []), (20, ["I204"])])
def test_a_lighter_core_is_plausible_a_heavier_rim_is_not(tmp_path, factor, expected):
    """The arm's 0.5 kg cylinder (r 0.05 m, 0.3 m) with its tensor scaled: 20x larger fits
    no mass distribution inside it (all mass in the corners gives 3x at most), 1/20 does
    (mass gathered at the axis), so only the larger one is a finding."""
    m, r, h = 0.5, 0.05, 0.3
    ixx, izz = m * (3 * r * r + h * h) / 12 * factor, m * r * r / 2 * factor
    text = (FIXTURES / "I209_bad_placeholder.urdf").read_text().replace(
        'ixx="1.0" ixy="0" ixz="0" iyy="1.0" iyz="0" izz="1.0"',
        f'ixx="{ixx:.9g}" ixy="0" ixz="0" iyy="{ixx:.9g}" iyz="0" izz="{izz:.9g}"')
    path = tmp_path / "arm.urdf"
    path.write_text(text)
    assert [f.code for f in run_checks(load_robot(path), Selection(select=("I",)))] == expected


SENSOR_INERTIA = 'ixx="4.16666667e-07" ixy="0" ixz="0" iyy="4.16666667e-07" iyz="0" izz="6.66666667e-07"'


def _arm_with_sensor(tmp_path, sensor_inertia: str, joint: str = "fixed") -> list[str]:
    """The clean arm's 0.01 kg sensor link with another tensor, on a fixed (or moving) joint."""
    text = (FIXTURES / "I209_bad_placeholder.urdf").read_text()
    text = text.replace('ixx="1.0" ixy="0" ixz="0" iyy="1.0" iyz="0" izz="1.0"',
                        'ixx="0.00385416667" ixy="0" ixz="0" iyy="0.00385416667" iyz="0" '
                        'izz="0.000625"')          # link1: its own cylinder, so it is quiet
    text = text.replace(SENSOR_INERTIA, sensor_inertia)
    if joint != "fixed":
        text = text.replace('<joint name="sensor_joint" type="fixed">',
                            f'<joint name="sensor_joint" type="{joint}">').replace(
            '<child link="sensor_link"/>\n    <origin xyz="0 0 0.06" rpy="0 0 0"/><axis xyz="0 0 1"/>',
            '<child link="sensor_link"/>\n    <origin xyz="0 0 0.06" rpy="0 0 0"/><axis xyz="0 0 1"/>'
            '<limit lower="-1" upper="1" effort="1" velocity="1"/>')
    path = tmp_path / "arm.urdf"
    path.write_text(text)
    return [f.code for f in run_checks(load_robot(path), Selection(select=("I20",)))
            if f.subject == "sensor_link"]


ZERO = 'ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0"'


def test_point_mass_on_a_fixed_joint_is_accepted(tmp_path):
    """aerial_gym's motor links: 0.01 kg with a zero tensor on a fixed joint is a point mass
    (gz-math calls zero moments valid; Gazebo merges the URDF link into its parent). On a
    joint that moves, the body has no inertia to turn with: I202."""
    assert _arm_with_sensor(tmp_path, ZERO) == []
    assert _arm_with_sensor(tmp_path, ZERO, joint="revolute") == ["I202"]
    # A negative moment is wrong wherever it is.
    assert _arm_with_sensor(tmp_path, ZERO.replace('izz="0"', 'izz="-1e-6"')) == ["I202"]


def test_merged_link_triangle_is_judged_in_its_parents_body(tmp_path):
    """A 0.01 kg sensor's (1e-7, 1e-7, 1e-6) breaks A + B >= C. The fixture keeps its joint
    (preserveFixedJoint): its own body in Gazebo, I203. Without that Gazebo merges it into
    the 2 kg base, whose sum keeps the inequality: nothing to report."""
    bad = 'ixx="1e-07" ixy="0" ixz="0" iyy="1e-07" iyz="0" izz="1e-06"'
    assert _arm_with_sensor(tmp_path, bad) == ["I203"]
    path = tmp_path / "arm.urdf"
    text = path.read_text()
    line = '<gazebo reference="sensor_joint"><preserveFixedJoint>true</preserveFixedJoint></gazebo>'
    assert line in text
    path.write_text(text.replace(line, ""))
    assert [f.code for f in run_checks(load_robot(path), Selection(select=("I20",)))
            if f.subject == "sensor_link"] == []


def test_a_small_tensor_is_never_an_error(tmp_path):
    """gz-sim's plane_propeller shape: the body's tensor 1/200 of its box's, on the link that
    is most of the robot. Mass gathered inside a shape is real down to any share, so this
    is I204 (warning) even though it decides the robot's inertia; 200x larger is I209."""
    text = (INERTIA_FIXTURES / "placeholder_surface.urdf").read_text()
    base = 'ixx="0.0433333333" ixy="0" ixz="0" iyy="0.0433333333" iyz="0" izz="0.0833333333"'
    for factor, expected in ((1 / 200, "I204"), (200, "I209")):
        scaled = (f'ixx="{0.0433333333 * factor:.9g}" ixy="0" ixz="0" '
                  f'iyy="{0.0433333333 * factor:.9g}" iyz="0" izz="{0.0833333333 * factor:.9g}"')
        path = tmp_path / "body.urdf"
        path.write_text(text.replace(base, scaled))
        found = [f.code for f in run_checks(load_robot(path), Selection(select=("I",)))
                 if f.subject == "base_link"]
        assert found == [expected], factor
