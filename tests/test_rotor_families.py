"""Rotor families (issue 10): ArduPilotPlugin + LiftDrag, a VTOL pusher, RotorS Neo tilts
and omav servos, a reversible omnidirectional frame.

Fixtures: tests/fixtures/rotor_families.py. Every expected number is derived here by hand
from the fixture's written values (positions, LiftDrag coefficients, multipliers).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from reedtool.checks.runner import run_checks
from reedtool.io.loader import load_robot
from reedtool.physics.rotors import discover_rotors

FIXTURES = Path(__file__).parent / "fixtures"

# (fixture relative to tests/fixtures/validate, as rule_helpers.codes expects, codes)
CASES = [
    ("../ardupilot/iris_lift_drag.sdf", ["R317"] * 4),
    ("../ardupilot/R318_bad_multiplier_sign.sdf", ["R304"] + ["R317"] * 4 + ["R318"]),
    ("../ardupilot/R317_bad_no_blades.sdf", ["R317"] * 4),
    ("../ardupilot/zephyr_pusher.sdf", ["R317", "R319"]),
    ("../vtol/vtol_pusher.sdf", ["R319"]),
    ("../vtol/R304_bad_flipped_direction.sdf", ["R304", "R319"]),
    ("../vtol/R301_bad_duplicate_actuator.sdf", ["R301", "R319"]),
    ("../vtol/R311_bad_single_tilt.sdf", ["R311", "R319"]),
    ("../vtol/vtol_motor_number_alias.sdf", ["R319"]),
    ("../rotors_neo/neo_balanced_tilt.sdf", ["R320"]),
    # Its rotors ride on the tilt servos: not judged at the zero pose (R319, information).
    ("../rotors_neo/omav_tilt_servos.sdf", ["R319"]),
    ("../vtol/tailsitter_tangential_tilt.sdf", ["R320"]),
    ("../omni/omni_reversible.sdf", ["R319"]),
    # The R319/R320 pair: a pusher and a balanced tilt are information (their bad fixtures).
    ("../vtol/R319_bad_pusher.sdf", ["R319"]),
    ("../rotors_neo/R320_bad_balanced_tilt.sdf", ["R320"]),
]
GOOD = [name for name, _ in CASES if "_bad_" not in name]


def _findings(name):
    return run_checks(load_robot(FIXTURES / "validate" / name))


@pytest.mark.parametrize("name,expected", CASES, ids=[c[0] for c in CASES])
def test_codes(name, expected):
    assert sorted(f.code for f in _findings(name)) == expected


@pytest.mark.parametrize("name", GOOD)
def test_good_fixtures_have_no_error_or_warning(name):
    assert [f.code for f in _findings(name) if f.severity in ("error", "warning")] == []


def _rotors(path):
    return discover_rotors(load_robot(FIXTURES / path))


# ----------------------------------------------------------------- ArduPilot

def test_ardupilot_iris_rotors():
    rotors = _rotors("ardupilot/iris_lift_drag.sdf")
    assert [r.channel for r in rotors] == [0, 1, 2, 3]
    assert [r.motor_number for r in rotors] == [0, 1, 2, 3]
    # ArduCopter quad X: motors 1, 2 (channels 0, 1) ccw, 3, 4 cw; multiplier +838 / -838
    # on joints whose axis is +z (the thrust axis), so + is ccw.
    assert [r.direction for r in rotors] == ["ccw", "ccw", "cw", "cw"]
    expected_xy = [(0.13, -0.22), (-0.13, 0.22), (0.13, 0.22), (-0.13, -0.22)]
    for rotor, (x, y) in zip(rotors, expected_xy):
        # SDF poses composed through frames: a few ulps of ~0.3 m (< 1e-15).
        np.testing.assert_allclose(rotor.position_m, [x, y, 0.023], atol=1e-12)
        np.testing.assert_allclose(rotor.axis, [0, 0, 1], atol=1e-12)
        assert rotor.kind == "ardupilot" and rotor.role == "lift"
        assert rotor.constants_estimated and len(rotor.blades) == 2
        # Two blades, cp at r = 0.084 m: k_f = 2 * 0.5 * rho * r^2 * area * cla * a0.
        k_f = 2 * 0.5 * 1.2041 * 0.084 ** 2 * 0.002 * 4.25 * 0.3
        assert rotor.motor_constant == pytest.approx(k_f, rel=1e-12)
        assert rotor.motor_constant == pytest.approx(2.16651e-05, rel=1e-5)
        # Drag cda * a0 at r over lift cla * a0: r * cda / cla.
        assert rotor.moment_constant == pytest.approx(0.084 * 0.10 / 4.25, rel=1e-12)
        # Command [0, 1] times |multiplier|, offset 0.
        assert rotor.max_rot_velocity_rad_s == 838
        assert rotor.blade_turning_sign == rotor.turning_sign


def test_ardupilot_hover_trim_by_hand():
    from reedtool.checks.context import CheckContext

    ctx = CheckContext(load_robot(FIXTURES / "ardupilot/iris_lift_drag.sdf"))
    mass = 1.5 + 4 * 0.005
    k_f = 2 * 0.5 * 1.2041 * 0.084 ** 2 * 0.002 * 4.25 * 0.3
    assert ctx.trim.feasible
    # Pseudo-inverse trim vs closed form: O(10) ulps (see test_trim); 1e-9 holds.
    np.testing.assert_allclose(ctx.trim.omega_rad_s, math.sqrt(mass * 9.80665 / (4 * k_f)),
                               rtol=1e-9)


def test_ardupilot_multiplier_against_blades_names_the_channel():
    (finding,) = [f for f in _findings("../ardupilot/R318_bad_multiplier_sign.sdf")
                  if f.code == "R318"]
    assert "channel 2" in finding.message and finding.severity == "error"
    (yaw,) = [f for f in _findings("../ardupilot/R318_bad_multiplier_sign.sdf") if f.code == "R304"]
    assert yaw.subject == "rotor_2" and "<multiplier>" in yaw.hint


def test_ardupilot_non_velocity_controls_are_not_rotors(tmp_path):
    text = (FIXTURES / "ardupilot/iris_lift_drag.sdf").read_text()
    text = text.replace('<control channel="3">', '<control channel="3">\n<type>POSITION</type>', 1)
    text = text.replace("<type>VELOCITY</type>\n        <p_gain>0.20</p_gain><i_gain>0</i_gain>"
                        "<d_gain>0</d_gain>\n        <i_max>0</i_max><i_min>0</i_min><cmd_max>2.5"
                        "</cmd_max><cmd_min>-2.5</cmd_min>\n      </control>\n    </plugin>",
                        "<p_gain>0.20</p_gain>\n      </control>\n    </plugin>")
    path = tmp_path / "iris.sdf"
    path.write_text(text)
    assert [r.channel for r in discover_rotors(load_robot(path))] == [0, 1, 2]


def test_ardupilot_zephyr_propeller_is_propulsion_spinning_with_its_blades():
    (rotor,) = _rotors("ardupilot/zephyr_pusher.sdf")     # the elevons are POSITION servos
    assert (rotor.channel, rotor.role) == (2, "propulsion")
    # Link pitched 90°: its y is the model's y, so the blades' upward (0, -1, 0) is -y,
    # the zephyr's forward. Joint axis (0, -1, 0) is the same; (axis x cp) . forward > 0
    # for both blades, and the multiplier is +838: ccw about the thrust axis, as built.
    np.testing.assert_allclose(rotor.axis, [0, -1, 0], atol=1e-9)
    assert rotor.direction == "ccw" and rotor.blade_turning_sign == 1
    k_f = 2 * 0.5 * 1.2041 * 0.074205 ** 2 * 0.02 * 4.25 * 0.30
    # The same LiftDrag formula evaluated in another order: a few ulps; 1e-9 is margin.
    assert rotor.motor_constant == pytest.approx(k_f, rel=1e-9)


# ---------------------------------------------------------------------- VTOL

def test_vtol_pusher_is_propulsion():
    rotors = _rotors("vtol/vtol_pusher.sdf")
    roles = {r.name: r.role for r in rotors}
    assert roles == {"rotor_0": "lift", "rotor_1": "lift", "rotor_2": "lift", "rotor_3": "lift",
                     "rotor_puller": "propulsion"}
    pusher = rotors[-1]
    np.testing.assert_allclose(pusher.axis, [1, 0, 0], atol=1e-9)  # pitch 90°: z onto +x
    np.testing.assert_allclose(pusher.position_m, [-0.35, 0, 0], atol=1e-12)
    assert [r.motor_number for r in rotors] == [0, 1, 2, 3, 4]
    assert all(r.number_tag == "actuator_number" for r in rotors)
    alias = _rotors("vtol/vtol_motor_number_alias.sdf")
    assert [r.motor_number for r in alias] == [0, 1, 2, 3, 4]
    assert alias[3].number_tag == "motorNumber"


def test_gz_missing_number_hint_names_actuator_number(tmp_path):
    path = tmp_path / "vtol.sdf"
    path.write_text((FIXTURES / "vtol/vtol_pusher.sdf").read_text().replace(
        "      <actuator_number>2</actuator_number>\n", ""))
    findings = [f for f in run_checks(load_robot(path)) if f.code == "R302"]
    assert len(findings) == 1
    assert "<actuator_number>" in findings[0].message + findings[0].hint
    assert "motorNumber" not in findings[0].message + findings[0].hint


def test_vtol_hover_test_uses_lift_rotors(capsys):
    import json

    from reedtool.cli import main

    with pytest.raises(SystemExit) as info:
        main(["hover-test", str(FIXTURES / "vtol/vtol_pusher.sdf"), "--format", "json"])
    report = json.loads(capsys.readouterr().out)
    assert info.value.code == 0 and report["passed"] is True
    table = report["model"]["rotor_table"]
    assert [(r["name"], r["role"]) for r in table][-1] == ("rotor_puller", "propulsion")
    assert [r["role"] for r in table[:4]] == ["lift"] * 4
    trim = report["trim"]
    assert trim["feasible"] and len(trim["rotors"]) == 4
    # Symmetric quad about the COM: each rotor carries a quarter of the weight.
    mass = 5.0 + 5 * 0.005
    # The pusher's mass sits at x = -0.35; COM shifts, so check the sum, not each speed.
    total = sum(r["thrust_N"] for r in trim["rotors"])
    assert total == pytest.approx(mass * 9.80665, rel=1e-9)


@pytest.mark.parametrize("rpy,tilt", [("1.5707963267949 0 0", 90.0), ("3.14159265358979 0 0", 180.0)])
def test_sideways_or_downward_rotor_on_a_wingless_quad_is_not_propulsion(tmp_path, rpy, tilt):
    """Rolled 90° (axis along y) or 180° (down) by mistake: still a lift rotor, R311 warns."""
    text = (FIXTURES / "vtol/vtol_pusher.sdf").read_text()
    text = text.replace("<pose>0.35 -0.35 0.08 0 0 0</pose>", f"<pose>0.35 -0.35 0.08 {rpy}</pose>")
    start = text.index("<!-- the wing")
    text = text[:start] + text[text.index("\n", start) + 1:]
    lift_drag = text.index('<plugin filename="gz-sim-lift-drag-system"')
    text = text[:lift_drag] + text[text.index("</plugin>", lift_drag) + len("</plugin>"):]
    path = tmp_path / "quad.sdf"
    path.write_text(text)
    robot = load_robot(path)
    roles = {r.name: r.role for r in discover_rotors(robot)}
    assert roles["rotor_0"] == "lift" and roles["rotor_puller"] == "propulsion"
    tilt_findings = [f for f in run_checks(robot) if f.code == "R311"]
    assert [f.subject for f in tilt_findings] == ["rotor_0"]
    assert f"tilted {tilt:.1f}°" in tilt_findings[0].message


# ----------------------------------------------------------------- RotorS

NEO_RPY = [  # rpy of neo11.xacro's six rotor joints, motor numbers 0..5
    (5, 0, 30), (0, -5, 0), (5, 0, 150), (-5, 0, -150), (0, 5, 180), (-5, 0, -30)]


def test_neo_tilts_are_five_degrees_alternating():
    rotors = _rotors("rotors_neo/neo_balanced_tilt.sdf")
    assert len(rotors) == 6 and [r.motor_number for r in rotors] == list(range(6))
    for i, (rotor, rpy) in enumerate(zip(rotors, NEO_RPY)):
        r, p, y = (math.radians(v) for v in rpy)
        # z column of Rz(y) Ry(p) Rx(r), written out.
        expected = [math.cos(y) * math.sin(p) * math.cos(r) + math.sin(y) * math.sin(r),
                    math.sin(y) * math.sin(p) * math.cos(r) - math.cos(y) * math.sin(r),
                    math.cos(p) * math.cos(r)]
        # SDF rpy in degrees -> radians -> matrix: a few ulps (~1e-16); 1e-9 is margin, a
        # wrong rotation order moves the axis by ~1e-2 at these 5 deg tilts.
        np.testing.assert_allclose(rotor.axis, expected, atol=1e-9)
        assert rotor.tilt_deg == pytest.approx(5.0, abs=1e-6)
        # The lean is tangential (about the arm), its sign alternating around the frame.
        bearing = math.atan2(rotor.position_m[1], rotor.position_m[0])
        tangential = -math.sin(bearing) * rotor.axis[0] + math.cos(bearing) * rotor.axis[1]
        assert tangential == pytest.approx((-1) ** (i + 1) * math.sin(math.radians(5)),
                                           abs=2e-3)
        assert rotor.direction == ("ccw" if i % 2 == 0 else "cw")


def test_tailsitter_tilts_by_hand():
    rotors = _rotors("vtol/tailsitter_tangential_tilt.sdf")
    # z axis of Ry(pitch) Rx(roll): (cos r sin p, -sin r, cos r cos p).
    a, b = math.cos(0.17) * math.sin(0.17), math.sin(0.17)
    expected = [(-a, -b), (a, b), (-a, b), (a, -b)]
    for rotor, (ax, ay) in zip(rotors, expected):
        np.testing.assert_allclose(rotor.axis[:2], [ax, ay], atol=1e-12)
    # Side forces cancel; tilt yaw torques x*a_y - y*a_x cancel in pairs.
    assert sum(r.axis[0] for r in rotors) == pytest.approx(0, abs=1e-12)
    torques = [r.position_m[0] * r.axis[1] - r.position_m[1] * r.axis[0] for r in rotors]
    assert torques[0] == pytest.approx(-(0.145 * b + 0.23 * a))
    # Pairs cancelling products of ~0.2 m and ~0.17: a few ulps (~1e-17) each.
    assert sum(torques) == pytest.approx(0, abs=1e-12)


def test_unbalanced_tilt_pattern_is_a_warning_per_rotor(tmp_path):
    """Flip one tailsitter rotor's roll: the side forces no longer cancel."""
    text = (FIXTURES / "vtol/tailsitter_tangential_tilt.sdf").read_text()
    path = tmp_path / "ts.sdf"
    path.write_text(text.replace("<pose>0.145 -0.23 0.1 0.17 -0.17 0</pose>",
                                 "<pose>0.145 -0.23 0.1 -0.17 -0.17 0</pose>"))
    codes = [f.code for f in run_checks(load_robot(path)) if f.code in ("R311", "R320")]
    assert codes == ["R311"] * 4


