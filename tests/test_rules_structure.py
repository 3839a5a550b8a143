"""Structure rules (S1xx): each bad fixture gives exactly the listed codes; check_urdf agrees.

Fixtures: tests/fixtures/validate (generate.py writes them: a clean model plus one change).
"""

from __future__ import annotations

import subprocess
from pathlib import Path

import pytest
from oracles import CHECK_URDF
from rule_helpers import FIXTURES, codes

from reedtool.checks.runner import run_checks
from reedtool.io.loader import load_robot

CASES = [
    ("S101_bad_number.urdf", ["S101"]),
    ("S102_bad_nan.urdf", ["S102"]),
    ("S103_bad_legacy.urdf.xacro", ["S103"]),
    ("S103_good_modern.urdf.xacro", []),
    ("S104_bad_two_roots.urdf", ["S104"]),
    # The dangling joint also leaves link1 without a parent: a second root.
    ("S105_bad_child_missing.urdf", ["S104", "S105"]),
    ("S106_bad_duplicate_link.urdf", ["S106"]),
    ("S107_bad_duplicate_joint.urdf", ["S107"]),
    ("S108_bad_two_parents.urdf", ["S108"]),
    ("S109_bad_cycle.urdf", ["S109"]),
    ("S110_bad_joint_type.urdf", ["S110"]),
    ("S142_bad_code_typo.urdf", ["S142"]),
    ("S142_good_known_names.urdf", []),
    ("S111_bad_no_limit.urdf", ["S111"]),
    ("S111_bad_no_effort.urdf", ["S111"]),
    ("S112_bad_inverted_limit.urdf", ["S112"]),
    ("S113_bad_zero_axis.urdf", ["S113"]),
    ("S114_bad_reference.urdf", ["S114"]),
    ("S115_bad_missing_mesh.urdf", ["S115"]),
    ("S115_bad_unknown_package.urdf", ["S115"]),
    ("S130_bad_step_mesh.urdf", ["S130"]),
    ("S131_bad_traversal.urdf", ["S131"]),
    ("S116_bad_zero_size.urdf", ["S116"]),
    ("S117_bad_no_inertial.urdf", ["S117"]),
    # 1e-7 kg with the 0.5 kg link's inertia is also implausible for its geometry (a
    # warning: the arm's tensor does not decide the robot's inertia).
    ("S117_bad_tiny_mass.urdf", ["I204", "S117"]),
    ("S118_bad_merged_link.urdf", ["S118"]),
    ("S118_good_body_name_lumped.urdf", []),
    ("S119_bad_tinyxml_only.sdf", ["S119"]),
    ("S119_good_strict.sdf", []),
    # URDF is read through sdformat's URDF parser, TinyXML2 as well.
    ("S119_bad_tinyxml_only.urdf", ["S119"]),
    # SDF models are held to SDFormat's joint types (ball, screw, universal, ...).
    ("S110_good_sdf_ball_joint.sdf", []),
    # An SDF link without <inertial> is 1 kg to sdformat: a warning, not a parse error.
    ("S120_bad_no_inertial.sdf", ["S120"]),
    # A negative mesh scale mirrors: the convention for a visual (information), a warning
    # on a collision (faces inside out); only a zero scale is S116.
    ("S121_bad_mirrored_visual.urdf", ["S121"]),
    ("S122_bad_mirrored_collision.urdf", ["S122"]),
    # 1.6's <use_parent_model_frame> in a 1.7 file: ignored, as libsdformat does.
    ("S123_bad_parent_frame_in_1_7.sdf", ["S123"]),
    # A comment before the XML declaration: read (S119), and gz-sim would refuse it (S124).
    ("S124_bad_comment_before_declaration.sdf", ["S119", "S124"]),
    # A 3-number <pose>: libsdformat 9 reads a position, 12+ refuses (S125, not S101).
    ("S125_bad_short_pose.sdf", ["S125", "S125"]),
    # Issue 27's classes (tests/fixtures/false_alarms, tests/test_false_alarms.py): a Fuel
    # mesh and a Fuel include are said unchecked (S190, info), not missing.
    ("../false_alarms/S190_bad_fuel_mesh_and_include.sdf", ["S190", "S190"]),
    ("../false_alarms/S191_bad_scoped_name_gz_target.sdf", ["S191", "S191"]),
    ("../false_alarms/S161_bad_joint_named_like_link_1_9.sdf", ["S161"]),
    ("../false_alarms/S105_good_classic_scoped_name.sdf", []),
    ("../false_alarms/S161_good_classic_joint_named_like_link.sdf", []),
    # Good fixtures: the arm has a zero-mass fixed tool frame (fine), a plugin on a fixed
    # link kept by preserveFixedJoint, a limited revolute joint; the car a mesh in metres.
    ("clean_arm.urdf", []),
    ("clean_car.urdf", []),
    # libsdformat's structural refusals (S160-S168); tests/test_sdformat_outputs.py shows
    # libsdformat refusing each bad fixture and loading each good one.
    ("S160_bad_double_colon_1_9.sdf", ["S160"]),
    ("S160_good_double_colon_1_6.sdf", []),
    # one finding: libsdformat checks names before it builds a frame graph (issue 27: this
    # was read as "part of a cycle of relative_to frames" and a joint to itself)
    ("S161_bad_link_named_as_joint.sdf", ["S161"]),
    ("S161_bad_duplicate_visual.sdf", ["S161"]),
    ("S161_good_renamed_below_1_7.sdf", []),   # PX4 rover_differential's caster shape
    ("S162_bad_link_named_world.sdf", ["S162", "S166"]),
    ("S163_bad_canonical_link.sdf", ["S163"]),
    ("S164_bad_attached_to_cycle.sdf", ["S164", "S164", "S165"]),
    ("S165_bad_relative_to_own_joint.sdf", ["S101", "S165"]),
    ("S165_good_frames_nested.sdf", []),
    ("S166_bad_joint_child_is_parent.sdf", ["S109", "S166"]),
    ("S167_bad_nested_without_link.sdf", ["S167"]),
    ("S168_bad_no_version.sdf", ["S168"]),
    # An absolute file:// mesh: machine-bound (S169), and missing here (S115).
    ("S169_bad_absolute_mesh.urdf", ["S115", "S169"]),
    ("S169_good_relative_mesh.urdf", []),
    ("S170_bad_script_without_uri.sdf", ["S170"]),
    ("S170_good_colour_material.sdf", []),
    ("S171_bad_two_models.sdf", ["S171"]),
    ("S171_good_models_in_world.sdf", []),
]


