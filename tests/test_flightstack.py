"""Flight-stack cross-check (C413-C439): PX4 airframes and ArduPilot frames against the model.

Good pairs are hand-written fixtures in the shape of PX4's 4001_gz_x500 + x500 and of
ArduPilot's quad X .parm + iris; each bad case is one edit of them. Expected numbers are
derived by hand from the fixture values (masses, motor constant, positions), expected
lines by searching the fixture text.
"""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pytest

from reedtool.checks.runner import Selection, run_checks
from reedtool.errors import ReedtoolError
from reedtool.flightstack import ardupilot, px4
from reedtool.io.loader import load_robot

FIX = Path(__file__).parent / "fixtures" / "flightstack"
X500 = FIX / "x500_flat.sdf"
AIRFRAME = (FIX / "x500_airframe").read_text()
PARM = (FIX / "iris_quad_x.parm").read_text()
G = 9.80665


def line_of(text: str, needle: str) -> int:
    return text[:text.index(needle)].count("\n") + 1


def px4_findings(tmp_path, airframe_text: str, model: Path = X500, name="airframe"):
    path = tmp_path / name
    path.write_text(airframe_text)
    return run_checks(load_robot(model), Selection(select=("C",)),
                      flight_params=[px4.load_px4_params(path)])


def ap_findings(tmp_path, parm_text: str, model: Path = X500):
    path = tmp_path / "vehicle.parm"
    path.write_text(parm_text)
    return run_checks(load_robot(model), Selection(select=("C",)),
                      flight_params=[ardupilot.load_parm(path)])


def not_info(findings) -> list[str]:
    return sorted(f.code for f in findings if f.severity != "info")


def x500_hover_setpoint() -> float:
    """By hand: total mass, thrust per rotor, speed, command through MIN 150 / MAX 1000."""
    mass = 2.0 + 4 * 0.0160769
    omega = math.sqrt(mass * G / 4 / 8.54858e-06)
    return (omega - 150.0) / (1000.0 - 150.0)


# --------------------------------------------------------------- reading

def test_airframe_and_qgc_export_read_the_same_values():
    script = px4.load_px4_params(FIX / "x500_airframe")
    qgc = px4.load_px4_params(FIX / "x500_qgc.params")
    for name in ("CA_ROTOR_COUNT", "CA_ROTOR1_PY", "CA_ROTOR3_KM", "SIM_GZ_EC_MIN2",
                 "SIM_GZ_EC_FUNC4", "MPC_THR_HOVER"):
        assert script.get(name).value == qgc.get(name).value
    # Exact: decimal text read by float() equals the literal.
    assert script.get("CA_ROTOR1_PY").value == -0.20
    assert script.get("CA_ROTOR1_PY").loc.line == line_of(AIRFRAME, "CA_ROTOR1_PY")
    assert [r.index for r in script.rotors()] == [0, 1, 2, 3]
    assert script.outputs_of(2) == [3]


def test_param_set_beats_set_default_in_any_order():
    params = px4.parse_px4_params("param set MPC_THR_HOVER 0.4\n"
                                  "param set-default MPC_THR_HOVER 0.6\n", "a")
    # Exact: decimal text read by float() equals the literal (defaults are literals).
    assert params.get("MPC_THR_HOVER").value == 0.4
    assert params.get("MPC_THR_HOVER").loc.line == 1
    # Unset values are PX4's documented defaults (CA_ROTORi_AZ -1: thrust up).
    assert params.get("CA_ROTOR0_AZ").value == -1.0 and not params.get("CA_ROTOR0_AZ").explicit


def test_bad_values_are_one_line_errors(tmp_path):
    with pytest.raises(ReedtoolError) as err:
        px4.parse_px4_params("\n\nparam set-default CA_ROTOR0_PX abc\n", "f")
    assert err.value.line == 3
    with pytest.raises(ReedtoolError):
        ardupilot.parse_parm("FRAME_CLASS one\n", "p")
    (tmp_path / "empty").write_text("# nothing\n")
    with pytest.raises(ReedtoolError):
        px4.load_px4_params(tmp_path / "empty")


