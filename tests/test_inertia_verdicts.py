"""One verdict for `validate` and `inertia`; generated packages pass `inertia`; the RotorS
rotor-inertia convention is a known exception."""

from __future__ import annotations

import json

import numpy as np
import pytest
from cli_helpers import run_cli
from rotors_builder import multirotor_urdf

from reedtool.checks.runner import Selection, run_checks
from reedtool.io.loader import load_robot
from reedtool.physics.inertia import box_inertia, compare_links, cylinder_inertia
from reedtool.generate.airframes import MULTIROTOR_FRAMES


def rotor_model(rotor_inertia_diag, slowdown: str | None = "10", rotor_mass=0.005) -> str:
    """A body box and one RotorS-style rotor (0.1 m radius, 5 mm disc) with its motor plugin."""
    slow = {"rotorVelocitySlowdownSim": slowdown} if slowdown else {}
    base = ''.join(f"<{k}>{v}</{k}>" for k, v in {"linkName": "base_link", **slow}.items())
    return multirotor_urdf(
        1, name="r", arm_m=0.2, angles_rad=[0.0], height_m=0.05, body_kg=1,
        body_inertia=np.diag(box_inertia(1.0, (0.3, 0.3, 0.1))),
        body_xml='<collision><geometry><box size="0.3 0.3 0.1"/></geometry></collision>',
        rotor_kg=rotor_mass, rotor_inertia=rotor_inertia_diag,
        rotor_xml='<collision><geometry><cylinder length="0.005" radius="0.1"/></geometry>'
                  '</collision>',
        plugin_name="m0", motor_defaults={}, motor=slow, numbered=False,
        extra='<gazebo><plugin name="base" filename="librotors_gazebo_multirotor_base_plugin.so">'
              f"{base}</plugin></gazebo>")


# RotorS multirotor_base.xacro: box_inertia(x=radius, y=0.015, z=0.003, mass=m * slowdown).
ROTORS_MACRO = np.diag(box_inertia(0.005 * 10, (0.1, 0.015, 0.003)))
CYLINDER = np.diag(cylinder_inertia(0.005, 0.1, 0.005))


def verdicts(tmp_path, text):
    path = tmp_path / "r.urdf"
    path.write_text(text)
    robot = load_robot(path)
    i_codes = sorted(f.code for f in run_checks(robot, Selection(select=("I",))))
    return {c.link: c.verdict for c in compare_links(robot)}["rotor_0"], i_codes, path


@pytest.mark.parametrize("diag, verdict, i_codes", [
    (ROTORS_MACRO, "slowdown-scaled", []),            # RotorS's own formula times 10
    (CYLINDER * 10, "slowdown-scaled", []),           # the disc times the slowdown
    (CYLINDER, "ok", []),                             # unscaled is fine too
    (CYLINDER * 10 * 50, "implausible", ["I204"]),    # 50x beyond the convention
    (np.ones(3), "way-off", ["I209"]),                # a 1.0 placeholder
])
def test_rotor_slowdown_convention(tmp_path, diag, verdict, i_codes):
    assert verdicts(tmp_path, rotor_model(diag))[:2] == (verdict, i_codes)


def test_without_slowdown_the_same_rotor_is_flagged(tmp_path):
    # 10x the disc with no slowdown element: 10x is past the plausible factor.
    verdict, i_codes, _ = verdicts(tmp_path, rotor_model(CYLINDER * 10.5, slowdown=None))
    assert (verdict, i_codes) == ("implausible", ["I204"])


@pytest.mark.parametrize("factor", [1.0, 20.0, 300.0, 1 / 300.0, 1e5])
def test_inertia_exits_1_exactly_when_validate_has_an_inertia_error(tmp_path, factor):
    # 300x and 1/300 of a 5 g rotor disc are orders off its geometry, but the robot's
    # inertia changes by far less than 2x with either tensor: a warning. 1e5 x the disc
    # (0.6 kg·m²) dominates the robot's inertia: an error in both commands.
    _, _, path = verdicts(tmp_path, rotor_model(CYLINDER * factor, slowdown=None))
    validate_errors = [f for f in run_checks(load_robot(path), Selection(select=("I",)))
                       if f.severity == "error"]
    code, out = run_cli("inertia", path, "--format", "json")
    doc = json.loads(out)
    assert code == (1 if validate_errors else 0)
    assert code == (1 if factor == 1e5 else 0)
    failing = [link["link"] for link in doc["links"] if link["severity"] == "error"]
    assert failing == sorted({f.subject for f in validate_errors})


