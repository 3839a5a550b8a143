"""Plausibility rules (R340-R342, I220): a good and a bad model per rule, numbers by hand."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from reedtool.checks.runner import Selection, run_checks
from reedtool.io.loader import load_robot

X500 = Path(__file__).parent / "fixtures" / "flightstack" / "x500_flat.sdf"
SDF = X500.read_text()
G = 9.80665
RULES = ("R340", "R341", "R342", "I220")


def findings_of(tmp_path, text: str):
    path = tmp_path / "model.sdf"
    path.write_text(text)
    return run_checks(load_robot(path), Selection(select=RULES))


def codes(findings) -> list[str]:
    return sorted(f.code for f in findings)


def test_x500_is_plausible(tmp_path):
    assert codes(findings_of(tmp_path, SDF)) == []


def test_thrust_to_weight_of_a_copied_speed(tmp_path):
    findings = findings_of(tmp_path, SDF.replace("<maxRotVelocity>1000.0", "<maxRotVelocity>8000"))
    assert codes(findings) == ["R340"]
    mass = 2.0 + 4 * 0.0160769
    ratio = 4 * 8.54858e-06 * 8000 ** 2 / (mass * G)              # 108
    assert f"thrust-to-weight {ratio:.3g}" in findings[0].message


def test_big_vehicle_mass_on_a_65_mm_frame(tmp_path):
    # Rotors at +-0.023 m: 65 mm apart across the diagonal; the 2 kg body and its inertia stay.
    text = SDF.replace("0.174 -0.174 0.06", "0.023 -0.023 0.06") \
              .replace("-0.174 0.174 0.06", "-0.023 0.023 0.06") \
              .replace("0.174 0.174 0.06", "0.023 0.023 0.06") \
              .replace("-0.174 -0.174 0.06", "-0.023 -0.023 0.06")
    findings = findings_of(tmp_path, text)
    assert codes(findings) == ["I220", "I220"]
    span = 2 * math.hypot(0.023, 0.023)
    density = (2.0 + 4 * 0.0160769) / span ** 3
    assert any(f"{density:.0f} kg/m³" in f.message for f in findings)


def test_rotor_joint_axis_off_the_thrust_axis(tmp_path):
    at = SDF.index("<xyz>0 0 1</xyz>")
    text = SDF[:at] + "<xyz>1 0 0</xyz>" + SDF[at + len("<xyz>0 0 1</xyz>"):]
    findings = findings_of(tmp_path, text)
    assert codes(findings) == ["R341"]
    assert findings[0].line == SDF[:at].count("\n") + 1
    assert "90.0°" in findings[0].message


@pytest.mark.parametrize("extra_m, fires", [(0.15, True), (0.0, False)])
def test_uneven_trim_with_one_long_arm(tmp_path, extra_m, fires):
    # Rotor 0's arm (bearing -45°, 0.246 m) made `extra_m` longer.
    arm = math.hypot(0.174, 0.174) + extra_m
    x = y = arm / math.sqrt(2)
    text = SDF.replace("<pose>0.174 -0.174 0.06", f"<pose>{x:.6f} {-y:.6f} 0.06")
    findings = findings_of(tmp_path, text)
    assert codes(findings) == (["R342"] if fires else [])
    if fires:
        assert "rotor_" in findings[0].message and "COM" in findings[0].message
        # Equal thrusts need the COM over the rotor centroid: shift = centroid - COM, with
        # the COM moved by the rotor's own mass (base link COM at the origin).
        rotor_kg, total_kg = 0.0160769, 2.0 + 4 * 0.0160769
        sum_x, sum_y = x - 0.174, 0.174 - y
        shift = [s * (1 / 4 - rotor_kg / total_kg) for s in (sum_x, sum_y)]
        assert f"({shift[0]:+.4g}, {shift[1]:+.4g})" in findings[0].hint


@pytest.mark.parametrize("ratio", [9.1, 15.0, 24.0])
def test_racing_thrust_to_weight_is_not_suspicious(tmp_path, ratio):
    """R340 good: thrust-to-weight 9.1 (PX4's omnicopter), 15 (a racing quad), 24. The
    ratio grows with speed squared, so the x500's speed times sqrt(ratio / its ratio)."""
    mass = 2.0 + 4 * 0.0160769
    base = 4 * 8.54858e-06 * 1000.0 ** 2 / (mass * G)          # 1.69 at 1000 rad/s
    omega_rad_s = 1000.0 * math.sqrt(ratio / base)
    text = SDF.replace("<maxRotVelocity>1000.0", f"<maxRotVelocity>{omega_rad_s:.3f}")
    assert codes(findings_of(tmp_path, text)) == []
    # ... and just above the bound it warns (the same model, ratio 26).
    text = SDF.replace("<maxRotVelocity>1000.0",
                       f"<maxRotVelocity>{1000.0 * math.sqrt(26.0 / base):.3f}")
    assert codes(findings_of(tmp_path, text)) == ["R340"]


def test_coaxial_rotors_have_no_span_to_judge(tmp_path):
    """Every rotor within 5 mm of the body's vertical (a coaxial helicopter, the Sikorsky
    X2's shape): 2.06 kg over a 10 mm span cube would be 2e6 kg/m³; I220 stays quiet."""
    text = SDF
    for x, y in (("0.174", "-0.174"), ("-0.174", "0.174"), ("0.174", "0.174"),
                 ("-0.174", "-0.174")):
        sx, sy = ("" if x[0] != "-" else "-"), ("" if y[0] != "-" else "-")
        text = text.replace(f"{x} {y} 0.06", f"{sx}0.0035 {sy}0.0035 0.06")
    assert text.count("0.0035") == 8
    assert "I220" not in codes(findings_of(tmp_path, text))
