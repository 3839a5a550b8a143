"""SDF reading: frame semantics, joints, geometry, plugins and errors.

Expected poses are computed by hand from the SDF rules (link pose relative to the model,
joint pose relative to the child, relative_to chains), not read back from the code.
"""

from __future__ import annotations

import math
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from reedtool.errors import ReedtoolError
from reedtool.io.loader import load_robot
from reedtool.io.sdf import parse_sdf
from reedtool.physics.kinematics import link_poses
from reedtool.physics.rotors import discover_rotors

GZ = Path(__file__).parent / "fixtures" / "gz"
FIXTURES_VALIDATE = Path(__file__).parent / "fixtures" / "validate"
S45 = math.sin(math.radians(45))
S10, C10 = math.sin(math.radians(10)), math.cos(math.radians(10))


def _sdf(body: str, version: str = "1.9") -> str:
    return f'<?xml version="1.0"?>\n<sdf version="{version}">\n{body}\n</sdf>\n'


# ------------------------------------------------------------------ frames

@pytest.fixture(scope="module")
def frames():
    return load_robot(GZ / "frames.sdf")


def test_relative_to_chain_and_degrees(frames):
    poses = link_poses(frames)
    # arm_mount = (0.1, 0, 0) yawed 45°; arm is 0.2 along the mount's x.
    np.testing.assert_allclose(poses["arm"][:3, 3], [0.1 + 0.2 * S45, 0.2 * S45, 0], atol=1e-9)
    # rotor_t: 0.05 along arm x, 0.02 up, pitched 10° (degrees="true") about the arm's y.
    np.testing.assert_allclose(poses["rotor_t"][:3, 3],
                               [0.1 + 0.25 * S45, 0.25 * S45, 0.02], atol=1e-9)
    np.testing.assert_allclose(poses["rotor_t"][:3, 2], [S10 * S45, S10 * S45, C10], atol=1e-9)


def test_quaternion_pose_nested_model_and_spawn_pose_ignored(frames):
    poses = link_poses(frames)
    np.testing.assert_allclose(poses["rotor_q"][:3, 3], [-0.2, 0, 0.03], atol=1e-12)
    np.testing.assert_allclose(poses["rotor_q"][:3, 0], [0, 1, 0], atol=1e-12)   # yaw 90°
    np.testing.assert_allclose(poses["gimbal::cam"][:3, 3], [0.1, 0, -0.05], atol=1e-12)
    np.testing.assert_allclose(poses["base_link"], np.eye(4))


def test_joint_axes_are_rotated_into_the_child_frame(frames):
    joints = frames.joint_map
    # expressed_in="__model__": model z seen from the child pitched 10° about y.
    np.testing.assert_allclose(joints["rotor_t_joint"].axis, [-S10, 0, C10], atol=1e-9)
    # default: the joint frame, here aligned with the model; the child is yawed 90°.
    np.testing.assert_allclose(joints["rotor_q_joint"].axis, [0, -1, 0], atol=1e-12)


def test_visual_and_inertial_poses(frames):
    arm = frames.link_map["arm"]
    np.testing.assert_allclose(arm.inertial.com_m, [0.01, 0, 0])
    # A visual at the base_link origin, seen from the arm (0.1 + 0.2 s45, 0.2 s45) yawed 45°.
    x, y = 0.1 + 0.2 * S45, 0.2 * S45
    np.testing.assert_allclose(arm.visuals[0].T_link_geom[:3, 3],
                               [-(x + y) * S45, (x - y) * S45, 0], atol=1e-9)


def test_joint_types_and_limits(frames):
    joints = frames.joint_map
    assert joints["rotor_t_joint"].type == "continuous"        # revolute without limits
    limited = joints["rotor_q_joint"]
    assert limited.type == "revolute"
    assert (limited.limit.lower, limited.limit.upper, limited.limit.effort,
            limited.limit.velocity) == (-0.5, 0.5, 2.0, 3.0)
    assert joints["arm_joint"].type == "fixed"
    assert frames.base_link == "base_link"