def test_documented_ranges_table():
    assert px4.PARAM_RANGES["CA_ROTOR_COUNT"][:2] == (0, 12)
    assert px4.PARAM_RANGES["CA_ROTOR#_KM"][:2] == (-1.0, 1.0)
    assert px4.range_key("CA_ROTOR11_KM") == "CA_ROTOR#_KM"
    assert px4.range_key("SIM_GZ_EC_MAX3") == "SIM_GZ_EC_MAX#"
    assert px4.range_key("MPC_THR_HOVER") == "MPC_THR_HOVER"


# --------------------------------------------------------------- PX4 good pair

@pytest.mark.parametrize("name", ["x500_airframe", "x500_qgc.params"])
def test_x500_pair_is_information_only(name):
    findings = run_checks(load_robot(X500), flight_params=[px4.load_px4_params(FIX / name)])
    assert not_info(findings) == []
    assert sorted(f.code for f in findings) == ["C417"] * 4 + ["C421"] + ["C423"] * 4
    hover = next(f for f in findings if f.code == "C421")
    assert f"{x500_hover_setpoint():.3f}" in hover.message      # 0.729 by hand
    assert "MPC_THR_HOVER 0.60" in hover.message


def test_x500_position_offset_numbers():
    findings = run_checks(load_robot(X500), Selection(select=("C423",)),
                          flight_params=[px4.load_px4_params(FIX / "x500_airframe")])
    first = next(f for f in findings if "CA_ROTOR0_PX" in f.message)
    # CA (0.13, 0.22) FRD vs model (0.174, 0.174): 59.42° vs 45°, 64 mm apart.
    gap = math.degrees(math.atan2(0.22, 0.13)) - 45.0
    assert f"{gap:.1f}°" in first.message
    assert f"{1000 * math.hypot(0.174 - 0.13, 0.22 - 0.174):.0f} mm" in first.message


# --------------------------------------------------------------- PX4 defects

def _swap_rotor_lines(text: str, a: int, b: int) -> str:
    for suffix in ("PX", "PY", "KM"):
        name_a, name_b = f"CA_ROTOR{a}_{suffix}", f"CA_ROTOR{b}_{suffix}"
        text = text.replace(name_a, "@@").replace(name_b, name_a).replace("@@", name_b)
    return text


def test_swapped_ca_rotors(tmp_path):
    text = _swap_rotor_lines(AIRFRAME, 0, 1)
    findings = px4_findings(tmp_path, text)
    assert not_info(findings) == ["C415", "C415"]
    first = next(f for f in findings if f.code == "C415" and "CA_ROTOR0_PX" in f.message)
    assert first.line == line_of(text, "CA_ROTOR0_PX")
    assert f"airframe:{line_of(text, 'CA_ROTOR0_PY')}" in first.message
    assert "x500_flat.sdf:" in first.message               # the model's place too
    assert "describes the model's motor 1" in first.hint


def test_flipped_km_sign(tmp_path):
    text = AIRFRAME.replace("CA_ROTOR2_KM -0.05", "CA_ROTOR2_KM 0.05")
    findings = px4_findings(tmp_path, text)
    assert not_info(findings) == ["C416"]
    spin = next(f for f in findings if f.code == "C416")
    assert spin.line == line_of(text, "CA_ROTOR2_KM")
    sdf = X500.read_text()
    turning = [m.start() for m in re.finditer("<turningDirection>", sdf)][2]
    assert f"x500_flat.sdf:{sdf[:turning].count(chr(10)) + 1}" in spin.message


def test_command_max_above_rotor_limit(tmp_path):
    text = AIRFRAME.replace("SIM_GZ_EC_MAX1 1000", "SIM_GZ_EC_MAX1 1100")
    findings = px4_findings(tmp_path, text)
    assert not_info(findings) == ["C419"]
    above = next(f for f in findings if f.code == "C419")
    assert above.line == line_of(text, "SIM_GZ_EC_MAX1")
    assert f"{100 * (1100 - 1000) / (1100 - 150):.0f} %" in above.message   # 11 %