def test_omav_servos_are_not_rotors():
    rotors = _rotors("rotors_neo/omav_tilt_servos.sdf")
    assert len(rotors) == 12
    assert sorted(r.motor_number for r in rotors) == list(range(12))
    assert not [r for r in rotors if r.link.startswith("arm_")]


# --------------------------------------------------------------------- omni

def test_omni_frame_uses_6dof_allocation():
    from reedtool.checks.context import CheckContext

    ctx = CheckContext(load_robot(FIXTURES / "omni/omni_reversible.sdf"))
    assert len(ctx.rotors) == 8 and all(r.reversible for r in ctx.rotors)
    assert ctx.omnidirectional and all(r.role == "lift" for r in ctx.rotors)
    assert np.linalg.matrix_rank(ctx.wrench_allocation) == 6
    trim = ctx.trim
    assert trim.feasible
    # The trim thrusts produce exactly the weight upward and nothing else.
    W = ctx.wrench_allocation
    weight = (1.5 + 8 * 0.005) * 9.80665
    np.testing.assert_allclose(W @ trim.thrust_N, [0, 0, weight, 0, 0, 0], atol=1e-6)


def test_omni_without_reversible_and_spread_is_not_omni(tmp_path):
    path = tmp_path / "omni.sdf"
    path.write_text((FIXTURES / "omni/omni_reversible.sdf").read_text().replace(
        "<reversible>true</reversible>", "<reversible>false</reversible>"))
    from reedtool.physics.rotors import is_omnidirectional

    rotors = discover_rotors(load_robot(path))
    # Axes still span every direction (cube corners, tangential lean): omnidirectional.
    assert is_omnidirectional(rotors) and not any(r.reversible for r in rotors)