@pytest.mark.parametrize("frame", sorted(MULTIROTOR_FRAMES))
def test_generated_classic_package_passes_inertia(tmp_path, frame):
    name = "gen_" + frame.replace("-", "_")
    assert run_cli("new-package", name, "--frame", frame, "--ros", "1", "-o", tmp_path)[0] == 0
    model = tmp_path / name / "urdf" / "mav_generic_odometry_sensor.gazebo"
    code, out = run_cli("inertia", model, "--package-path", tmp_path, "--format", "json")
    doc = json.loads(out)
    assert code == 0, [link for link in doc["links"] if link["severity"]]
    rotors = [link for link in doc["links"] if "/rotor_" in link["link"]]
    assert rotors and {link["verdict"] for link in rotors} == {"slowdown-scaled"}


def test_generated_gz_package_passes_inertia(tmp_path):
    assert run_cli("new-package", "gz_quad", "--frame", "quad-x", "--ros", "2", "-o",
                   tmp_path)[0] == 0
    model = tmp_path / "gz_quad" / "urdf" / "gz_quad.urdf.xacro"
    assert run_cli("inertia", model, "--package-path", tmp_path)[0] == 0


def test_a_negligible_whole_robot_change_is_said_in_percent():
    """A tensor judged way off whose swap barely moves the whole robot is lowered to
    implausible, and its message gives the change in percent, never 'changes 1x' (the
    audit: a user cannot read '1x'). The rotor's comparison is marked way-off by hand;
    its declared and geometric tensors are the fixture's, a few grams on a 1.5 kg body."""
    import dataclasses
    from pathlib import Path

    from reedtool.io.loader import load_robot
    from reedtool.physics.inertia import compare_links, judge_in_robot

    robot = load_robot(Path(__file__).parent / "fixtures" / "validate" / "clean_quad_x.urdf")
    rotor = next(c for c in compare_links(robot) if "rotor" in c.link and c.derived is not None)
    way_off = dataclasses.replace(rotor, verdict="way-off", message="declared")
    (judged,) = [c for c in judge_in_robot(robot, [way_off]) if c.link == rotor.link]
    assert judged.verdict == "implausible"
    assert "%" in judged.message and " 1x" not in judged.message


# A 1 kg box body and a 0.1 kg wheel (cylinder r 0.05 m, 2 cm wide) on a continuous joint:
# no rotor, so validate's only finding is the wheel's inertia. The wheel's solid-cylinder
# tensor is m(3r^2 + l^2)/12 = 6.5833e-5 about x and y, m r^2/2 = 1.25e-4 about z.
WHEEL_SOLID = np.diag(cylinder_inertia(0.1, 0.05, 0.02))


def cart_model(wheel_diag, mass="0.1", joint="continuous") -> str:
    ixx, iyy, izz = np.diag(box_inertia(1.0, (0.3, 0.3, 0.1)))
    wxx, wyy, wzz = wheel_diag
    return f"""<?xml version="1.0"?>
<robot name="cart">
  <link name="base_link"><inertial><mass value="1"/>
    <inertia ixx="{ixx}" ixy="0" ixz="0" iyy="{iyy}" iyz="0" izz="{izz}"/></inertial>
    <collision><geometry><box size="0.3 0.3 0.1"/></geometry></collision></link>
  <joint name="wheel_joint" type="{joint}"><parent link="base_link"/><child link="wheel"/>
    <origin xyz="0.2 0 0"/><axis xyz="0 1 0"/></joint>
  <link name="wheel"><inertial><mass value="{mass}"/>
    <inertia ixx="{wxx}" ixy="0" ixz="0" iyy="{wyy}" iyz="0" izz="{wzz}"/></inertial>
    <collision><geometry><cylinder length="0.02" radius="0.05"/></geometry></collision></link>
</robot>
"""