def test_rotor_from_model_plugin_in_sdf(frames):
    (rotor,) = discover_rotors(frames)
    assert (rotor.kind, rotor.joint, rotor.turning_sign, rotor.motor_number) == \
        ("gz", "rotor_t_joint", -1, 0)
    # Frames composed through relative_to chains with 45/10 deg rotations: a few ulps
    # (~1e-16 m); 1e-9 is margin, a frame applied twice is ~0.1 m off.
    np.testing.assert_allclose(rotor.position_m, [0.1 + 0.25 * S45, 0.25 * S45, 0.02], atol=1e-9)
    np.testing.assert_allclose(rotor.axis, [S10 * S45, S10 * S45, C10], atol=1e-9)
    assert rotor.loc.line == 82 and rotor.plugin.param_loc("turningDirection").line == 86


def test_source_lines(frames):
    # Lines as `grep -n` shows them in the fixture.
    assert frames.link_map["rotor_t"].loc.line == 34
    assert frames.joint_map["rotor_t_joint"].loc.line == 44
    assert frames.joint_map["rotor_t_joint"].axis_loc.line == 49
    assert frames.link_map["base_link"].inertial.mass_loc.line == 13


# ------------------------------------------------------------------ X3 quadrotor

def test_x3_rotors_match_the_written_layout():
    robot = load_robot(GZ / "x3_quad.sdf")
    rotors = discover_rotors(robot)
    assert [(r.joint, r.turning_sign, r.motor_number) for r in rotors] == [
        ("X3/rotor_0_joint", 1, 0), ("X3/rotor_1_joint", 1, 1),
        ("X3/rotor_2_joint", -1, 2), ("X3/rotor_3_joint", -1, 3)]
    expected = [[0.13, -0.22, 0.023], [-0.13, 0.22, 0.023], [0.13, 0.22, 0.023],
                [-0.13, -0.22, 0.023]]
    # Composed poses: a few ulps of ~0.3 m (< 1e-15).
    np.testing.assert_allclose([r.position_m for r in rotors], expected, atol=1e-12)
    np.testing.assert_allclose([r.axis for r in rotors], [[0, 0, 1]] * 4, atol=1e-12)
    assert all(robot.joint_map[r.joint].type == "continuous" for r in rotors)


def test_sdf_and_urdf_variants_are_the_same_model():
    sdf, urdf = load_robot(GZ / "x3_quad.sdf"), load_robot(GZ / "x3_quad.urdf")
    assert [l.name for l in sdf.links] == [l.name for l in urdf.links]
    for name, T in link_poses(urdf).items():
        # SDF and URDF readers compose the same transforms: a few ulps.
        np.testing.assert_allclose(link_poses(sdf)[name], T, atol=1e-12)
    for a, b in zip(discover_rotors(sdf), discover_rotors(urdf)):
        assert (a.joint, a.direction, a.motor_constant) == (b.joint, b.direction, b.motor_constant)


def test_equivalent_urdf_passes_check_urdf_and_pinocchio(tmp_path):
    from reedtool.physics.pinocchio_bridge import whole_robot_pinocchio

    robot = load_robot(GZ / "x3_quad.sdf")
    from oracles import CHECK_URDF as check_urdf

    out = tmp_path / "x3.urdf"
    out.write_text(robot.urdf_xml)
    result = subprocess.run([check_urdf, str(out)], capture_output=True, text=True)
    assert result.returncode == 0, result.stdout + result.stderr
    whole = whole_robot_pinocchio(robot)
    assert whole.mass_kg == pytest.approx(1.5 + 4 * 0.005)
    # COM height: four 5 g rotors 0.023 m above the body's centre.
    np.testing.assert_allclose(whole.com_m, [0, 0, 4 * 0.005 * 0.023 / 1.52], atol=1e-12)


# ------------------------------------------------------------------ variants

def test_sdf16_use_parent_model_frame_axis():
    text = _sdf("""<model name="m">
      <link name="a"/>
      <link name="b"><pose>0 0 0 0 0 1.5707963267948966</pose></link>
      <joint name="j" type="revolute"><parent>a</parent><child>b</child>
        <axis><xyz>1 0 0</xyz><use_parent_model_frame>true</use_parent_model_frame></axis>
      </joint></model>""", "1.6")
    robot = parse_sdf(text, "m.sdf")
    # Model x seen from b (yawed +90°) is -y.
    np.testing.assert_allclose(robot.joint_map["j"].axis, [0, -1, 0], atol=1e-12)


