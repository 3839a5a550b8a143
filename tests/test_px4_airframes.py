"""PX4 as PX4 reads it: each gz airframe's CA_AIRFRAME picks how the rotor table is read.

The airframes are our own files with the parameters of PX4's gz airframes
(tests/fixtures/px4_airframes, generate.py); each is paired with reedtool's fixture in the
shape of the model PX4 flies it with. Acceptance of issue 18: no flight-stack error on any
pair, and PX4's two real command-range defects (px4vision 1100 above 1000 rad/s,
quadtailsitter 1500 above 1200 rad/s) still reported.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from reedtool.checks.runner import Selection, run_checks
from reedtool.flightstack.px4 import (
    AIRFRAMES,
    is_upward,
    load_px4_params,
    rotor_axis,
    tilted_axis,
)
from reedtool.io.loader import load_robot

FIX = Path(__file__).parent / "fixtures"
AIRFRAME_DIR = FIX / "px4_airframes"

PAIRS = {
    "4003_fixed_wing": FIX / "upstream_shapes" / "fixed_wing_puller" / "model.sdf",
    "4004_standard_vtol": FIX / "vtol" / "vtol_pusher.sdf",
    "4006_px4vision": FIX / "upstream_shapes" / "px4vision_quad" / "model.sdf",
    "4018_quadtailsitter": FIX / "upstream_shapes" / "quad_tailsitter" / "model.sdf",
    "4020_tiltrotor": FIX / "upstream_shapes" / "tiltrotor" / "model.sdf",
    "8011_omnicopter": AIRFRAME_DIR / "omnicopter.sdf",
}


def findings(airframe: str, text: str | None = None, tmp_path: Path | None = None):
    path = AIRFRAME_DIR / airframe
    if text is not None:
        path = tmp_path / airframe
        path.write_text(text)
    return run_checks(load_robot(PAIRS[airframe]), Selection(select=("C",)),
                      flight_params=[load_px4_params(path)])


@pytest.mark.parametrize("airframe", sorted(PAIRS))
def test_px4_pairs_have_no_flight_stack_error(airframe):
    assert [(f.code, f.message) for f in findings(airframe) if f.severity == "error"] == []


@pytest.mark.parametrize("airframe, above, limit", [
    ("4006_px4vision", 1100, 1000), ("4018_quadtailsitter", 1500, 1200)])
def test_px4_command_range_defects_still_reported(airframe, above, limit):
    range_findings = [f for f in findings(airframe) if f.code == "C419"]
    assert len(range_findings) == 4 and {f.severity for f in range_findings} == {"warning"}
    lost = 100 * (above - limit) / (above - (150 if "px4vision" in airframe else 10))
    for f in range_findings:
        assert f"{above} rad/s" in f.message and f"maxRotVelocity {limit}" in f.message
        assert f"top {lost:.0f} %" in f.message


def test_fixed_wing_axis_is_fixed_forward_and_km_unused(tmp_path):
    """4003 sets no CA_ROTOR0_AX/AY/AZ (default: up) and no KM (default 0.05, ccw) for a cw
    puller; CA_AIRFRAME 1 fixes the axis forward and disables propeller torque."""
    assert [f.code for f in findings("4003_fixed_wing") if f.code in ("C416", "C418")] == []
    # Read as a multirotor (CA_AIRFRAME 0) the same table is wrong twice over.
    text = (AIRFRAME_DIR / "4003_fixed_wing").read_text().replace(
        "CA_AIRFRAME 1", "CA_AIRFRAME 0")
    errors = sorted(f.code for f in findings("4003_fixed_wing", text, tmp_path)
                    if f.severity == "error")
    assert errors == ["C416", "C418"]


def test_unset_parameter_names_its_default_and_the_file_without_line(tmp_path):
    text = (AIRFRAME_DIR / "4003_fixed_wing").read_text().replace(
        "CA_AIRFRAME 1", "CA_AIRFRAME 0")
    (spin,) = [f for f in findings("4003_fixed_wing", text, tmp_path) if f.code == "C416"]
    assert "CA_ROTOR0_KM not set: PX4's default 0.05" in spin.message
    assert spin.line is None and spin.file.endswith("4003_fixed_wing")


def test_standard_vtol_pusher_position_and_spin_are_not_compared():
    """4004's pusher: CA_ROTOR4_PX 0.2 (ahead of the COM) for a pusher behind it, KM unset
    (ccw) for whatever the model spins. Thrust along x makes x-position torque-free
    (p x x̂ = (0, pz, -py)) and CA_AIRFRAME 2 drops non-upward rotors' KM."""
    codes = [f.code for f in findings("4004_standard_vtol") if f.subject == "CA_ROTOR4"]
    assert "C415" not in codes and "C416" not in codes