@pytest.mark.parametrize("name,expected", CASES, ids=[c[0] for c in CASES])
def test_structure_rule_codes(name, expected):
    assert codes(name) == expected


def test_findings_point_at_the_offending_line():
    findings = run_checks(load_robot(FIXTURES / "S110_bad_joint_type.urdf"))
    text = (FIXTURES / "S110_bad_joint_type.urdf").read_text().splitlines()
    (finding,) = findings
    assert 'type="revolut"' in text[finding.line - 1]
    assert finding.subject == "joint1"


# Structure mistakes urdfdom rejects: check_urdf must fail on each, as reedtool does.
# (It accepts S101_bad_number, a cycle detached from the root and the rest: reedtool is
# stricter there, which the code tables above show.)
CHECK_URDF_REJECTS = ["S102_bad_nan.urdf", "S104_bad_two_roots.urdf",
                      "S105_bad_child_missing.urdf", "S106_bad_duplicate_link.urdf",
                      "S107_bad_duplicate_joint.urdf",
                      "S110_bad_joint_type.urdf", "S111_bad_no_limit.urdf",
                      "S111_bad_no_effort.urdf"]


def _check_urdf_ok(path: Path) -> bool:
    result = subprocess.run([CHECK_URDF, str(path)], capture_output=True, text=True, timeout=30)
    return result.returncode == 0


@pytest.mark.parametrize("name", CHECK_URDF_REJECTS)
def test_superset_of_check_urdf(name):
    assert not _check_urdf_ok(FIXTURES / name)
    findings = run_checks(load_robot(FIXTURES / name))
    assert any(f.severity == "error" and f.code.startswith("S") for f in findings)


@pytest.mark.parametrize("name", ["clean_quad_x.urdf", "clean_hex.urdf", "clean_octo.urdf",
                                  "clean_arm.urdf", "clean_car.urdf"])
def test_clean_models_pass_check_urdf(name):
    assert _check_urdf_ok(FIXTURES / name)


def test_a_nan_in_sdf_is_not_blamed_on_xacro(tmp_path):
    """SDF has no expressions: S102's hint on an SDF says to write the number, and only a
    URDF (possibly from xacro) gets the xacro hint."""
    model = tmp_path / "nan.sdf"
    model.write_text('<sdf version="1.9"><model name="m"><link name="base">'
                     '<inertial><mass>nan</mass></inertial></link></model></sdf>')
    s102 = [f for f in run_checks(load_robot(model)) if f.code == "S102"]
    assert len(s102) == 1 and "xacro" not in s102[0].hint
    (urdf,) = [f for f in run_checks(load_robot(FIXTURES / "S102_bad_nan.urdf"))
               if f.code == "S102"]
    assert "xacro" in urdf.hint