# ------------------------------------------------------------- odd inputs

ODD_EDITS = [
    ("<multiplier>838</multiplier>", "<multiplier>fast</multiplier>"),
    ('<control channel="1">', '<control channel="one">'),
    ("<cp>0.084 0 0</cp>", "<cp>0.084 0</cp>"),
    ("<forward>0 1 0</forward>", "<forward>0 0 0</forward>"),
    ("<upward>0 0 1</upward>", "<upward>nan nan nan</upward>"),
    ("<a0>0.3</a0>", "<a0>x</a0>"),
    ("<jointName>rotor_1_joint</jointName>", ""),
    ("<jointName>rotor_1_joint</jointName>", "<jointName>nope</jointName>"),
    ("<type>VELOCITY</type>", "<type>weird</type>"),
    ("<offset>0</offset>", "<offset>-1</offset>"),
    ("<link_name>rotor_0</link_name>", "<link_name>missing</link_name>"),
    ('<control channel="0">', ('<control channel="0"><rotorVelocitySlowdownSim>0'
                              '</rotorVelocitySlowdownSim>')),
]


@pytest.mark.parametrize("old,new", ODD_EDITS, ids=[e[1][:30] or "removed" for e in ODD_EDITS])
def test_odd_ardupilot_input_never_raises(tmp_path, old, new):
    text = (FIXTURES / "ardupilot/iris_lift_drag.sdf").read_text()
    assert old in text
    path = tmp_path / "odd.sdf"
    path.write_text(text.replace(old, new))
    robot = load_robot(path)
    rotors = discover_rotors(robot)
    assert 3 <= len(rotors) <= 4
    run_checks(robot)


