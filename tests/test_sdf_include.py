"""SDF as libsdformat reads it: <include>, merge, nested models, worlds, resource paths.

Fixtures: tests/fixtures/px4_gz (generate.py) and tests/fixtures/gz_worlds. Expected
numbers are read by hand from those files, not from reedtool.
"""

import json
import math
from pathlib import Path

import numpy as np
import pytest
from cli_helpers import run_cli

from reedtool.checks.runner import Selection, run_checks
from reedtool.errors import ReedtoolError
from reedtool.io.loader import load_robot, load_robots
from reedtool.resolve.resources import RESOURCE_PATH_VARS
from reedtool.physics.kinematics import link_poses
from reedtool.physics.rotors import discover_rotors

PX4 = Path(__file__).parent / "fixtures" / "px4_gz"
MODELS = PX4 / "models"
WORLDS = Path(__file__).parent / "fixtures" / "gz_worlds"
STANDARD_GRAVITY = 9.80665   # what reedtool's trim uses (reedtool.physics.trim)

# From models/x500_base/model.sdf: base_link <mass>2</mass>, four rotors <mass>0.02</mass>.
X500_MASS_KG = 2.0 + 4 * 0.02
# From models/x500/model.sdf: every plugin's <motorConstant>.
X500_K = 8.54858e-06
# rotor link poses in x500_base (base_link at the model origin): (x, y, z), direction, number
X500_ROTORS = {
    "rotor_0": ((0.18, -0.18, 0.055), "ccw", 0),
    "rotor_1": ((-0.18, 0.18, 0.055), "ccw", 1),
    "rotor_2": ((0.18, 0.18, 0.055), "cw", 2),
    "rotor_3": ((-0.18, -0.18, 0.055), "cw", 3),
}


@pytest.fixture(autouse=True)
def no_resource_env(monkeypatch):
    for var in RESOURCE_PATH_VARS:
        monkeypatch.delenv(var, raising=False)


def codes_of(robot) -> list[str]:
    return sorted(f.code for f in run_checks(robot, Selection(select=("",))))


# ------------------------------------------------------------------ include + merge

def test_x500_include_merge_reads_the_four_rotors_gazebo_flies():
    robot = load_robot(MODELS / "x500" / "model.sdf")
    rotors = discover_rotors(robot)
    assert sorted(r.name for r in rotors) == sorted(X500_ROTORS)
    for rotor in rotors:
        position, direction, number = X500_ROTORS[rotor.name]
        # Include poses composed: a few ulps of ~0.2 m (< 1e-15).
        np.testing.assert_allclose(rotor.position_m, position, atol=1e-12)
        np.testing.assert_allclose(rotor.axis, [0, 0, 1], atol=1e-12)
        assert rotor.direction == direction
        assert rotor.motor_number == number
        assert rotor.motor_constant == X500_K
        # Exact: plugin text read by float() equals the literal.
        assert rotor.moment_constant == 0.016
        assert rotor.joint == f"{rotor.name}_joint"
    # The plugins come from x500, the links from the included x500_base.
    assert {Path(r.loc.file).parent.name for r in rotors} == {"x500"}
    assert Path(robot.link_map["rotor_0"].loc.file).parent.name == "x500_base"
    assert sum(link.inertial.mass_kg for link in robot.links) == pytest.approx(X500_MASS_KG)


@pytest.mark.parametrize("model", ["x500", "x500_depth", "x500_front_cam"])
def test_good_px4_models_validate_clean(model):
    code, output = run_cli("validate", MODELS / model / "model.sdf")
    assert code == 0, output
    assert "no findings" in output


def test_model_directory_is_read_through_model_config(tmp_path):
    assert codes_of(load_robot(MODELS / "x500")) == []
    # model.config lists model_1_6.sdf (0.5 kg) and model.sdf (0.06 kg, version 1.9).
    # Exact: <mass> text read by float() equals the literal.
    assert load_robot(MODELS / "depth_cam").links[0].inertial.mass_kg == 0.06
    only_old = tmp_path / "cam"
    only_old.mkdir()
    (only_old / "old.sdf").write_text((MODELS / "depth_cam" / "model_1_6.sdf").read_text())
    (only_old / "model.config").write_text(
        '<model><sdf version="1.6">old.sdf</sdf></model>')
    assert load_robot(only_old).links[0].inertial.mass_kg == 0.5