def test_command_max_below_rotor_limit(tmp_path):
    text = AIRFRAME.replace("SIM_GZ_EC_MAX4 1000", "SIM_GZ_EC_MAX4 800")
    findings = px4_findings(tmp_path, text)
    assert "C424" in not_info(findings)
    below = next(f for f in findings if f.code == "C424")
    assert "64 %" in below.message                                 # (800/1000)²


def test_idle_above_hover_speed(tmp_path):
    text = AIRFRAME.replace("SIM_GZ_EC_MIN3 150", "SIM_GZ_EC_MIN3 800")   # hover ~770
    assert "C420" in not_info(px4_findings(tmp_path, text))


def test_hover_throttle_far_off(tmp_path):
    text = AIRFRAME.replace("MPC_THR_HOVER 0.60", "MPC_THR_HOVER 0.30")
    findings = px4_findings(tmp_path, text)
    assert not_info(findings) == ["C422"]
    assert "C421" not in [f.code for f in findings]


def test_rotor_count_and_unmapped_motor(tmp_path):
    text = AIRFRAME.replace("CA_ROTOR_COUNT 4", "CA_ROTOR_COUNT 3")
    codes = not_info(px4_findings(tmp_path, text))
    assert "C413" in codes and "C414" in codes


def test_swapped_gz_outputs(tmp_path):
    text = AIRFRAME.replace("SIM_GZ_EC_FUNC1 101", "SIM_GZ_EC_FUNC1 102") \
                   .replace("SIM_GZ_EC_FUNC2 102", "SIM_GZ_EC_FUNC2 101")
    assert not_info(px4_findings(tmp_path, text)) == ["C415", "C415"]


def test_out_of_range_value(tmp_path):
    text = AIRFRAME.replace("CA_ROTOR0_KM  0.05", "CA_ROTOR0_KM  1.5")
    assert not_info(px4_findings(tmp_path, text)) == ["C425"]


def test_tilted_thrust_axis(tmp_path):
    # 45° off the x500's upright rotor: most thrust still goes up, PX4 allocates a wrong
    # side force (C426, warning); at 73° (AX 1, AZ -0.3: acos(0.3/1.044)) less than half does
    # (C418, error).
    text = AIRFRAME + "param set-default CA_ROTOR0_AX 0.5\nparam set-default CA_ROTOR0_AZ -0.5\n"
    (finding,) = [f for f in px4_findings(tmp_path, text) if f.severity != "info"]
    assert (finding.code, finding.severity) == ("C426", "warning")
    assert "45.0°" in finding.message
    text = AIRFRAME + "param set-default CA_ROTOR0_AX 1\nparam set-default CA_ROTOR0_AZ -0.3\n"
    (finding,) = [f for f in px4_findings(tmp_path, text) if f.severity != "info"]
    assert (finding.code, finding.severity) == ("C418", "error")
    assert f"{math.degrees(math.acos(0.3 / math.hypot(1, 0.3))):.1f}°" in finding.message


# --------------------------------------------------------------- ArduPilot tables

def test_motor_tables_match_hand_facts():
    quad_x = ardupilot.motor_table(1, 1)
    # ArduCopter quad X: motor 1 front-right CCW, 2 back-left CCW, 3 front-left CW, 4 back-right CW.
    assert [(m.bearing_deg, m.spin) for m in quad_x] == [(45, 1), (-135, 1), (-45, -1), (135, -1)]
    for (frame_class, frame_type), motors in ardupilot.MOTOR_TABLES.items():
        assert sorted(m.test_order for m in motors) == list(range(1, len(motors) + 1))
        assert [m.number for m in motors] == list(range(1, len(motors) + 1))
        spins = [m.spin for m in motors]
        if 0 not in spins:                                   # yaw balanced
            assert sum(spins) == 0, (frame_class, frame_type)
    # Y6B: raw factors (-1, 0.5) -> bearing atan2(1, 0.5) = 63.4°, coaxial pairs share it.
    y6b = ardupilot.motor_table(5, 10)
    assert y6b[0].bearing_deg == y6b[1].bearing_deg == round(math.degrees(math.atan2(1, 0.5)), 1)
    assert ardupilot.motor_table(5, 1) == ardupilot.MOTOR_TABLES[(5, None)]   # Y6 default
    assert ardupilot.motor_table(7, 1) is None