def test_missing_ardupilot_joint_is_reported(tmp_path):
    text = (FIXTURES / "ardupilot/iris_lift_drag.sdf").read_text()
    path = tmp_path / "odd.sdf"
    path.write_text(text.replace("<jointName>rotor_1_joint</jointName>",
                                 "<jointName>rotor_9_joint</jointName>"))
    codes = [f.code for f in run_checks(load_robot(path)) if f.severity == "error"]
    assert codes == ["R314"]


def test_scoped_ardupilot_names_resolve(tmp_path):
    """Classic models write `iris::rotor_0_joint` / `iris::rotor_0`; Gazebo resolves them."""
    text = (FIXTURES / "ardupilot/iris_lift_drag.sdf").read_text()
    for i in range(4):
        text = text.replace(f"<jointName>rotor_{i}_joint</jointName>",
                            f"<jointName>iris::rotor_{i}_joint</jointName>")
        text = text.replace(f"<link_name>rotor_{i}</link_name>",
                            f"<link_name>iris::rotor_{i}</link_name>")
    path = tmp_path / "scoped.sdf"
    path.write_text(text)
    robot = load_robot(path)
    rotors = discover_rotors(robot)
    assert [r.joint for r in rotors] == [f"rotor_{i}_joint" for i in range(4)]
    assert all(len(r.blades) == 2 for r in rotors)
    assert [f.code for f in run_checks(robot) if f.severity != "info"] == []