def test_hover_speed_is_sqrt_mg_over_4k():
    code, output = run_cli("hover-test", MODELS / "x500" / "model.sdf", "--duration", "1.5",
                           "--rate", "200", "--format", "json")
    assert code in (0, 1), output
    trim = json.loads(output)["trim"]
    expected = math.sqrt(X500_MASS_KG * STANDARD_GRAVITY / (4 * X500_K))
    assert expected == pytest.approx(772.35, abs=0.01)     # the hand value
    assert [r["omega_rad_s"] for r in trim["rotors"]] == pytest.approx([expected] * 4,
                                                                       rel=1e-9)


def test_merged_camera_pose_and_highest_sdf_version():
    robot = load_robot(MODELS / "x500_depth" / "model.sdf")
    camera = robot.link_map["camera_link"]
    # depth_cam's model.config lists 1.6 (mass 0.5) and 1.9 (mass 0.06): 1.9 wins.
    assert camera.inertial.mass_kg == 0.06
    assert Path(camera.loc.file).name == "model.sdf"
    # Include pose .12 .03 .242 in x500_depth's frame; base_link sits at z .24 there.
    T = link_poses(robot)["camera_link"]
    np.testing.assert_allclose(T[:3, 3], [0.12, 0.03, 0.002], atol=1e-12)
    assert [j.child for j in robot.joints if j.name == "CameraJoint"] == ["camera_link"]


# ------------------------------------------------------------------ nested models

def test_joint_child_naming_a_nested_model_is_its_canonical_link():
    robot = load_robot(MODELS / "x500_front_cam" / "model.sdf")
    joint = robot.joint_map["front_cam_joint"]
    assert (joint.parent, joint.child) == ("base_link", "front_cam::camera_link")
    # Include pose 0.15 0 0.01 relative_to base_link.
    np.testing.assert_allclose(link_poses(robot)["front_cam::camera_link"][:3, 3],
                               [0.15, 0.0, 0.01], atol=1e-12)
    assert not {"S104", "S105"} & set(codes_of(robot))


def _box_link(name, pose="0 0 0 0 0 0", mass=0.1):
    I = mass * (0.1 ** 2 + 0.1 ** 2) / 12
    return (f'<link name="{name}"><pose>{pose}</pose><inertial><mass>{mass}</mass><inertia>'
            f"<ixx>{I}</ixx><iyy>{I}</iyy><izz>{I}</izz></inertia></inertial>"
            "<collision name='c'><geometry><box><size>0.1 0.1 0.1</size></box></geometry>"
            "</collision></link>")


def test_canonical_link_attribute_and_nested_scoping(tmp_path):
    sdf = tmp_path / "m.sdf"
    sdf.write_text(
        '<sdf version="1.8"><model name="robot">' + _box_link("body", mass=1.0)
        + '<model name="sensor" canonical_link="lens"><pose>0.2 0 0 0 0 0</pose>'
        + _box_link("housing") + _box_link("lens", "0 0 0.05 0 0 0")
        + '<joint name="inner" type="fixed"><parent>lens</parent><child>housing</child>'
          "</joint></model>"
        + '<joint name="mount" type="fixed"><parent>body</parent><child>sensor</child>'
          "</joint></model></sdf>")
    robot = load_robot(sdf)
    assert (robot.joint_map["mount"].parent, robot.joint_map["mount"].child) == \
        ("body", "sensor::lens")
    assert (robot.joint_map["sensor::inner"].parent, robot.joint_map["sensor::inner"].child) == \
        ("sensor::lens", "sensor::housing")
    # Two translations added, no rotation: exact to an ulp (default rtol 1e-7 is a ceiling).
    np.testing.assert_allclose(link_poses(robot)["sensor::lens"][:3, 3], [0.2, 0, 0.05])
    assert not {"S104", "S105"} & set(codes_of(robot))


def test_plugins_of_a_nested_include_name_scoped_joints(tmp_path):
    outer = tmp_path / "outer.sdf"
    outer.write_text(
        '<sdf version="1.9"><model name="carrier">'
        f"<include><uri>{MODELS / 'x500'}</uri><name>quad</name>"
        "<pose>1 0 0 0 0 0</pose></include></model></sdf>")
    robot = load_robot(outer)
    rotors = discover_rotors(robot)
    assert sorted(r.joint for r in rotors) == [f"quad::rotor_{i}_joint" for i in range(4)]
    assert sorted(r.name for r in rotors) == [f"quad::rotor_{i}" for i in range(4)]
    for rotor in rotors:
        position, direction, _number = X500_ROTORS[rotor.name.removeprefix("quad::")]
        # Include poses composed: a few ulps of ~0.2 m (< 1e-15).
        np.testing.assert_allclose(rotor.position_m, position, atol=1e-12)
        assert rotor.direction == direction


