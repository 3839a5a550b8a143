"""Controller cross-check (C4xx): tables read with their lines, one good and bad case per rule.

Bad cases are the good fixtures with one edit each; expected lines are found in the fixture
text itself (like `grep -n`), not taken from the code under test.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from reedtool.checks.runner import Selection, run_checks
from reedtool.errors import ReedtoolError
from reedtool.flightstack.controller_tables import (
    load_controller_yaml,
    parse_controller_yaml,
    velocity_control_tables,
)
from reedtool.io.loader import load_robot

GZ = Path(__file__).parent / "fixtures" / "gz"
SDF = (GZ / "x3_quad.sdf").read_text()
URDF = (GZ / "x3_quad.urdf").read_text()
YAML = (GZ / "x3_rotors.yaml").read_text()
CONFIG_START = SDF.index("<rotorConfiguration>")


def replace_nth(text: str, old: str, new: str, n: int = 0, start: int = 0) -> str:
    """Replace the n-th occurrence (0-based) of `old` at or after `start`."""
    at = start - 1
    for _ in range(n + 1):
        at = text.index(old, at + 1)
    return text[:at] + new + text[at + len(old):]


def line_of(text: str, needle: str, n: int = 0, start: int = 0) -> int:
    at = start - 1
    for _ in range(n + 1):
        at = text.index(needle, at + 1)
    return text.count("\n", 0, at) + 1


def run(tmp_path: Path, model_text: str = SDF, suffix: str = ".sdf",
        yaml_texts: tuple[str, ...] = ()) -> list:
    model = tmp_path / f"x3{suffix}"
    model.write_text(model_text)
    controllers = []
    for i, text in enumerate(yaml_texts):
        path = tmp_path / f"controller{i}.yaml"
        path.write_text(text)
        controllers.append(load_controller_yaml(path))
    return run_checks(load_robot(model), Selection(), controllers=controllers)


def codes(findings) -> list[str]:
    return sorted(f.code for f in findings)


def swap_in_config(text: str, a: str, b: str) -> str:
    head, config = text[:CONFIG_START], text[CONFIG_START:]
    return head + config.replace(a, "@@").replace(b, a).replace("@@", b)


# --------------------------------------------------------------- clean across every family

@pytest.mark.parametrize("model_text, suffix", [(SDF, ".sdf"), (URDF, ".urdf")])
def test_hand_written_gz_quadrotor_validates_clean(tmp_path, model_text, suffix):
    assert run(tmp_path, model_text, suffix, (YAML,)) == []


# --------------------------------------------------------------- velocity control

VELOCITY_CASES = {
    "direction-flipped": (replace_nth(SDF, "<direction>-1</direction>", "<direction>1</direction>",
                                      start=CONFIG_START), ["C404"]),
    "force-constant": (replace_nth(SDF, "<forceConstant>8.54858e-06", "<forceConstant>9.5e-06", 1),
                       ["C407"]),
    "moment-constant": (replace_nth(SDF, "<momentConstant>0.016", "<momentConstant>0.02", 2,
                                    start=CONFIG_START), ["C408"]),
    "unknown-joint": (replace_nth(SDF, "X3/rotor_3_joint", "X3/rotor_9_joint", start=CONFIG_START),
                      ["C402"]),
    "order": (swap_in_config(SDF, "X3/rotor_0_joint", "X3/rotor_1_joint"), ["C403", "C403"]),
    "count": (SDF[:SDF.rindex("<rotor>")] + SDF[SDF.rindex("</rotor>") + len("</rotor>"):],
              ["C401"]),
    "com-link-missing": (SDF.replace("<comLinkName>X3/base_link</comLinkName>", ""), ["C412"]),
    "com-link-unknown": (SDF.replace("<comLinkName>X3/base_link", "<comLinkName>X3/body"),
                         ["C412"]),
    "entry-incomplete": (replace_nth(SDF, "<direction>-1</direction>", "", 1, start=CONFIG_START),
                         ["C411"]),
    "direction-not-unit": (replace_nth(SDF, "<direction>1</direction>", "<direction>2</direction>",
                                       start=CONFIG_START), ["C411"]),
}


@pytest.mark.parametrize("case", sorted(VELOCITY_CASES))
def test_velocity_control_cases(tmp_path, case):
    text, expected = VELOCITY_CASES[case]
    assert text != SDF
    assert codes(run(tmp_path, text)) == expected


def test_flipped_direction_is_one_finding_naming_both_lines(tmp_path):
    text, _ = VELOCITY_CASES["direction-flipped"]
    (finding,) = run(tmp_path, text)
    controller_line = line_of(text, "<direction>1</direction>", 2, start=CONFIG_START)
    motor_line = line_of(text, "<turningDirection>cw</turningDirection>")
    assert (finding.code, finding.line) == ("C404", controller_line)
    assert f"x3.sdf:{motor_line}" in finding.message
    assert "+1 (ccw)" in finding.message and "turns cw" in finding.message


def test_urdf_gazebo_blocks_are_cross_checked_too(tmp_path):
    text = replace_nth(URDF, "<direction>-1</direction>", "<direction>1</direction>")
    (finding,) = run(tmp_path, text, ".urdf")
    assert finding.code == "C404"
    assert finding.line == line_of(text, "<direction>1</direction>", 2)


def test_velocity_control_table_reading():
    robot = load_robot(GZ / "x3_quad.sdf")
    (table,) = velocity_control_tables(robot)
    assert (table.source, table.com_link, table.problems) == \
        ("velocity-control", "X3/base_link", [])
    assert [(e.index, e.joint_name, e.direction) for e in table.rotors] == [
        (0, "X3/rotor_0_joint", 1.0), (1, "X3/rotor_1_joint", 1.0),
        (2, "X3/rotor_2_joint", -1.0), (3, "X3/rotor_3_joint", -1.0)]
    assert table.rotors[1].loc.line == line_of(SDF, "<rotor>", 1)
    assert table.rotors[1].loc_of("force_constant").line == \
        line_of(SDF, "<forceConstant>", 1)


# --------------------------------------------------------------- RotorS YAML

def yaml_entry(text: str, index: int, old: str, new: str) -> str:
    start = text.index(f"'{index}':")
    return replace_nth(text, old, new, start=start)


YAML_CASES = {
    "mass-2-percent": ((GZ / "x3_rotors_mass_off.yaml").read_text(), ["C409"]),
    "xy-swapped": ((GZ / "x3_rotors_xy_swapped.yaml").read_text(), ["C405"] * 4),
    "arm-length": (yaml_entry(YAML, 2, "arm_length: 0.255539", "arm_length: 0.3"), ["C406"]),
    "direction": (yaml_entry(YAML, 1, "direction: 1.0", "direction: -1.0"), ["C404"]),
    "force-constant": (yaml_entry(YAML, 0, "rotor_force_constant: 8.54858e-06",
                                  "rotor_force_constant: 8.0e-06"), ["C407"]),
    "moment-constant": (yaml_entry(YAML, 3, "rotor_moment_constant: 0.016",
                                   "rotor_moment_constant: 0.06"), ["C408"]),
    "inertia": (YAML.replace("zz: 0.056631", "zz: 0.0977"), ["C410"]),
    "key-gap": (YAML.replace("'3':", "'4':"), ["C401", "C411"]),
    "missing-field": (yaml_entry(YAML, 0, ", direction: 1.0", ""), ["C411"]),
    "order": (YAML.replace("'0':", "'x':").replace("'2':", "'0':").replace("'x':", "'2':"),
              ["C404", "C404", "C405", "C405"]),
}


@pytest.mark.parametrize("case", sorted(YAML_CASES))
def test_controller_yaml_cases(tmp_path, case):
    text, expected = YAML_CASES[case]
    assert text != YAML
    assert codes(run(tmp_path, yaml_texts=(text,))) == expected


def test_mass_two_percent_off_reports_both_values(tmp_path):
    text, _ = YAML_CASES["mass-2-percent"]
    (finding,) = run(tmp_path, yaml_texts=(text,))
    assert finding.file.endswith("controller0.yaml") and finding.line == line_of(text, "mass:")
    assert "1.5504 kg" in finding.message and "1.52 kg" in finding.message
    assert "x3.sdf:" in finding.message


def test_xy_swapped_angles_report_both_values_and_say_why(tmp_path):
    text, _ = YAML_CASES["xy-swapped"]
    findings = run(tmp_path, yaml_texts=(text,))
    first = next(f for f in findings if f.line == line_of(text, "'0':"))
    # Rotor 0 sits at (0.13, -0.22): atan2(-0.22, 0.13) = -1.0371 rad; the table has 2.6079.
    assert "2.6079 rad" in first.message and "-1.0371 rad" in first.message
    assert "x3.sdf:" in first.message
    assert all("x and y swapped" in f.hint for f in findings)


def test_swapped_entries_are_reported_as_an_ordering_mistake(tmp_path):
    text, _ = YAML_CASES["order"]
    findings = [f for f in run(tmp_path, yaml_texts=(text,)) if f.code == "C405"]
    assert len(findings) == 2 and all("motorNumber i" in f.hint for f in findings)
    mirrored = YAML.replace("angle: -1.037088", "angle: +X").replace(
        "angle: 1.037088", "angle: -1.037088").replace("angle: +X", "angle: 1.037088")
    findings = run(tmp_path, yaml_texts=(mirrored,))
    assert codes(findings) == ["C405", "C405"] and all("mirrored" in f.hint for f in findings)


def test_arm_length_change_is_one_finding_naming_both_lines(tmp_path):
    text, _ = YAML_CASES["arm-length"]
    (finding,) = run(tmp_path, URDF, ".urdf", (text,))
    assert finding.code == "C406" and finding.line == line_of(text, "'2':")
    joint_origin = line_of(URDF, '<origin xyz="0.13 0.22 0.023"')
    assert f"x3.urdf:{joint_origin}" in finding.message
    assert "0.3 m" in finding.message and "0.2555 m" in finding.message


def test_yaml_values_and_lines():
    table = parse_controller_yaml(YAML, "x3_rotors.yaml")
    assert table.mass_kg == 1.52 and table.locs["mass"].line == line_of(YAML, "\nmass:") + 1
    # Exact: a decimal read by float() is the same double as the same literal.
    assert table.inertia_kg_m2[2, 2] == 0.056631
    assert [e.direction for e in table.rotors] == [1.0, 1.0, -1.0, -1.0]
    assert table.rotors[2].angle_rad == 1.037088 and table.rotors[2].arm_length_m == 0.255539
    assert table.rotors[2].loc.line == line_of(YAML, "'2':")


def test_ros2_parameter_file_layout_is_found():
    nested = "lee_position_controller:\n  ros__parameters:\n" + "".join(
        "    " + line + "\n" for line in YAML.splitlines())
    table = parse_controller_yaml(nested, "params.yaml")
    # Exact: decimal text read by float() equals the literal.
    assert len(table.rotors) == 4 and table.mass_kg == 1.52
    assert table.rotors[0].loc.line == line_of(nested, "'0':")


@pytest.mark.parametrize("text, fragment", [
    ("mass: [1.0\n", "malformed YAML"),
    ("mass: 1.0\ninertia: {xx: 1}\n", "no rotor_configuration"),
])
def test_unreadable_yaml_is_one_reedtool_error(tmp_path, text, fragment):
    path = tmp_path / "c.yaml"
    path.write_text(text)
    with pytest.raises(ReedtoolError) as info:
        load_controller_yaml(path)
    assert fragment in info.value.message


def test_cli_controller_option(tmp_path):
    from click.testing import CliRunner

    from reedtool.cli import cli

    result = CliRunner().invoke(
        cli, ["validate", str(GZ / "x3_quad.sdf"), "--format", "json", "--controller",
              str(GZ / "x3_rotors_xy_swapped.yaml"), "--controller", str(GZ / "x3_rotors.yaml")],
        standalone_mode=False)
    assert result.exception is None and result.return_value == 1
    report = json.loads(result.output)
    assert [f["code"] for f in report["findings"]] == ["C405"] * 4
    assert {Path(f["file"]).name for f in report["findings"]} == {"x3_rotors_xy_swapped.yaml"}
