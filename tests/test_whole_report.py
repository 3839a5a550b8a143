"""A failing rule or a broken number cannot take the report with it (issue 19).

A rule that raises becomes one error finding of its own and exit 3, the other rules'
findings are all there. A number that cannot be read (NaN, inf, 1e300, "0.35m") is
reported by its reader alone: the rules computed from it stay quiet instead of judging
"a box of nan x nan x nan m" or crashing in an SVD.
"""

from __future__ import annotations

import dataclasses
import json
import math
import re
from pathlib import Path

import pytest
from cli_helpers import run_validate

from reedtool.checks import registry
from reedtool.checks.runner import INTERNAL_ERROR, apply_suppressions, run_checks
from reedtool.io.urdf import parse_urdf

FIXTURES = Path(__file__).parent / "fixtures"
TWO_ERRORS = FIXTURES / "validate" / "S105_bad_child_missing.urdf"     # S104 + S105
HEX = FIXTURES / "validate" / "R350_bad_alternating_hex.urdf"          # R350 (info) clean
QUAD = FIXTURES / "core" / "quad_x_rotors.urdf"


@pytest.fixture
def crashing_s104(monkeypatch):
    """S104 replaced by a rule that raises, as a bug in it would."""
    def boom(ctx):
        yield from ()
        raise ZeroDivisionError("float division by zero")

    rule = registry.get_rule("S104")
    monkeypatch.setitem(registry._RULES, "S104", dataclasses.replace(rule, check=boom))


def codes(out: str) -> set[str]:
    return set(re.findall(r"\b([SIRC]\d{3})\b", out))


def test_a_crashing_rule_is_one_finding_the_rest_is_reported_exit_3(crashing_s104, capsys):
    code, out, err = run_validate([TWO_ERRORS], capsys)
    assert code == 3
    assert "S104" in out and f"{INTERNAL_ERROR}ZeroDivisionError: float division by zero" in out
    assert "S105" in out                     # the other rule's finding is still there
    assert "Traceback" not in out + err
    # --exit-zero does not hide an incomplete report.
    assert run_validate([TWO_ERRORS, "--exit-zero"], capsys)[0] == 3


def test_the_internal_error_is_in_every_format(crashing_s104, capsys):
    code, out, _ = run_validate([TWO_ERRORS, "--format", "json"], capsys)
    assert code == 3
    findings = [f for m in json.loads(out)["models"] for f in m["findings"]]
    crashed = [f for f in findings if f["message"].startswith(INTERNAL_ERROR)]
    assert [(f["code"], f["severity"]) for f in crashed] == [("S104", "error")]
    assert any(f["code"] == "S105" for f in findings)


def test_an_internal_error_cannot_be_suppressed(crashing_s104):
    robot = parse_urdf(TWO_ERRORS.read_text(), TWO_ERRORS)
    findings = run_checks(robot)
    kept, _ = apply_suppressions(findings, lambda file: ("S",))   # per-file ignore of all S
    assert [f.code for f in kept] == ["S104"]


def test_debug_lets_the_exception_through(crashing_s104, monkeypatch):
    monkeypatch.setenv("REEDTOOL_DEBUG", "1")
    with pytest.raises(ZeroDivisionError):
        run_checks(parse_urdf(TWO_ERRORS.read_text(), TWO_ERRORS))


# ------------------------------------------------------------------ broken numbers

def quad_text() -> str:
    # Without its mavlink plugin, whose rotor count (6) is a finding of its own (R312).
    return re.sub(r"<gazebo><plugin name=\"mavlink_interface\".*?</gazebo>", "",
                  QUAD.read_text(), flags=re.S)


def check(tmp_path: Path, name: str, text: str, capsys) -> tuple[int, str]:
    path = tmp_path / name
    path.write_text(text)
    code, out, err = run_validate([path], capsys)
    assert "internal error" not in out + err
    return code, out


def test_the_quad_itself_is_clean(tmp_path, capsys):
    code, out = check(tmp_path, "quad.urdf", quad_text(), capsys)
    assert code == 0 and not codes(out), out


@pytest.mark.parametrize("old, new, reader_code", [
    # An xacro body_width="0.35m" lands here: S101, and no I209 about "a box of nan m".
    ('<box size="0.47 0.47 0.11"/>', '<box size="0.35m 0.47 0.11"/>', "S101"),
    ('<mass value="1.5"/>', '<mass value="nan"/>', "S102"),           # no R340 at 0.02 kg
    ('<mass value="1.5"/>', '<mass value="one"/>', "S101"),
    ('izz="0.0799"', 'izz="1e300"', "S102"),
    ('<origin xyz="0.18738 -0.18738 0.026"', '<origin xyz="nan -0.18738 0.026"', "S102"),
    ('<motorConstant>8.54858e-06', '<motorConstant>1e300', "R316"),
    ('<maxRotVelocity>838', '<maxRotVelocity>inf', "R316"),
])
def test_a_broken_number_is_reported_by_its_reader_alone(tmp_path, capsys, old, new,
                                                         reader_code):
    text = quad_text()
    assert old in text
    code, out = check(tmp_path, "quad.urdf", text.replace(old, new, 1), capsys)
    assert code == 1 and codes(out) == {reader_code}, out


def test_nan_in_the_com_of_a_hexacopter_is_s102_alone(tmp_path, capsys):
    # RotorS firefly's shape: R350 searched spin orders on a NaN COM ("SVD did not
    # converge") and R305/R308 judged the NaN allocation.
    text = HEX.read_text().replace('<inertial><origin xyz="0 0 0"', '<inertial><origin xyz="0 nan 0"', 1)
    assert "nan" in text
    code, out = check(tmp_path, "hex.urdf", text, capsys)
    assert code == 1 and codes(out) == {"S102"}, out


def test_nan_in_a_base_joint_above_every_rotor_is_s102_alone(tmp_path, capsys):
    text = HEX.read_text()
    body = text.index('<link name="base_link"')
    text = (text[:body] + '<link name="root"/><joint name="base_joint" type="fixed">'
            '<parent link="root"/><child link="base_link"/><origin xyz="0 0 nan"/></joint>'
            + text[body:])
    code, out = check(tmp_path, "hex.urdf", text, capsys)
    assert code == 1 and codes(out) == {"S102"}, out


# ------------------------------------------------------------------ physics on any robot

def test_whole_robot_leaves_out_a_joint_child_that_is_no_link():
    from reedtool.physics.inertia import whole_robot
    from reedtool.physics.kinematics import link_poses

    text = quad_text().replace('<child link="rotor_0"/>', '<child link="ghost"/>', 1)
    robot = parse_urdf(text, "ghost.urdf")
    poses = link_poses(robot)
    assert "ghost" not in poses and set(poses) <= set(robot.link_map)
    # Base 1.5 kg and the three rotors still attached (5 g each); rotor_0 is a second root.
    # Four additions of exact-enough decimals: a few ulps (2.2e-16 each) at most.
    assert whole_robot(robot).mass_kg == pytest.approx(1.5 + 3 * 0.005, rel=1e-15)


def test_whole_robot_of_an_unreadable_mass_is_unknown_not_the_rest():
    from reedtool.physics.inertia import whole_robot

    robot = parse_urdf(quad_text().replace('<mass value="1.5"/>', '<mass value="one"/>'), "q.urdf")
    assert math.isnan(whole_robot(robot).mass_kg)      # not 0.02 kg of rotors alone