# ------------------------------------------------------------------ planted defects

def test_flipped_direction_in_the_outer_plugin_is_found():
    robot = load_robot(PX4 / "bad" / "x500_flipped" / "model.sdf", package_paths=[MODELS])
    assert codes_of(robot) == ["R304"]


def test_missing_included_model_is_one_line_error_at_the_include():
    path = PX4 / "bad" / "missing_include" / "model.sdf"
    code, output = run_cli("validate", path)
    assert code == 2
    line = output.strip().splitlines()[-1]
    assert line.startswith(f"{path}:4: included model 'model://no_such_model' not found")
    assert len(output.strip().splitlines()) == 1


def test_include_cycle_is_refused_with_the_chain():
    path = PX4 / "bad" / "cycle_a" / "model.sdf"
    code, output = run_cli("validate", path)
    assert code == 2
    assert len(output.strip().splitlines()) == 1
    assert "<include> cycle: " in output
    chain = output.split("<include> cycle: ")[1].split(" (")[0].split(" -> ")
    assert [Path(p).parent.name for p in chain] == ["cycle_a", "cycle_b", "cycle_a"]


def test_bad_include_pose_points_at_the_include_line(tmp_path):
    outer = tmp_path / "outer.sdf"
    outer.write_text('<sdf version="1.9">\n<model name="o">\n<include>\n'
                     f"<uri>{MODELS / 'x500'}</uri>\n<pose>1 2</pose>\n</include>\n"
                     "</model>\n</sdf>\n")
    robot = load_robot(outer)
    issues = [i for i in robot.parse_issues if i.kind == "bad-number"]
    # The issue is with the inclusion: it points at the <include> line of the outer file.
    assert [(Path(i.loc.file).name, i.loc.line) for i in issues] == [("outer.sdf", 3)]


def test_merge_include_in_a_world_is_read_as_that_model(tmp_path):
    world = tmp_path / "w.sdf"
    world.write_text('<sdf version="1.10"><world name="w">\n<include merge="true">'
                     f"<uri>{MODELS / 'x500'}</uri></include></world></sdf>")
    robot = load_robot(world)
    assert robot.name == "x500" and len(discover_rotors(robot)) == 4


# ------------------------------------------------------------------ resource lookup

def _outside_world(tmp_path) -> Path:
    """A model file far from the models/ directory, so only a search path finds x500."""
    path = tmp_path / "elsewhere" / "deep" / "model.sdf"
    path.parent.mkdir(parents=True)
    path.write_text('<sdf version="1.9"><model name="w">'
                    "<include merge='true'><uri>model://x500</uri></include></model></sdf>")
    return path


@pytest.mark.parametrize("var", RESOURCE_PATH_VARS)
def test_each_resource_path_variable_is_searched(tmp_path, monkeypatch, var):
    path = _outside_world(tmp_path)
    with pytest.raises(ReedtoolError):
        load_robot(path)
    monkeypatch.setenv(var, f"/nonexistent:{MODELS}")
    assert len(discover_rotors(load_robot(path))) == 4


def test_package_path_is_a_model_root(tmp_path):
    path = _outside_world(tmp_path)
    assert len(discover_rotors(load_robot(path, package_paths=[MODELS]))) == 4
    code, output = run_cli("validate", path, "--package-path", MODELS)
    assert code == 0 and "no findings" in output


def test_including_files_directory_comes_first(tmp_path, monkeypatch):
    # A decoy x500 on the env path with 3 rotors only; the sibling directory wins.
    decoy = tmp_path / "decoy" / "x500"
    decoy.mkdir(parents=True)
    text = (MODELS / "x500" / "model.sdf").read_text()
    start = text.index("<plugin")
    decoy.joinpath("model.sdf").write_text(text[:start] + text[text.index("</plugin>") + 9:])
    monkeypatch.setenv("GZ_SIM_RESOURCE_PATH", str(tmp_path / "decoy"))
    robot = load_robot(MODELS / "x500_depth" / "model.sdf")
    assert len(discover_rotors(robot)) == 4


# ------------------------------------------------------------------ worlds

