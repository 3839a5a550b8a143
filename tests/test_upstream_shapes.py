"""Models in the shape of what people fly today (acceptance sweep, issues 10 and 11).

Fixtures: tests/fixtures/upstream_shapes/<name>/model.sdf, written for this project in
the structure and with the numbers of the public models their comments name. Each good
fixture stays quiet (no error, no warning); each `<CODE>_bad_*` plants one defect that is
still found. Expected numbers are derived here by hand from the fixtures' written values.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from reedtool.checks.runner import run_checks
from reedtool.cli import main
from reedtool.io.loader import load_robot
from reedtool.physics.rotors import ardupilot_time_constant, discover_rotors

SHAPES = Path(__file__).parent / "fixtures" / "upstream_shapes"

CASES = [
    ("fixed_wing_puller", ["R319"]),
    ("R316_bad_fixed_wing_negative_k", ["R316", "R319"]),
    # Rotors 0 and 2 ride on tilt motors: no hover judgement at the zero pose (R319 says so).
    ("tiltrotor", ["R319"]),
    ("I204_bad_tiltrotor_motor_inertia", ["I204", "I204", "R319"]),
    ("rotors_plus_quad", []),
    ("R304_bad_rotors_plus_quad_flipped", ["R304"]),
    ("quad_tailsitter", ["R320"]),
    ("R311_bad_tailsitter_one_rotor_untilted", ["R311"] * 3),
    ("px4vision_quad", []),
    ("R301_bad_px4vision_duplicate_number", ["R301"]),
]
GOOD = [name for name, _ in CASES if "_bad_" not in name]


def _model(name: str) -> Path:
    (path,) = [p for p in (SHAPES / name).iterdir() if p.suffix in (".sdf", ".xacro")]
    return path


def _findings(name: str):
    return run_checks(load_robot(_model(name)))


@pytest.mark.parametrize("name,expected", CASES, ids=[c[0] for c in CASES])
def test_codes(name, expected):
    assert sorted(f.code for f in _findings(name)) == expected


@pytest.mark.parametrize("name", GOOD)
def test_good_shapes_have_no_error_or_warning(name):
    assert [f.code for f in _findings(name) if f.severity in ("error", "warning")] == []


# ------------------------------------------------------------------ fixed-wing

def test_fixed_wing_puller_is_propulsion_with_an_advanced_lift_drag_wing():
    (rotor,) = discover_rotors(load_robot(_model("fixed_wing_puller")))
    assert rotor.role == "propulsion"
    # Link pitched 1.57 rad: its z axis is (sin 1.57, 0, cos 1.57) in the base frame.
    np.testing.assert_allclose(rotor.axis, [math.sin(1.57), 0, math.cos(1.57)], atol=1e-12)


def test_fixed_wing_puller_without_a_wing_stays_lift(tmp_path):
    """The wing is what makes a lone horizontal rotor propulsion: without any lift-drag
    surface the same model is a (broken) multirotor and the rotor rules speak."""
    text = _model("fixed_wing_puller").read_text()
    start = text.index("    <plugin filename='gz-sim-advanced-lift-drag-system'")
    end = text.index("</plugin>", start) + len("</plugin>\n")
    model = tmp_path / "wingless.sdf"
    model.write_text(text[:start] + text[end:])
    (rotor,) = discover_rotors(load_robot(model))
    assert rotor.role == "lift"
    codes = {f.code for f in run_checks(load_robot(model))}
    assert {"R304", "R305"} <= codes


def test_hover_test_says_a_fixed_wing_cannot_hover(capsys):
    with pytest.raises(SystemExit) as info:
        main(["hover-test", str(_model("fixed_wing_puller"))])
    captured = capsys.readouterr()
    assert info.value.code == 1
    assert "Traceback" not in captured.err
    failed = [line for line in captured.out.splitlines() if line.startswith("FAILED")]
    assert failed == [("FAILED: no hover trim: the model has no lift rotors (rotor_puller is "
                       "propulsion: its thrust axis is horizontal); a fixed-wing cannot hover")]


# ------------------------------------------------------------------- tiltrotor

def test_tiltrotor_servos_are_not_rotors_and_trim_by_hand():
    robot = load_robot(_model("tiltrotor"))
    rotors = discover_rotors(robot)
    assert [r.link for r in rotors] == ["rotor_0", "rotor_1", "rotor_2", "rotor_3"]
    assert [r.direction for r in rotors] == ["ccw", "ccw", "cw", "cw"]
    assert all(r.role == "lift" for r in rotors)
    from reedtool.checks.context import CheckContext

    trim = CheckContext(robot).trim
    # 5 kg body, two 50 g tilt motors at x = +0.35, four 5 g rotors: COM x = 0.035/5.12.
    mass, k = 5 + 2 * 0.05 + 4 * 0.005, 2e-05
    com_x = (2 * 0.05 * 0.35) / mass
    # Pitch balance: 2 T_front (0.35 - c) = 2 T_back (0.35 + c); 2 T_front + 2 T_back = m g.
    weight = mass * 9.80665
    t_front = weight / 2 * (0.35 + com_x) / 0.7
    t_back = weight / 2 - t_front
    expected = np.sqrt(np.array([t_front, t_back, t_front, t_back]) / k)
    assert trim.feasible
    # Hand pitch balance vs the pseudo-inverse: both exact in exact arithmetic (the yaw
    # row is balanced by the symmetric pairs); measured 4.4e-16 apart, 1e-6 is margin.
    np.testing.assert_allclose(trim.omega_rad_s, expected, rtol=1e-6)


# ----------------------------------------------------------- ArduPilot motor lag

def _iris_rotor(tmp_path, edit=lambda text: text):
    text = (Path(__file__).parent / "fixtures" / "ardupilot" / "iris_lift_drag.sdf").read_text()
    model = tmp_path / "iris.sdf"
    model.write_text(edit(text))
    robot = load_robot(model)
    return robot, discover_rotors(robot)[0]


def test_ardupilot_time_constant_pd_and_offset_inertial(tmp_path):
    """(I + d) / p with I about the joint axis through the link origin: the COM 0.01 m off
    that axis adds m * 0.01^2 (parallel axis)."""
    def edit(text):
        text = text.replace("<d_gain>0</d_gain>", "<d_gain>0.0001</d_gain>")
        return text.replace("<inertial><mass>0.005</mass>",
                            "<inertial><pose>0.01 0 0 0 0 0</pose><mass>0.005</mass>", 1)
    robot, rotor = _iris_rotor(tmp_path, edit)
    found = ardupilot_time_constant(robot, rotor)
    inertia = 2.5e-05 + 0.005 * 0.01 ** 2
    # The same sum and division in the code: a few ulps (~1e-15); 1e-12 holds.
    assert found.time_constant_s == pytest.approx((inertia + 0.0001) / 0.20, rel=1e-12)


def test_ardupilot_time_constant_refused_without_force_control(tmp_path):
    def edit(text):
        return text.replace("<useForce>1</useForce>", "<useForce>0</useForce>")
    robot, rotor = _iris_rotor(tmp_path, edit)
    found = ardupilot_time_constant(robot, rotor)
    assert math.isnan(found.time_constant_s)
    assert "useForce" in found.explanation


# ------------------------------------------------------------ RotorS "+" quad

def test_rotors_plus_quad_through_the_bundled_macros_by_hand():
    robot = load_robot(_model("rotors_plus_quad"))
    rotors = discover_rotors(robot)
    assert [r.direction for r in rotors] == ["cw", "ccw", "cw", "ccw"]
    expected_xy = [(0.17, 0), (0, 0.17), (-0.17, 0), (0, -0.17)]
    for rotor, (x, y) in zip(rotors, expected_xy):
        # Poses composed through frames: a few ulps of ~0.3 m (< 1e-15).
        np.testing.assert_allclose(rotor.position_m, [x, y, 0.01], atol=1e-12)
    from reedtool.checks.context import CheckContext

    mass, k = 0.68 + 4 * 0.009, 8.54858e-06
    # Pseudo-inverse trim vs closed form: O(10) ulps (see test_trim); 1e-9 holds.
    np.testing.assert_allclose(CheckContext(robot).trim.omega_rad_s,
                               math.sqrt(mass * 9.80665 / (4 * k)), rtol=1e-9)


# ------------------------------------------------------------- quad tailsitter

def test_quad_tailsitter_tilts_and_trim_by_hand():
    """rpy (+-0.17, +-0.17, 0): the rotor z axis is (cos r sin p, -sin r, cos r cos p), so
    each rotor lifts with cos(0.17)^2 of its thrust; the side components cancel."""
    robot = load_robot(_model("quad_tailsitter"))
    rotors = discover_rotors(robot)
    cz = math.cos(0.17) ** 2
    for rotor in rotors:
        assert rotor.role == "lift"
        # rpy -> matrix: products of cos/sin, a few ulps (~1e-16); 1e-12 holds.
        assert rotor.axis[2] == pytest.approx(cz, rel=1e-12)
        assert abs(rotor.axis[0]) == pytest.approx(math.cos(0.17) * math.sin(0.17), rel=1e-12)
        assert abs(rotor.axis[1]) == pytest.approx(math.sin(0.17), rel=1e-12)
    from reedtool.checks.context import CheckContext

    trim = CheckContext(robot).trim
    thrust = (1.6 + 4 * 0.005) * 9.80665 / (4 * cz)
    # Pseudo-inverse of a tilted symmetric frame vs closed form: O(10) ulps; 1e-9 holds.
    np.testing.assert_allclose(trim.thrust_N, thrust, rtol=1e-9)


# ------------------------------------------------------- omnidirectional frame

def test_hover_test_judges_an_omni_frame_by_its_6dof_trim_then_says_it_is_not_flown(capsys):
    """validate finds the reversible omni frame's 6-DoF trim; hover-test used to run the
    4-DoF one-way trim on it and report FAILED (yaw cannot cancel): a false alarm. Its
    geometric controller does not apply to the frame: "not flown" (issue 20), which is
    not a pass (issue 26): exit 1 by default, "accepted" with --require stable."""
    omni = Path(__file__).parent / "fixtures" / "omni" / "omni_reversible.sdf"
    with pytest.raises(SystemExit) as info:
        main(["hover-test", str(omni), "--format", "json"])
    captured = capsys.readouterr()
    assert info.value.code == 1 and "Traceback" not in captured.err
    assert json.loads(captured.out)["outcome"] == "failed"
    with pytest.raises(SystemExit) as info:
        main(["hover-test", str(omni), "--format", "json", "--require", "stable"])
    captured = capsys.readouterr()
    assert info.value.code == 0 and "Traceback" not in captured.err
    report = json.loads(captured.out)
    assert report["outcome"] == "accepted"
    assert (report["status"], report["passed"], report["sim"]) == ("not-flown", True, None)
    assert "(6-DoF allocation)" in report["message"]
    assert report["message"].startswith("omnidirectional frame")


def test_hover_test_still_fails_an_omni_frame_too_heavy_to_hover(tmp_path, capsys):
    omni = Path(__file__).parent / "fixtures" / "omni" / "omni_reversible.sdf"
    text = omni.read_text()
    model = tmp_path / "omni_heavy.sdf"
    start = text.index("<mass>") + len("<mass>")
    end = text.index("</mass>", start)
    model.write_text(text[:start] + "60" + text[end:])
    with pytest.raises(SystemExit) as info:
        main(["hover-test", str(model), "--ignore-validation"])
    out = capsys.readouterr().out
    assert info.value.code == 1
    assert "INFEASIBLE (insufficient-thrust)" in out


# ------------------------------------------------------------------- px4vision

def test_px4vision_rotors_and_hover_by_hand():
    robot = load_robot(_model("px4vision_quad"))
    rotors = discover_rotors(robot)
    assert [r.motor_number for r in rotors] == [0, 1, 2, 3]
    assert [r.direction for r in rotors] == ["ccw", "ccw", "cw", "cw"]
    from reedtool.checks.context import CheckContext

    mass, k = 1.5 + 4 * 0.005, 8.54858e-06
    # Pseudo-inverse trim vs closed form: O(10) ulps (see test_trim); 1e-9 holds.
    np.testing.assert_allclose(CheckContext(robot).trim.omega_rad_s,
                               math.sqrt(mass * 9.80665 / (4 * k)), rtol=1e-9)


def test_hover_test_on_a_broken_ardupilot_model_reports_validation_not_time_constants(capsys):
    """The bad-input pre-check before the validation verdict used to demand
    <timeConstantUp> from ArduPilotPlugin rotors (exit 2, a false 'bad input')."""
    bad = Path(__file__).parent / "fixtures" / "ardupilot" / "R318_bad_multiplier_sign.sdf"
    with pytest.raises(SystemExit) as info:
        main(["hover-test", str(bad)])
    captured = capsys.readouterr()
    assert info.value.code == 1
    assert "timeConstantUp" not in captured.err
    assert captured.out.splitlines()[-1].startswith("FAILED: validate reports")


def test_fixed_wing_with_classic_lift_drag_wing_is_also_propulsion(tmp_path):
    """rc_cessna's shape: the wing is a LiftDrag plugin on the body instead."""
    text = _model("fixed_wing_puller").read_text()
    start = text.index("    <plugin filename='gz-sim-advanced-lift-drag-system'")
    end = text.index("</plugin>", start) + len("</plugin>\n")
    wing = ("    <plugin filename='gz-sim-lift-drag-system' name='gz::sim::systems::LiftDrag'>"
            "<a0>0.05984281113</a0><cla>4.752798721</cla><cda>0.6417112299</cda>"
            "<cp>-0.12 0 0</cp><area>0.34</area><forward>1 0 0</forward><upward>0 0 1</upward>"
            "<link_name>base_link</link_name></plugin>\n")
    model = tmp_path / "cessna_like.sdf"
    model.write_text(text[:start] + wing + text[end:])
    assert sorted(f.code for f in run_checks(load_robot(model))) == ["R319"]