GZ_FIXTURES = ("omni/omni_reversible.sdf", "vtol/vtol_pusher.sdf")


def _edited(tmp_path, fixture, old=None, new=None, name="odd.sdf"):
    """The fixture with every `old` replaced by `new` (None: as it is): (robot, rotors,
    findings). The edit must change the text: a mutation of an absent string tests nothing."""
    text = (FIXTURES / fixture).read_text()
    if old is not None:
        assert old in text and old != new, f"{fixture}: replacing {old} changes nothing"
        text = text.replace(old, new)
    path = tmp_path / name
    path.write_text(text)
    robot = load_robot(path)
    findings = run_checks(robot)
    crashed = [f"{f.code}: {f.message}" for f in findings
               if f.message.startswith("internal error in this rule")]
    assert not crashed
    return robot, discover_rotors(robot), findings


def _said(findings) -> list[tuple[str, str, str]]:
    return sorted((f.code, f.severity, f.message) for f in findings)


def test_an_odd_reversible_word_reads_as_sdformat_reads_it(tmp_path):
    """gz-sim reads `<reversible>` with Element::Get<bool>(): sdformat accepts true/false/
    1/0 in any case and gives bool() = false for any other word (Param.cc "Invalid boolean
    value"). So "maybe" is "false": the omnicopter's eight motors spin one way only, and
    every finding is the one the model with "false" written gets."""
    old = "<reversible>true</reversible>"
    _, rotors, findings = _edited(tmp_path, "omni/omni_reversible.sdf", old,
                                  "<reversible>maybe</reversible>")
    _, rotors_false, findings_false = _edited(tmp_path, "omni/omni_reversible.sdf", old,
                                              "<reversible>false</reversible>", "false.sdf")
    assert len(rotors) == 8 and not any(r.reversible for r in rotors)
    assert _said(findings) == _said(findings_false)
    assert any("(0 reversible)" in f.message for f in findings if f.code == "R319")
    _, rotors_upper, _ = _edited(tmp_path, "omni/omni_reversible.sdf", old,
                                 "<reversible>TRUE</reversible>", "upper.sdf")
    assert all(r.reversible for r in rotors_upper)