def test_world_with_several_models_checks_each_multirotor():
    robots = load_robots(WORLDS / "several_models.sdf", package_paths=[MODELS])
    assert [r.name for r in robots] == ["x500_0", "x500_1"]   # not the cart, not the ground
    assert [len(discover_rotors(r)) for r in robots] == [4, 4]
    code, output = run_cli("validate", WORLDS / "several_models.sdf", "--package-path", MODELS)
    assert code == 0, output
    assert "[model x500_0]: no findings" in output and "[model x500_1]: no findings" in output


def test_world_model_option_picks_one():
    robot = load_robot(WORLDS / "several_models.sdf", package_paths=[MODELS], model_name="cart")
    assert [link.name for link in robot.links] == ["chassis"]
    code, output = run_cli("validate", WORLDS / "several_models.sdf", "--package-path", MODELS,
                           "--model", "x500_1", "--format", "json")
    assert code == 0
    assert json.loads(output)["findings"] == []
    code, output = run_cli("validate", WORLDS / "several_models.sdf", "--package-path", MODELS,
                           "--model", "nope")
    assert code == 2 and "'x500_0', 'x500_1', 'cart'" in output


def test_world_json_reports_each_model():
    code, output = run_cli("validate", WORLDS / "several_models.sdf", "--package-path", MODELS,
                           "--format", "json")
    assert code == 0
    models = json.loads(output)["models"]
    assert [m["model"].rsplit(" ", 1)[-1] for m in models] == ["x500_0]", "x500_1]"]
    assert [m["findings"] for m in models] == [[], []]


def test_inertia_and_hover_test_take_model_option():
    code, output = run_cli("inertia", WORLDS / "several_models.sdf", "--package-path", MODELS,
                           "--model", "x500_0", "--format", "json")
    assert code in (0, 1), output
    # A sum of the model's decimal masses: a few ulps; default rel 1e-6 is a ceiling.
    assert json.loads(output)["whole_robot"]["mass_kg"] == pytest.approx(X500_MASS_KG)


def test_quadcopter_world_reads_with_one_info():
    robot = load_robot(WORLDS / "quadcopter.sdf")
    assert robot.name == "X3"
    assert len(discover_rotors(robot)) == 4
    findings = run_checks(robot, Selection(select=("",)))
    assert [(f.code, f.severity, f.line) for f in findings] == [("S119", "info", 2)]


def test_frames_and_relative_to_through_included_models(tmp_path):
    """A frame of a nested include, named from outside with its scope, and a frame of the
    outer model posed relative to a merged link."""
    (tmp_path / "sensor").mkdir()
    (tmp_path / "sensor" / "model.sdf").write_text(
        '<sdf version="1.9"><model name="sensor">' + _box_link("lens", "0 0 0.02 0 0 0")
        + '<frame name="optical" attached_to="lens"><pose>0 0 0.01 0 0 0</pose></frame>'
        "</model></sdf>")
    outer = tmp_path / "outer.sdf"
    outer.write_text(
        '<sdf version="1.9"><model name="rig">'
        f"<include merge='true'><uri>{MODELS / 'x500'}</uri></include>"
        '<frame name="mount" attached_to="rotor_2"><pose relative_to="rotor_2">'
        "0 0 0.1 0 0 0</pose></frame>"
        "<include><uri>model://sensor</uri><name>cam</name>"
        '<pose relative_to="mount">0.01 0 0 0 0 0</pose></include>'
        '<link name="marker"><pose relative_to="cam::optical">0 0 0 0 0 0</pose>'
        "<inertial><mass>0.01</mass><inertia><ixx>1e-6</ixx><iyy>1e-6</iyy><izz>1e-6</izz>"
        "</inertia></inertial></link>"
        '<joint name="cam_joint" type="fixed"><parent>mount</parent><child>cam</child></joint>'
        '<joint name="marker_joint" type="fixed"><parent>cam::optical</parent>'
        "<child>marker</child></joint></model></sdf>")
    robot = load_robot(outer)
    poses = link_poses(robot)
    # rotor_2 at (0.18, 0.18, 0.055); mount 0.1 above; cam model 0.01 along x; lens 0.02
    # above the cam frame; optical 0.01 above the lens.
    np.testing.assert_allclose(poses["cam::lens"][:3, 3], [0.19, 0.18, 0.175], atol=1e-12)
    np.testing.assert_allclose(poses["marker"][:3, 3], [0.19, 0.18, 0.185], atol=1e-12)
    # Joint ends naming a frame are the link it is attached to; a model, its canonical link.
    assert (robot.joint_map["cam_joint"].parent, robot.joint_map["cam_joint"].child) == \
        ("rotor_2", "cam::lens")
    assert robot.joint_map["marker_joint"].parent == "cam::lens"
    assert not [i for i in robot.parse_issues if i.kind == "unknown-frame"]