def test_servo_functions():
    params = ardupilot.parse_parm("SERVO1_FUNCTION 34\nSERVO2_FUNCTION 33\n", "p")
    assert params.output_of_motor(1)[0] == 2
    assert params.output_of_motor(2)[0] == 1
    assert params.output_of_motor(3) == (3, None)
    assert ardupilot.motor_function(9) == 82


# --------------------------------------------------------------- ArduPilot against a model

def test_quad_x_parm_on_x500_is_clean(tmp_path):
    assert ap_findings(tmp_path, PARM) == []


def test_plus_frame_type_on_x_model(tmp_path):
    text = PARM.replace("FRAME_TYPE 1", "FRAME_TYPE 0")
    findings = ap_findings(tmp_path, text)
    assert not_info(findings) == ["C432"] * 4
    assert all(f"vehicle.parm:{line_of(text, 'FRAME_TYPE')}" in f.message for f in findings)
    assert {f.line for f in findings} == {line_of(text, "FRAME_TYPE")}
    assert all("x500_flat.sdf:" in f.message for f in findings)


def test_swapped_servo_channels(tmp_path):
    text = PARM.replace("SERVO1_FUNCTION 33", "SERVO1_FUNCTION 34") \
               .replace("SERVO2_FUNCTION 34", "SERVO2_FUNCTION 33")
    findings = ap_findings(tmp_path, text)
    assert not_info(findings) == ["C432", "C432"]
    assert sorted(f.line for f in findings) == [line_of(text, "SERVO1_FUNCTION"),
                                                line_of(text, "SERVO2_FUNCTION")]


def test_h_frame_on_x_model_reverses_every_spin(tmp_path):
    assert not_info(ap_findings(tmp_path, PARM.replace("FRAME_TYPE 1", "FRAME_TYPE 3"))) \
        == ["C433"] * 4


def test_wrong_class_and_missing_class(tmp_path):
    assert not_info(ap_findings(tmp_path, PARM.replace("FRAME_CLASS 1", "FRAME_CLASS 2"))) \
        == ["C431"]
    # Without FRAME_CLASS the file may be one of several SITL loads: information only.
    missing = ap_findings(tmp_path, PARM.replace("FRAME_CLASS 1\n", ""))
    assert [(f.code, f.severity) for f in missing] == [("C430", "info")]


def _iris_has_channels() -> bool:
    from reedtool.physics.rotors import discover_rotors

    rotors = discover_rotors(load_robot(FIX / "iris_ardupilot.sdf"))
    return len(rotors) == 4 and all(getattr(r, "channel", None) is not None for r in rotors)


@pytest.mark.skipif(not _iris_has_channels(), reason="ArduPilotPlugin rotors not read yet")
def test_iris_with_plugin(tmp_path):
    iris = FIX / "iris_ardupilot.sdf"
    assert not_info(ap_findings(tmp_path, PARM, iris)) == []
    assert not_info(ap_findings(tmp_path, PARM.replace("FRAME_TYPE 1", "FRAME_TYPE 0"), iris)) \
        == ["C432"] * 4
    sdf = iris.read_text().replace('channel="0"', 'channel="@"') \
        .replace('channel="1"', 'channel="0"').replace('channel="@"', 'channel="1"')
    swapped = tmp_path / "iris_swapped.sdf"
    swapped.write_text(sdf)
    assert not_info(ap_findings(tmp_path, PARM, swapped)) == ["C432", "C432"]


def test_match_frame_finds_quad_x_numbers():
    found = ardupilot.match_frame([45, -135, -45, 135], [1, 1, -1, -1])
    assert found == (1, 1, [1, 2, 3, 4])
    assert ardupilot.match_frame([45, -135, -45, 135], [1, 1, 1, -1]) is None
    # Whole-degree differences: exact in binary; isclose's default is a ceiling.
    assert np.isclose(ardupilot.angle_gap_deg(170, -170), 20)


