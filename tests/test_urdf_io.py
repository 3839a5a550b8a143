"""URDF loader: values, source lines and collected parse issues."""

from pathlib import Path

import numpy as np
import pytest

from reedtool.errors import ReedtoolError
from reedtool.io.urdf import load_urdf_file, parse_urdf
from reedtool.physics.kinematics import link_poses

CORE = Path(__file__).parent / "fixtures" / "core"


def test_quad_values_and_lines():
    robot = load_urdf_file(CORE / "quad_x_rotors.urdf")
    assert robot.name == "quad"
    assert [link.name for link in robot.links][:2] == ["base_link", "rotor_0"]
    base = robot.link_map["base_link"]
    # Exact: <mass value> read by float() equals the literal.
    assert base.inertial.mass_kg == 1.5
    # Exact: decimal text parsed by float() twice gives the same double.
    np.testing.assert_array_equal(np.diag(base.inertial.inertia_kg_m2), [0.0347563, 0.0458929, 0.0799])
    np.testing.assert_array_equal(base.collisions[0].geometry.size_m, [0.47, 0.47, 0.11])
    # Lines of the fixture file, counted by hand: <link name="base_link"> is line 3.
    text = (CORE / "quad_x_rotors.urdf").read_text().splitlines()
    assert text[base.loc.line - 1].strip() == '<link name="base_link">'
    joint = robot.joint_map["rotor_2_joint"]
    assert text[joint.loc.line - 1].strip() == '<joint name="rotor_2_joint" type="continuous">'
    # Exact: the origin's numbers copied into T (default rtol 1e-7 is only a ceiling).
    np.testing.assert_allclose(joint.T_parent_joint[:3, 3], [0.18738, 0.18738, 0.026])
    assert robot.parse_issues == []


def test_gazebo_plugins_are_kept_with_parameters_and_lines():
    robot = load_urdf_file(CORE / "quad_x_rotors.urdf")
    plugins = [plugin for _, plugin in robot.plugins()]
    assert len(plugins) == 5
    assert plugins[0].library == "rotors_gazebo_motor_model"
    assert plugins[0].param("turningDirection") == "ccw"
    text = (CORE / "quad_x_rotors.urdf").read_text().splitlines()
    assert "<turningDirection>ccw" in text[plugins[0].param_loc("turningDirection").line - 1]


def test_link_poses_compose_rotations():
    robot = load_urdf_file(CORE / "tilted_mixed.urdf")
    poses = link_poses(robot)
    # Hand computation: arm at (0.1, 0, 0) yawed 90 deg; rotor_a at (0.2, 0, 0.05) in the arm.
    np.testing.assert_allclose(poses["rotor_a"][:3, 3], [0.1, 0.2, 0.05], atol=1e-12)
    np.testing.assert_allclose(poses["rotor_a"][:3, 2], [np.sin(0.3), 0.0, np.cos(0.3)], atol=1e-12)


def test_broken_numbers_become_parse_issues_not_exceptions():
    robot = load_urdf_file(CORE / "broken_numbers.urdf")
    kinds = sorted(issue.kind for issue in robot.parse_issues)
    assert kinds == ["bad-number", "bad-number", "non-finite", "non-finite"]
    text = (CORE / "broken_numbers.urdf").read_text().splitlines()
    for issue in robot.parse_issues:
        assert issue.loc.line is not None and text[issue.loc.line - 1].strip().startswith("<")


@pytest.mark.parametrize("xml, fragment", [
    ("<robot><link name='a'></robot>", "malformed XML"),
    ("<sdf version='1.9'/>", "not a URDF"),
])
def test_not_urdf_is_one_line_error(xml, fragment, tmp_path):
    with pytest.raises(ReedtoolError) as info:
        parse_urdf(xml, tmp_path / "m.urdf")
    assert fragment in info.value.one_line()
    assert "\n" not in info.value.one_line()
    assert str(tmp_path / "m.urdf") in info.value.one_line()


def test_multiline_start_tag_points_at_its_first_line(tmp_path):
    # lxml reports the line of the closing '>'; users look for the line with '<link'.
    path = tmp_path / "m.urdf"
    path.write_text('<robot name="r">\n  <link\n     name="a">\n  </link>\n</robot>\n')
    robot = load_urdf_file(path)
    assert robot.link_map["a"].loc.line == 2
