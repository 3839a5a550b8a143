"""PX4 classic (gazebo-classic) models read as gazebo_mavlink_interface drives them.

Fixtures: tests/fixtures/px4_classic (generate.py), in the shape of PX4-SITL_gazebo-classic's
iris (a channel list shared with other models) and advanced_plane (the puller is motor 4).
"""

from __future__ import annotations

from pathlib import Path

import pytest

from reedtool.checks.runner import run_checks
from reedtool.io.loader import load_robot
from reedtool.physics.rotors import command_vector, discover_rotors

FIX = Path(__file__).parent / "fixtures" / "px4_classic"


def codes(name: str, severities=("error", "warning")) -> list[str]:
    return sorted(f.code for f in run_checks(load_robot(FIX / name)) if f.severity in severities)


@pytest.mark.parametrize("name, expected", [
    ("iris_template_channels.sdf", []),
    ("plane_puller_motor_4.sdf", []),
    ("R302_bad_unfilled_number.sdf", ["R302"]),
    ("eight_channels_four_motors.sdf", []),
])
def test_classic_interface_codes(name, expected):
    assert codes(name) == expected


def test_command_vector_is_the_velocity_channels_input_indices():
    """iris: rotor1-4 (0..3) and rotor5, a velocity channel (4); rotor6-8 are servos."""
    vector = command_vector(load_robot(FIX / "iris_template_channels.sdf"))
    assert vector.indices == {0, 1, 2, 3, 4}
    plane = command_vector(load_robot(FIX / "plane_puller_motor_4.sdf"))
    assert plane.indices == {4}


def test_classic_advanced_lift_drag_is_a_wing():
    """libAdvancedLiftDragPlugin.so marks a wing: the lone puller is propulsion, so no
    hover rule (R304, R305, R308, R311) speaks about it."""
    (puller,) = discover_rotors(load_robot(FIX / "plane_puller_motor_4.sdf"))
    assert puller.role == "propulsion"
    assert codes("plane_puller_motor_4.sdf", ("error", "warning", "info")) == ["R319"]