@pytest.mark.parametrize("fixture", GZ_FIXTURES)
def test_a_word_for_an_actuator_number_is_an_error_naming_it(tmp_path, fixture):
    # gz-sim's Get<int>() gives int() = 0 for "three": the motor would listen to output 0.
    _, original, _ = _edited(tmp_path, fixture, name="original.sdf")
    _, rotors, findings = _edited(tmp_path, fixture, "<actuator_number>3</actuator_number>",
                                  "<actuator_number>three</actuator_number>")
    assert [r.joint for r in rotors] == [r.joint for r in original]
    named = [f for f in findings if "'three'" in f.message]
    assert [(f.code, f.severity, f.subject) for f in named] == [("R302", "error", "rotor_3")]


@pytest.mark.parametrize("fixture", GZ_FIXTURES)
def test_motor_type_is_compared_exactly_as_the_motor_plugins_do(tmp_path, fixture):
    """gz-sim's MulticopterMotorModel (and RotorS' gazebo_motor_model) compare the word
    exactly: "position" makes a servo, "POSITION" is not one of their words and leaves the
    default, a velocity motor (an error in Gazebo's log, nothing else changes)."""
    old = "<motorType>velocity</motorType>"
    _, original, findings_original = _edited(tmp_path, fixture, name="original.sdf")
    _, rotors, findings = _edited(tmp_path, fixture, old, "<motorType>POSITION</motorType>")
    assert [(r.joint, r.motor_number) for r in rotors] == \
        [(r.joint, r.motor_number) for r in original]
    assert len(rotors) == (FIXTURES / fixture).read_text().count(old) > 0
    assert _said(findings) == _said(findings_original)
    _, servos, _ = _edited(tmp_path, fixture, old, "<motorType>position</motorType>",
                           "servo.sdf")
    assert servos == []