def test_quadtailsitter_balanced_tilt_is_information():
    """PX4's quadtailsitter tilts its rotors 0.17 rad in roll and pitch (R320 balanced);
    PX4 allocates them upward: acos(cos 0.17 · cos 0.17) = 13.7° apart, as information."""
    axis = [f for f in findings("4018_quadtailsitter") if f.code in ("C418", "C426", "C427")]
    assert [f.code for f in axis] == ["C427"] * 4
    expected = math.degrees(math.acos(math.cos(0.17) * math.cos(0.17)))
    assert all(f"{expected:.1f}°" in f.message for f in axis)


def test_px4vision_flipped_km_is_still_an_error(tmp_path):
    text = (AIRFRAME_DIR / "4006_px4vision").read_text().replace(
        "CA_ROTOR2_KM -0.05", "CA_ROTOR2_KM 0.05")
    assert [f.code for f in findings("4006_px4vision", text, tmp_path)
            if f.severity == "error"] == ["C416"]


def test_tiltrotor_axis_follows_its_tilt_servo(tmp_path):
    """4020 tilts rotors 0 and 2 from 0° (hover) to 90°; with the servo's minimum at 90°
    PX4 would allocate them forward while the model's rotors point up: C418 on both."""
    text = (AIRFRAME_DIR / "4020_tiltrotor").read_text().replace(
        "CA_SV_TL0_MINA 0", "CA_SV_TL0_MINA 90").replace("CA_SV_TL1_MINA 0", "CA_SV_TL1_MINA 90")
    errors = [f for f in findings("4020_tiltrotor", text, tmp_path) if f.severity == "error"]
    assert sorted((f.code, f.subject) for f in errors) == [("C418", "CA_ROTOR0"),
                                                          ("C418", "CA_ROTOR2")]


def test_tilted_axis_and_upward_test_by_hand():
    # ActuatorEffectivenessRotors::tiltedAxis: 0° is up (0, 0, -1), 90° towards the
    # direction: 0° direction is forward, 90° right.
    np.testing.assert_allclose(tilted_axis(0.0, 0.0), [0, 0, -1], atol=1e-15)
    np.testing.assert_allclose(tilted_axis(math.pi / 2, 0.0), [1, 0, 0], atol=1e-15)
    np.testing.assert_allclose(tilted_axis(math.pi / 2, math.pi / 2), [0, 1, 0], atol=1e-15)
    assert is_upward(np.array([0.05, -0.05, -0.99])) and not is_upward(np.array([1.0, 0, 0]))


def test_airframe_classes_match_px4_source():
    """ControlAllocator's EffectivenessSource numbers and each class's axis configuration."""
    assert {k: v.axes for k, v in AIRFRAMES.items() if v.rotor_table} == {
        0: "configurable", 1: "forward", 2: "configurable", 3: "configurable",
        4: "configurable", 7: "configurable", 8: "upward", 9: "configurable"}
    assert not AIRFRAMES[1].propeller_torque and AIRFRAMES[2].torque_upward_only
    params = load_px4_params(AIRFRAME_DIR / "4003_fixed_wing")
    (ca,) = params.rotors()
    assert rotor_axis(params, ca, AIRFRAMES[1]).axis_frd.tolist() == [1.0, 0.0, 0.0]