# ------------------------------------------------- rotors on actuated joints

def _legged_quad(joint_type: str) -> str:
    """SITL_Models' hexapod_copter shape, as a quad: each rotor on a leg link whose joint
    (revolute, driven by a servo in flight) holds it sideways at the zero pose."""
    links, plugins = [], []
    for i, (x, y) in enumerate([(0.2, -0.2), (-0.2, 0.2), (0.2, 0.2), (-0.2, -0.2)]):
        links.append(f"""
    <link name="leg_{i}"><pose>{x} {y} 0 0 0 0</pose>
      <inertial><mass>0.05</mass><inertia><ixx>1e-5</ixx><ixy>0</ixy><ixz>0</ixz><iyy>1e-5</iyy><iyz>0</iyz><izz>1e-5</izz></inertia></inertial>
      <collision name="c"><geometry><box><size>0.03 0.03 0.03</size></box></geometry></collision></link>
    <joint name="leg_{i}_joint" type="{joint_type}"><parent>base_link</parent><child>leg_{i}</child>
      <axis><xyz>1 0 0</xyz><limit><lower>-1.6</lower><upper>1.6</upper></limit></axis></joint>
    <link name="rotor_{i}"><pose>{x} {y} 0.05 0 1.5707963 0</pose>
      <inertial><mass>0.005</mass><inertia><ixx>1e-6</ixx><ixy>0</ixy><ixz>0</ixz><iyy>1e-6</iyy><iyz>0</iyz><izz>2e-6</izz></inertia></inertial>
      <collision name="c"><geometry><cylinder><length>0.005</length><radius>0.03</radius></cylinder></geometry></collision></link>
    <joint name="rotor_{i}_joint" type="revolute"><parent>leg_{i}</parent><child>rotor_{i}</child>
      <axis><xyz>0 0 1</xyz><limit><lower>-1e16</lower><upper>1e16</upper></limit></axis></joint>""")
        plugins.append(f"""
    <plugin filename="gz-sim-multicopter-motor-model-system" name="gz::sim::systems::MulticopterMotorModel">
      <jointName>rotor_{i}_joint</jointName><linkName>rotor_{i}</linkName>
      <turningDirection>{'ccw' if i < 2 else 'cw'}</turningDirection><maxRotVelocity>1000</maxRotVelocity>
      <motorConstant>8.54858e-06</motorConstant><momentConstant>0.016</momentConstant>
      <actuator_number>{i}</actuator_number></plugin>""")
    return f"""<?xml version="1.0"?>
<sdf version="1.9"><model name="legged">
    <link name="base_link">
      <inertial><mass>1.5</mass><inertia><ixx>0.01</ixx><ixy>0</ixy><ixz>0</ixz><iyy>0.01</iyy><iyz>0</iyz><izz>0.02</izz></inertia></inertial>
      <collision name="c"><geometry><box><size>0.3 0.3 0.1</size></box></geometry></collision></link>{''.join(links)}{''.join(plugins)}
</model></sdf>
"""


def test_rotors_on_actuated_legs_are_not_judged_at_the_zero_pose(tmp_path):
    path = tmp_path / "legged.sdf"
    path.write_text(_legged_quad("revolute"))
    findings = run_checks(load_robot(path))
    assert [(f.code, f.severity) for f in findings] == [("R319", "info")]
    assert "leg_0_joint" in findings[0].message
    # Control: with the legs welded (fixed joints) the same sideways rotors cannot lift.
    path.write_text(_legged_quad("fixed"))
    errors = {f.code for f in run_checks(load_robot(path)) if f.severity == "error"}
    assert errors & {"R305", "R307", "R308"}