def test_world_includes_reedtool_cannot_fetch_are_skipped_unless_asked_for():
    world = WORLDS / "several_models.sdf"
    sun_line = next(n for n, line in enumerate(world.read_text().splitlines(), 1)
                    if "<include>" in line)
    with pytest.raises(ReedtoolError) as info:
        load_robot(world, package_paths=[MODELS], model_name="Sun")
    assert (Path(info.value.file).name, info.value.line) == ("several_models.sdf", sun_line)
    assert "Fuel" in info.value.message


def test_world_including_a_light_model_is_not_an_error(tmp_path):
    (tmp_path / "sun").mkdir()
    (tmp_path / "sun" / "model.sdf").write_text(
        '<sdf version="1.6"><light name="sun" type="directional"/></sdf>')
    world = tmp_path / "w.sdf"
    world.write_text('<sdf version="1.9"><world name="w">'
                     "<include><uri>model://sun</uri></include>"
                     f"<include><uri>{MODELS / 'x500'}</uri></include></world></sdf>")
    robots = load_robots(world)
    assert [r.name for r in robots] == ["x500"]


@pytest.mark.parametrize("axis_xml", [
    '<xyz expressed_in="__model__">1 0 0</xyz>',
    "<xyz>1 0 0</xyz><use_parent_model_frame>true</use_parent_model_frame>",
])
def test_merged_model_frame_keeps_its_meaning_under_a_rotated_include(tmp_path, axis_xml):
    """The included model's __model__ (written or implied) is the proxy frame, not the
    including model's frame: an axis along the included model's x stays along it."""
    (tmp_path / "hinge").mkdir()
    (tmp_path / "hinge" / "model.sdf").write_text(
        '<sdf version="1.9"><model name="hinge">' + _box_link("root", mass=1.0)
        + _box_link("flap", "0.1 0 0 0 0 0")
        + '<joint name="j" type="revolute"><parent>root</parent><child>flap</child>'
        f"<axis>{axis_xml}</axis></joint></model></sdf>")
    outer = tmp_path / "outer.sdf"
    outer.write_text('<sdf version="1.9"><model name="o"><include merge="true">'
                     "<uri>model://hinge</uri><pose>0 0 0 0 0 1.5707963267948966</pose>"
                     "</include></model></sdf>")
    robot = load_robot(outer)
    # An axis expressed in a rotated frame, rotated back: a few ulps.
    np.testing.assert_allclose(robot.joint_map["j"].axis, [1, 0, 0], atol=1e-12)
    np.testing.assert_allclose(link_poses(robot)["flap"][:3, 3], [0.1, 0, 0], atol=1e-12)


@pytest.mark.parametrize("merge", ["false", "true"])
def test_placement_frame_places_that_frame(tmp_path, merge):
    """SDF 1.8: with <placement_frame>, the include's pose is the pose of that frame."""
    (tmp_path / "leg").mkdir()
    (tmp_path / "leg" / "model.sdf").write_text(
        '<sdf version="1.9"><model name="leg">' + _box_link("hip", mass=1.0)
        + '<frame name="foot" attached_to="hip"><pose>0 0 -0.3 0 0 0</pose></frame>'
        "</model></sdf>")
    outer = tmp_path / "outer.sdf"
    outer.write_text(
        '<sdf version="1.9"><model name="o">' + _box_link("body", mass=2.0)
        + f'<include merge="{merge}"><uri>model://leg</uri><name>leg</name>'
        "<placement_frame>foot</placement_frame><pose>0.5 0 0 0 0 0</pose></include>"
        '<joint name="fix" type="fixed"><parent>body</parent>'
        f"<child>{'hip' if merge == 'true' else 'leg'}</child></joint></model></sdf>")
    robot = load_robot(outer)
    hip = "hip" if merge == "true" else "leg::hip"
    # The foot lands at (0.5, 0, 0), so the hip is 0.3 above it.
    np.testing.assert_allclose(link_poses(robot)[hip][:3, 3], [0.5, 0, 0.3], atol=1e-12)
    assert not [i for i in robot.parse_issues if i.kind == "unknown-frame"]