def test_hover_test_derives_ardupilot_time_constant_from_the_pid(capsys):
    """iris: rotor izz 2.5e-05 kg m^2 about its +z joint, p_gain 0.20, d_gain 0: a P
    controller on joint speed gives tau = I / p = 1.25e-4 s (hand-derived)."""
    from reedtool.cli import main

    with pytest.raises(SystemExit) as info:
        main(["hover-test", str(FIXTURES / "ardupilot/iris_lift_drag.sdf")])
    out = capsys.readouterr().out
    assert info.value.code == 0
    derived = [line for line in out.splitlines() if line.startswith("derived: ")]
    assert len(derived) == 4
    assert all("0.000125 s derived from the ArduPilotPlugin velocity PID" in line
               for line in derived)
    assert "cmd_max/p_gain = 12.5 rad/s" in derived[0]   # 2.5 N*m / 0.2


def test_hover_test_refuses_ardupilot_pid_with_integral_term(tmp_path, capsys):
    from reedtool.cli import main

    text = (FIXTURES / "ardupilot/iris_lift_drag.sdf").read_text()
    assert "<i_gain>0</i_gain>" in text
    model = tmp_path / "iris_pi.sdf"
    model.write_text(text.replace("<i_gain>0</i_gain>", "<i_gain>0.5</i_gain>"))
    with pytest.raises(SystemExit) as info:
        main(["hover-test", str(model)])
    err = capsys.readouterr().err
    assert info.value.code == 2
    assert "integral term (i_gain 0.5)" in err and "second order" in err
    assert "Traceback" not in err and len(err.strip().splitlines()) <= 2


def test_ardupilot_rotor_spun_about_another_axis_is_r341_not_r318(tmp_path):
    """SITL_Models' alti_transition_quad's shape: the forward motor's joint turns about the
    vertical while its blades face forward. With the joint 90° from the thrust axis there is
    no spin direction about the thrust axis to compare: R341 (warning) says what is wrong,
    R318 says nothing. The R318 bad fixture's flipped rotor 2, its joint turned to x:"""
    text = (FIXTURES / "ardupilot/R318_bad_multiplier_sign.sdf").read_text()
    at = text.index('<joint name="rotor_2_joint"')
    at = text.index("<xyz>0 0 1</xyz>", at)
    text = text[:at] + "<xyz>1 0 0</xyz>" + text[at + len("<xyz>0 0 1</xyz>"):]
    path = tmp_path / "model.sdf"
    path.write_text(text)
    found = [(f.code, f.subject) for f in run_checks(load_robot(path))
             if f.code in ("R318", "R341")]
    assert found == [("R341", "rotor_2_joint")]


def test_migrate_ports_exactly_the_motor_plugins_discovery_reads():
    """One table of motor plugins: the Classic motor models migrate ports are those rotor
    discovery reads as RotorS / PX4 classic rotors (librotors_gazebo_motor_model.so,
    libgazebo_motor_model.so), and the gz system it writes is one discovery reads as gz."""
    from reedtool.model import motor_plugin_family
    from reedtool.port.gz_port import MOTOR_SYSTEM, PLUGIN_FAMILIES

    (motor,) = [f for f in PLUGIN_FAMILIES if f.action == "motor"]
    assert {lib: motor_plugin_family(f"lib{lib}.so", None) for lib in motor.libraries} == \
        {"rotors_gazebo_motor_model": "rotors", "gazebo_motor_model": "px4"}
    assert motor_plugin_family(*MOTOR_SYSTEM) == "gz"