def test_missing_inertial_gets_sdformat_defaults_and_a_finding():
    from reedtool.checks.runner import Selection, run_checks

    robot = parse_sdf(_sdf('<model name="m"><link name="a"/></model>'), "m.sdf")
    # Exact: <mass> text read by float().
    assert robot.link_map["a"].inertial.mass_kg == 1.0
    # Exact: the declared numbers, read (default rtol 1e-7 is only a ceiling).
    np.testing.assert_allclose(robot.link_map["a"].inertial.inertia_kg_m2, np.eye(3))
    # Valid SDF that Gazebo loads with 1 kg: a warning (S120), not a parse error.
    codes = [f.code for f in run_checks(robot, Selection(select=("S1",)))]
    assert codes == ["S120"]


def test_world_picks_the_non_static_model(tmp_path):
    text = _sdf("""<world name="w">
      <model name="ground_plane"><static>true</static><link name="link"/></model>
      <model name="drone"><link name="body"><inertial><mass>2</mass></inertial></link></model>
    </world>""")
    robot = parse_sdf(text, tmp_path / "w.sdf")
    assert robot.name == "drone" and [l.name for l in robot.links] == ["body"]


@pytest.mark.parametrize("motor", [
    '<plugin name="m0" filename="libgazebo_motor_model.so"/>',            # PX4 classic
    '<plugin name="m0" filename="librotors_gazebo_motor_model.so"/>',     # RotorS
    '<plugin filename="gz-sim-multicopter-motor-model-system" '
    'name="gz::sim::systems::MulticopterMotorModel"/>',                  # gz-sim
])
def test_world_picks_the_model_whose_plugin_rotor_discovery_reads(tmp_path, motor):
    """The vehicle of a world is the model with a motor plugin as rotor discovery reads
    one (one table, model.MOTOR_PLUGINS): a plugin merely named like a motor model (here a
    walker's logger) does not make a second vehicle, which would refuse the world."""
    text = _sdf(f"""<world name="w">
      <model name="walker"><link name="torso"><inertial><mass>3</mass></inertial></link>
        <plugin name="walker_motor_model" filename="libwalker_motor_model_logger.so"/></model>
      <model name="drone"><link name="body"><inertial><mass>2</mass></inertial></link>
        {motor}</model>
    </world>""")
    robot = parse_sdf(text, tmp_path / "w.sdf")
    assert robot.name == "drone"


@pytest.mark.parametrize("text, fragment", [
    (_sdf('<world name="w"><include><uri>https://fuel/X3</uri></include></world>'), "<include>"),
    (_sdf('<world name="w"/>'), "no <model>"),
    ('<robot name="r"/>', "not an SDF"),
    ('<sdf version="1.9"><model name="m"><link name="a"></model></sdf>', "malformed XML"),
])
def test_unreadable_input_is_one_reedtool_error(text, fragment):
    with pytest.raises(ReedtoolError) as info:
        parse_sdf(text, "bad.sdf")
    assert fragment in info.value.message and "\n" not in info.value.one_line()


def test_model_uri_resolves_through_resource_path(tmp_path, monkeypatch):
    mesh = tmp_path / "frames" / "meshes" / "prop.stl"
    mesh.parent.mkdir(parents=True)
    mesh.write_text("solid x\nendsolid x\n")
    monkeypatch.setenv("GZ_SIM_RESOURCE_PATH", str(tmp_path))
    robot = load_robot(GZ / "frames.sdf")
    geometry = robot.link_map["rotor_t"].visuals[0].geometry
    assert geometry.path == mesh
    # Exact: the declared scale, read.
    np.testing.assert_allclose(geometry.scale, [0.001] * 3)


def test_loader_accepts_a_model_directory(tmp_path):
    (tmp_path / "x3").mkdir()
    shutil.copy(GZ / "x3_quad.sdf", tmp_path / "x3" / "model.sdf")
    assert len(discover_rotors(load_robot(tmp_path / "x3"))) == 4