def _exit_and_json(argv, capsys) -> tuple[int, dict]:
    from reedtool.cli import main

    with pytest.raises(SystemExit) as exc:
        main([*map(str, argv), "--format", "json"])
    return exc.value.code, json.loads(capsys.readouterr().out)


# (wheel tensor, the user's pyproject.toml [tool.reedtool] lines, the wheel's severity and
# the exit code both commands must give). 1.0 everywhere is ~1.2e4x the wheel's trace and
# decides the cart's inertia (I209, error by default); 20x the solid cylinder is past the
# 10x plausible bound but the cart flies alike (I204, warning by default).
@pytest.mark.parametrize("wheel, config, severity, code", [
    (np.ones(3), "", "error", 1),
    (np.ones(3), '[tool.reedtool.severity]\nI209 = "warning"\n', "warning", 0),
    (np.ones(3), '[tool.reedtool.severity]\nI2 = "info"\n', "info", 0),     # a prefix
    (np.ones(3), '[tool.reedtool]\nignore = ["I209"]\n', None, 0),
    (WHEEL_SOLID * 20, "", "warning", 0),
    (WHEEL_SOLID * 20, '[tool.reedtool.severity]\nI204 = "error"\n', "error", 1),
])
def test_a_severity_override_means_the_same_in_validate_and_inertia(
        tmp_path, capsys, wheel, config, severity, code):
    """The user's configuration decides a verdict's severity in `inertia` exactly as in
    `validate` (issue 29: inertia kept its own table and exited 1 on an I209 the user
    had made a warning, printing "(error, as in validate)")."""
    model = tmp_path / "cart.urdf"
    model.write_text(cart_model(wheel))
    if config:
        (tmp_path / "pyproject.toml").write_text(config)
    validate_code, validate_doc = _exit_and_json(["validate", model], capsys)
    inertia_code, inertia_doc = _exit_and_json(["inertia", model], capsys)
    by_link = {f["subject"]: f["severity"] for f in validate_doc["findings"]}
    (wheel_link,) = [link for link in inertia_doc["links"] if link["link"] == "wheel"]
    assert (validate_code, inertia_code) == (code, code)
    assert by_link.get("wheel") == wheel_link["severity"] == severity
    assert inertia_doc["failing"] == code
    # The text report says the same word.
    from cli_helpers import run_cli

    text_code, text = run_cli("inertia", model)
    assert text_code == code
    if severity in ("error", "warning"):
        assert f"({severity}, as in validate): wheel" in text
    else:
        assert "as in validate" not in text


@pytest.mark.parametrize("wheel, mass, joint, verdict", [
    (WHEEL_SOLID, "-0.1", "continuous", "negative-mass"),
    (np.zeros(3), "0", "continuous", "massless-moving"),
    (WHEEL_SOLID, "0", "continuous", "massless-inertia"),   # moving: I201 says it
    (WHEEL_SOLID, "0", "fixed", "massless-inertia"),        # fixed: I208 says it
    ((1e-4, 1e-4, 5e-4), "0.1", "continuous", "invalid"),   # 1e-4 + 1e-4 < 5e-4
    ((-1e-4, 1e-4, 1e-4), "0.1", "continuous", "invalid"),  # a negative moment
    (np.ones(3), "0.1", "continuous", "way-off"),
    (WHEEL_SOLID * 20, "0.1", "continuous", "implausible"),
])
def test_each_failing_verdict_maps_to_the_rule_validate_reports_it_with(
        tmp_path, wheel, mass, joint, verdict):
    """inertia takes a verdict's severity from one rule (workflows.validation.verdict_code);
    that must be the rule validate actually reports the link with, found by running
    validate's rules, not by reading the map back."""
    from reedtool.workflows.validation import verdict_code
    from reedtool.physics.inertia import moving_links

    model = tmp_path / "cart.urdf"
    model.write_text(cart_model(wheel, mass, joint))
    robot = load_robot(model)
    (c,) = [c for c in compare_links(robot) if c.link == "wheel"]
    assert c.verdict == verdict
    reported = {f.code for f in run_checks(robot) if f.subject == "wheel"}
    assert verdict_code(c, "wheel" in moving_links(robot)) in reported, reported
