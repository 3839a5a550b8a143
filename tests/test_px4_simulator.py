"""validate --airframe knows which Gazebo a model is for (C435-C438).

PX4 commands a Gazebo Classic model through simulator_mavlink and the model's
gazebo_mavlink_interface: speed = (u + input_offset) * input_scaling + zero_position_armed
(PX4-SITL_gazebo-classic gazebo_mavlink_interface.cpp), u in 0..1; SIM_GZ_EC_* is never
read. A Gazebo Sim model through the gz bridge and SIM_GZ_EC_MIN/MAX. The fixtures:
tests/fixtures/px4_classic_jinja (a Classic model as a PX4 template, its Classic airframe
and a gz one with the same rotor table) and tests/fixtures/px4_x500_ref (a gz model).
Expected numbers are derived by hand below.
"""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from reedtool.checks.runner import run_checks
from reedtool.flightstack.px4 import load_px4_params
from reedtool.io.loader import load_robot

FIXTURES = Path(__file__).parent / "fixtures"
CLASSIC = FIXTURES / "px4_classic_jinja"
TEMPLATE = CLASSIC / "models" / "quad_jinja" / "quad_jinja.sdf.jinja"
CLASSIC_AIRFRAME = CLASSIC / "airframes" / "10100_gazebo-classic_quad_jinja"
GZ_AIRFRAME = CLASSIC / "airframes" / "4100_gz_quad_jinja"
X500 = FIXTURES / "px4_x500_ref" / "models" / "x500" / "model.sdf"
G = 9.80665


def findings(model: Path, airframe: Path, package_paths=()):
    robot = load_robot(model, {}, list(package_paths))
    return [f for f in run_checks(robot, flight_params=[load_px4_params(airframe)])
            if f.code.startswith("C")]


def not_info(found) -> list[str]:
    return sorted(f.code for f in found if f.severity != "info")


def hover_u() -> float:
    """quad_jinja hovers on four equal thrusts (its layout balances pitch, roll and yaw
    only with T0 = T1 = T2 = T3): W = (1.5 + 4 x 0.005) kg g, ω = sqrt(W / (4 k)), k =
    5.84e-06, and the channel maps u to 100 + 1000 u."""
    omega = math.sqrt(1.52 * G / (4 * 5.84e-06))
    return (omega - 100) / 1000


def test_classic_model_with_its_classic_airframe():
    found = findings(TEMPLATE, CLASSIC_AIRFRAME)
    assert not_info(found) == []
    assert not any("SIM_GZ" in f.message or "SIM_GZ" in (f.hint or "") for f in found)
    hover = next(f for f in found if f.code == "C421")
    needed = float(hover.message.split("thrust setpoint of ")[1].split(" ")[0])
    # g between 9.80 and 9.81 moves u by omega * 0.0005 / 1000 < 0.0005; printed to 3 places.
    assert needed == pytest.approx(hover_u(), abs=1.5e-3)


def test_classic_model_with_a_gz_airframe_is_one_mismatch():
    found = findings(TEMPLATE, GZ_AIRFRAME)
    assert not_info(found) == ["C435"]
    mismatch = next(f for f in found if f.code == "C435")
    assert "Gazebo Sim" in mismatch.message and "Gazebo Classic" in mismatch.message
    assert mismatch.line == 13              # SIM_GZ_EN 1, the line that says gz
    others = [f for f in found if f.code != "C435"]
    assert not any("SIM_GZ" in (f.hint or "") for f in others)


def test_gz_model_with_a_classic_airframe_is_one_mismatch(tmp_path):
    airframe = tmp_path / "10015_gazebo-classic_x500"
    # The x500 rotor table (FRD), PWM_MAIN outputs as PX4's Classic airframes set them.
    rows = [(0.174, 0.174, 0.016), (-0.174, -0.174, 0.016), (0.174, -0.174, -0.016),
            (-0.174, 0.174, -0.016)]
    lines = ["param set-default CA_ROTOR_COUNT 4"]
    for i, (x, y, km) in enumerate(rows):
        lines += [f"param set-default CA_ROTOR{i}_PX {x}", f"param set-default CA_ROTOR{i}_PY {y}",
                  f"param set-default CA_ROTOR{i}_KM {km}", f"param set-default PWM_MAIN_FUNC{i + 1} {101 + i}"]
    airframe.write_text("\n".join(lines) + "\n")
    found = findings(X500, airframe, [X500.parent.parent])
    assert not_info(found) == ["C435"]


@pytest.mark.parametrize("edits, expected, number", [
    # input_scaling 1500: up to 100 + 1500 = 1600 rad/s, the top (1600 - 1100) / 1500 = 33 %;
    # the hover command (799 - 100) / 1500 = 0.47 is then 0.23 from MPC_THR_HOVER 0.70.
    ({"<input_scaling>1000<": "<input_scaling>1500<"}, ["C422"] + ["C436"] * 4, "33 %"),
    # input_scaling 800: at most 900 rad/s, (900 / 1100)² = 67 % of the thrust; hover
    # command (799 - 100) / 800 = 0.87.
    ({"<input_scaling>1000<": "<input_scaling>800<"}, ["C422"] + ["C437"] * 4, "67 %"),
    # armed idle 850 rad/s (top 850 + 250 = 1100, the motor's limit), above the ~799 rad/s
    # hover speed; the hover command is below zero.
    ({"<zero_position_armed>100<": "<zero_position_armed>850<",
      "<input_scaling>1000<": "<input_scaling>250<"}, ["C422"] + ["C438"] * 4, "850 rad/s"),
])
def test_classic_command_range_against_the_motor(tmp_path, edits, expected, number):
    text = TEMPLATE.read_text()
    for old, new in edits.items():
        assert old in text
        text = text.replace(old, new)
    model = tmp_path / "quad_jinja.sdf.jinja"
    model.write_text(text)
    found = findings(model, CLASSIC_AIRFRAME)
    assert not_info(found) == expected
    assert number in next(f for f in found if f.code == expected[-1]).message
    assert not any("SIM_GZ" in (f.hint or "") + f.message for f in found)