@pytest.mark.filterwarnings("ignore::RuntimeWarning")   # the control's infinite pose
@pytest.mark.parametrize("as_sdf", [True, False])
def test_dbl_max_joint_limits_mean_no_limit(tmp_path, as_sdf):
    """A wheel joint limited at ±1.79769e+308 (DBL_MAX: exporters' 'no limit', PX4's
    rc_cessna wheels) is read as unbounded, with no S102; the same number in a pose is
    still S102 (control)."""
    big = "1.79769e+308"
    if as_sdf:
        def model(limit: str, pose: str) -> str:
            link = ('<link name="{n}"><pose>{p}</pose><inertial><mass>1</mass><inertia>'
                    '<ixx>0.01</ixx><iyy>0.01</iyy><izz>0.01</izz></inertia></inertial></link>')
            return ('<sdf version="1.9"><model name="m">' + link.format(n="body", p="0 0 0 0 0 0")
                    + link.format(n="wheel", p=pose)
                    + '<joint name="axle" type="revolute"><parent>body</parent>'
                    '<child>wheel</child><axis><xyz>0 1 0</xyz><limit>' + limit
                    + '</limit></axis></joint></model></sdf>')
        good = model(f"<lower>-{big}</lower><upper>{big}</upper>", "0 0.1 0 0 0 0")
        bad = model("<lower>-1</lower><upper>1</upper>", f"0 {big} 0 0 0 0")
        suffix = ".sdf"
    else:
        def model(limit: str, xyz: str) -> str:
            link = ('<link name="{n}"><inertial><mass value="1"/><inertia ixx="0.01" ixy="0" '
                    'ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>')
            return ('<robot name="m">' + link.format(n="body") + link.format(n="wheel")
                    + '<joint name="axle" type="revolute"><parent link="body"/>'
                    f'<child link="wheel"/><origin xyz="{xyz}"/><axis xyz="0 1 0"/>'
                    f'<limit {limit} effort="1" velocity="1"/></joint></robot>')
        good = model(f'lower="-{big}" upper="{big}"', "0 0.1 0")
        bad = model('lower="-1" upper="1"', f"0 {big} 0")
        suffix = ".urdf"
    for text, expected in ((good, []), (bad, ["S102"])):
        path = tmp_path / f"m{suffix}"
        path.write_text(text)
        assert [f.code for f in run_checks(load_robot(path)) if f.code == "S102"] == expected


def test_an_absolute_file_uri_works_here_only(tmp_path):
    """S169: a mesh and an <include> named by absolute paths that exist on this machine
    load (no S115, no include error) and are still reported, once each; the same files
    named relative to the model are not."""
    import shutil

    models = tmp_path / "models"
    (models / "camera").mkdir(parents=True)
    (models / "camera" / "model.config").write_text(
        '<?xml version="1.0"?><model><name>camera</name><sdf version="1.9">model.sdf</sdf>'
        "</model>")
    (models / "camera" / "model.sdf").write_text(
        '<sdf version="1.9"><model name="camera"><link name="link"><inertial><mass>0.05'
        "</mass><inertia><ixx>1e-5</ixx><iyy>1e-5</iyy><izz>1e-5</izz></inertia></inertial>"
        "</link></model></sdf>")
    shutil.copy(FIXTURES / "meshes" / "camera_m.stl", models / "body.stl")

    def model(mesh_uri: str, include_uri: str) -> list[str]:
        path = models / "quad.sdf"   # model://camera resolves beside it
        path.write_text(
            '<sdf version="1.9"><model name="quad"><link name="base_link"><inertial>'
            "<mass>0.1</mass><inertia><ixx>1.5e-05</ixx><iyy>3.75e-05</iyy><izz>3.75e-05</izz>"
            f"</inertia></inertial><visual name='v'><geometry><mesh><uri>{mesh_uri}</uri>"
            f"</mesh></geometry></visual></link><include><uri>{include_uri}</uri></include>"
            '<joint name="cam" type="fixed"><parent>base_link</parent><child>camera::link'
            "</child></joint></model></sdf>")
        return sorted(f.code for f in run_checks(load_robot(path)) if f.code.startswith("S"))

    absolute = model(f"file://{models}/body.stl", f"file://{models}/camera")
    assert absolute == ["S169", "S169"]
    assert model("body.stl", "model://camera") == []