def test_docs_motor_tables_are_the_data():
    doc = (Path(__file__).parents[1] / "docs" / "validate.md").read_text()
    spin = {1: "CCW", -1: "CW", 0: "-"}
    for (frame_class, frame_type), motors in ardupilot.MOTOR_TABLES.items():
        cell = "; ".join(f"{m.number} {m.bearing_deg:g} {spin[m.spin]} ({m.test_order})"
                         for m in motors)
        assert f"| {frame_class} / {frame_type if frame_type is not None else 'other'} |" in doc
        assert cell in doc, (frame_class, frame_type)


def test_parm_formats():
    # .parm (space), Mission Planner (comma) and QGC (tab) lines read the same.
    text = "FRAME_CLASS 1\nFRAME_TYPE,1\n1\t1\tSERVO1_FUNCTION\t33\t2\n"
    params = ardupilot.parse_parm(text, "p")
    assert [params.get(n).value for n in ("FRAME_CLASS", "FRAME_TYPE", "SERVO1_FUNCTION")] \
        == [1, 1, 33]
    assert params.get("SERVO1_FUNCTION").loc.line == 3


def test_cli_missing_airframe_is_one_line(tmp_path):
    from cli_helpers import run_cli

    code, output = run_cli("validate", X500, "--airframe", tmp_path / "nope")
    assert code == 2 and "nope" in output and "file not found" in output
    code, output = run_cli("validate", X500, "--airframe", FIX / "x500_airframe")
    assert code == 0 and "C421" in output


def test_vtol_pusher_is_a_ca_rotor_but_not_in_the_hover(tmp_path):
    vtol = Path(__file__).parent / "fixtures" / "vtol" / "vtol_pusher.sdf"
    text = (FIX / "vtol_pusher_airframe").read_text()
    findings = px4_findings(tmp_path, text, vtol)
    assert not_info(findings) == []                     # 5 CA rotors = 4 lift + the pusher
    assert "C421" in [f.code for f in findings]
    # CA_AIRFRAME 2 drops the propeller torque of rotors that are not upward
    # (enablePropellerTorqueNonUpwards(false)): the pusher's KM sign is not used.
    flipped = text.replace("CA_ROTOR4_KM 0.05", "CA_ROTOR4_KM -0.05")
    assert not_info(px4_findings(tmp_path, flipped, vtol)) == []
    # ... but a lift rotor's is.
    flipped = text.replace("CA_ROTOR0_KM 0.05", "CA_ROTOR0_KM -0.05")
    assert not_info(px4_findings(tmp_path, flipped, vtol)) == ["C416"]
    level = text.replace("CA_ROTOR4_AX 1", "CA_ROTOR4_AX 0").replace("CA_ROTOR4_AZ 0",
                                                                       "CA_ROTOR4_AZ -1")
    assert not_info(px4_findings(tmp_path, level, vtol)) == ["C418"]
    # CA_AIRFRAME 1 (fixed-wing) fixes every rotor forward whatever AX/AY/AZ say: the
    # four lift rotors are 90° off, and the finding points at CA_AIRFRAME.
    fixed_wing = text.replace("set-default CA_AIRFRAME 2", "set-default CA_AIRFRAME 1")
    findings = [f for f in px4_findings(tmp_path, fixed_wing, vtol) if f.severity == "error"]
    assert [f.code for f in findings] == ["C418"] * 4
    assert {f.line for f in findings} == {line_of(fixed_wing, "set-default CA_AIRFRAME 1")}


def test_unset_ardupilot_parameter_points_at_the_file_without_a_line(tmp_path):
    """FRAME_CLASS missing: the finding names the file, not a line 1 that says nothing."""
    (finding,) = ap_findings(tmp_path, PARM.replace("FRAME_CLASS 1\n", ""))
    assert finding.code == "C430" and finding.line is None
    assert finding.file.endswith(".parm")
