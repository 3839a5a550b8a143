"""Rotor rules (R3xx): codes per fixture; clean quad-X, hex and octo are quiet.

The rotor layouts, masses and inertias of the fixtures are computed by
tests/fixtures/validate/generate.py from textbook formulas, not by reedtool.
"""

from __future__ import annotations

import math
from pathlib import Path

import pytest
from rule_helpers import FIXTURES, codes

from reedtool.checks.registry import all_rules
from reedtool.checks.runner import run_checks
from reedtool.io.loader import load_robot

CASES = [
    ("R301_bad_duplicate_number.urdf", ["R301"]),
    ("R302_bad_gap.urdf", ["R302"]),
    ("R302_bad_missing.urdf", ["R302"]),
    ("R303_bad_direction.urdf", ["R303"]),
    ("R304_bad_three_ccw.urdf", ["R304"]),
    ("R305_bad_same_side.urdf", ["R305"]),
    # Nearly coupled yaw and roll also needs one rotor near full speed to hover.
    ("R306_bad_nearly_coupled.urdf", ["R306", "R310"]),
    ("R307_bad_com_offset.urdf", ["R307"]),
    ("R308_bad_heavy.urdf", ["R308"]),
    # T/W 1.35 on a symmetric quad means sqrt(1/1.35) = 86 % hover throttle as well.
    ("R309_bad_low_margin.urdf", ["R309", "R310"]),
    # Front-heavy: the rear rotors hover harder than the front ones (R342 names the shift).
    ("R310_bad_front_heavy.urdf", ["R310", "R342"]),
    ("R311_bad_tilted.urdf", ["R311"]),
    ("R312_bad_rotor_count.urdf", ["R312"]),
    ("R313_bad_revolute.urdf", ["R313"]),
    ("R314_bad_joint_name.urdf", ["R314"]),
    ("R314_bad_link_name.urdf", ["R314"]),
    ("R315_bad_link_mismatch.urdf", ["R315"]),
    ("R316_bad_motor_constant.urdf", ["R316"]),
    ("R316_bad_missing_max_speed.urdf", ["R316"]),
    # Plausibility (checks/plausibility_rules.py): clean_quad_x with one edit each.
    ("R340_bad_copied_speed.urdf", ["R340"]),
    ("R341_bad_joint_axis.urdf", ["R341"]),
    ("R342_bad_long_arm.urdf", ["R342"]),
    ("I220_bad_tiny_frame.urdf", ["I220", "I220"]),
    # R350 (info): the alternating hexacopter loses full control with any rotor; the
    # paper's PPNNPN order of the same rotors keeps it after four failures.
    ("R350_bad_alternating_hex.urdf", ["R350"]),
    ("R350_good_ppnnpn_hex.urdf", []),
    ("clean_quad_x.urdf", []),
    ("clean_hex.urdf", ["R350"]),
    ("clean_octo.urdf", []),
]


@pytest.mark.parametrize("name,expected", CASES, ids=[c[0] for c in CASES])
def test_rotor_rule_codes(name, expected):
    assert codes(name) == expected


def test_no_rotor_rules_without_rotors():
    findings = run_checks(load_robot(FIXTURES / "clean_car.urdf"))
    assert not [f for f in findings if f.code.startswith("R")]


def test_thrust_to_weight_figures_match_hand_calculation():
    (finding,) = run_checks(load_robot(FIXTURES / "R308_bad_heavy.urdf"))
    # 4 rotors * 8.54858e-06 * 838^2 against (3.0 + 4 * 0.005) kg * g.
    thrust_N = 4 * 8.54858e-06 * 838 ** 2
    weight_N = 3.02 * 9.80665
    assert f"thrust-to-weight {thrust_N / weight_N:.3g}" in finding.message
    # maxRotVelocity for T/W 1.5: 838 * sqrt(1.5 / (T/W)).
    assert f"{838 * math.sqrt(1.5 * weight_N / thrust_N):.0f} rad/s" in finding.hint