def test_cli_validate_sdf_clean_and_bad_xml(tmp_path):
    from click.testing import CliRunner

    from reedtool.cli import cli

    runner = CliRunner()
    result = runner.invoke(cli, ["validate", str(GZ / "x3_quad.sdf"), "--format", "json"],
                           standalone_mode=False)
    assert result.exception is None and result.return_value == 0
    bad = tmp_path / "bad.sdf"
    bad.write_text('<sdf version="1.9"><model name="m">\n<link name="a"></model></sdf>')
    proc = subprocess.run([str(Path(sys.executable).parent / "reedtool"), "validate", str(bad)],
                          capture_output=True, text=True)
    assert proc.returncode == 2 and len(proc.stderr.strip().splitlines()) == 1
    assert f"{bad}:2" in proc.stderr


@pytest.mark.parametrize("model", ["x3_quad.sdf", "x3_quad.urdf"])
def test_hover_test_and_inertia_work_on_gz_models_unchanged(model):
    # Issue 7: gz-sim models go through the same loader, rotor discovery and simulator.
    import json

    from click.testing import CliRunner

    from reedtool.cli import cli

    path = str(Path(__file__).parent / "fixtures" / "gz" / model)
    hover = CliRunner().invoke(cli, ["hover-test", path, "--format", "json", "--duration", "5"])
    assert hover.exit_code == 0, hover.output
    report = json.loads(hover.output)
    assert report["passed"] is True
    # Hover speed from first principles: sqrt(m g / (n k)) with the fixture's numbers
    # (1.52 kg, 4 rotors, motor constant 8.54858e-06 as written in x3_quad).
    omega = np.sqrt(1.52 * 9.80665 / (4 * 8.54858e-06))
    omegas = [rotor["omega_rad_s"] for rotor in report["trim"]["rotors"]]
    assert len(omegas) == 4 and np.allclose(omegas, omega, rtol=1e-9)
    inertia = CliRunner().invoke(cli, ["inertia", path, "--format", "json"])
    assert inertia.exit_code == 0, inertia.output


@pytest.mark.parametrize("version, axis_in_base", [("1.7", [-1, 0, 0]), ("1.6", [0, 0, 1])])
def test_use_parent_model_frame_counts_only_where_the_version_defines_it(version, axis_in_base):
    """In 1.6 it puts the axis in the model frame (body z); a 1.7 file's is ignored, so the
    axis stays in the joint frame: the wheel link's z, pitched -90° onto body -x."""
    from reedtool.physics.kinematics import link_poses

    text = (FIXTURES_VALIDATE / "S123_bad_parent_frame_in_1_7.sdf").read_text().replace(
        '<sdf version="1.7">', f'<sdf version="{version}">')
    robot = parse_sdf(text, "m.sdf")
    joint = robot.joint_map["wheel_joint"]
    axis = link_poses(robot)["wheel"][:3, :3] @ joint.axis
    np.testing.assert_allclose(axis, axis_in_base, atol=1e-9)
    kinds = [i.kind for i in robot.parse_issues]
    assert kinds == (["sdf-undefined-element"] if version == "1.7" else [])


def test_three_number_pose_is_a_position_as_libsdformat_9_reads_it(tmp_path):
    """GymFC's nf1 shape: "0 0 0.007083" and "0 0 0.0185" place the links 7.1 and 18.5 mm
    up, no rotation: the battery sits 11.417 mm above the frame. With a Gazebo classic
    plugin (the model's target) nothing is reported."""
    from reedtool.checks.runner import run_checks
    from reedtool.physics.kinematics import link_poses

    text = (FIXTURES_VALIDATE / "S125_bad_short_pose.sdf").read_text()
    robot = parse_sdf(text, tmp_path / "m.sdf")
    np.testing.assert_allclose(link_poses(robot)["battery"], np.array(
        [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0.0185 - 0.007083], [0, 0, 0, 1]]), atol=1e-15)
    classic = text.replace("  </model>", '    <plugin name="imu" filename="libgazebo_imu_plugin.so"/>\n  </model>')
    path = tmp_path / "classic.sdf"
    path.write_text(classic)
    from reedtool.io.loader import load_robot
    assert [f.code for f in run_checks(load_robot(path))] == []