def test_rotors_without_thrust_get_no_infinite_speed_hint(tmp_path):
    """k·ω_max² with maxRotVelocity 1e-300 underflows to 0 N: thrust-to-weight is 0 and no
    speed scales it up, so the hint names the constants instead of 'inf rad/s'."""
    text = (FIXTURES / "R308_bad_heavy.urdf").read_text()
    assert text.count("<maxRotVelocity>838</maxRotVelocity>") == 4
    model = tmp_path / "no_thrust.urdf"
    model.write_text(text.replace("<maxRotVelocity>838</maxRotVelocity>",
                                  "<maxRotVelocity>1e-300</maxRotVelocity>"))
    (finding,) = run_checks(load_robot(model))
    assert finding.code == "R308" and "thrust-to-weight 0 <" in finding.message
    assert "inf" not in finding.hint and "motorConstant" in finding.hint


def test_yaw_imbalance_names_the_rotor_to_flip():
    (finding,) = run_checks(load_robot(FIXTURES / "R304_bad_three_ccw.urdf"))
    assert finding.subject == "rotor_2"
    assert "(3 ccw, 1 cw" in finding.message


def _all_tables():
    import importlib.util

    tables = []
    for module in ("test_rules_structure", "test_rules_inertia", "test_rotor_families"):
        spec = importlib.util.spec_from_file_location(f"_{module}",
                                                      Path(__file__).parent / f"{module}.py")
        mod = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(mod)
        tables += mod.CASES
    return tables + CASES


def test_every_sir_rule_has_a_bad_and_a_good_fixture():
    tables = _all_tables()
    bad = {Path(name).name.split("_")[0] for name, expected in tables if expected}
    for rule in all_rules():
        if rule.code[0] not in "SIR":
            continue  # other families keep their fixtures with their own tests
        if rule.check.__module__ == "reedtool.checks.argument_rules":
            continue  # need xacro arguments: good/bad fixtures in test_launch.py (S140_*)
        if rule.run_level:
            continue  # judged over a whole run (S143): cases in test_ci_features.py
        if rule.code == "S150":
            continue  # needs a package search path: good/bad cases in test_packages.py
        if rule.code in ("I221", "R343"):
            continue  # exporters' packages with meshes: good/bad in test_plausibility_physical.py
        assert rule.code in bad, f"{rule.code} has no bad fixture"
        # The bad fixture named after the rule reports that rule.
        own = [expected for name, expected in tables if Path(name).name.startswith(rule.code + "_bad")]
        assert own and all(rule.code in e for e in own), rule.code
    assert any(not expected for _name, expected in tables)  # good fixtures exist


@pytest.mark.parametrize("lower, upper, fires", [
    ("-1e-16", "1e+16", False),    # mini_talon_vtail's typo: open on the side it turns
    ("-1e+16", "1e-16", True),     # open only the other way: it stops at once
    ("-1", "1", True),             # a limited revolute joint
    ("-1e+12", "1e+12", False),    # SwiftGust's Sikorsky X2 blades: never reached
])
def test_revolute_rotor_joint_open_in_its_direction(tmp_path, lower, upper, fires):
    """x500's rotor 0 turns ccw: the motor model drives its joint at +omega, so only the
    upper limit matters."""
    x500 = Path(__file__).parent / "fixtures" / "flightstack" / "x500_flat.sdf"
    text = x500.read_text()
    at = text.index('<joint name="rotor_0_joint"')
    old = "<limit><lower>-1e+16</lower><upper>1e+16</upper></limit>"
    at = text.index(old, at)
    text = text[:at] + f"<limit><lower>{lower}</lower><upper>{upper}</upper></limit>" + \
        text[at + len(old):]
    path = tmp_path / "x500.sdf"
    path.write_text(text)
    found = [f.subject for f in run_checks(load_robot(path)) if f.code == "R313"]
    assert found == (["rotor_0_joint"] if fires else [])
