"""Rotor discovery and the allocation matrix, against hand-derived values."""

from pathlib import Path

import numpy as np

from reedtool.io.urdf import load_urdf_file
from reedtool.physics.allocation import allocation_matrix
from reedtool.physics.rotors import declared_rotor_counts, discover_rotors

CORE = Path(__file__).parent / "fixtures" / "core"
ARM = 0.18738  # seed 000's arm length


def test_seed_quad_rotors():
    robot = load_urdf_file(CORE / "quad_x_rotors.urdf")
    rotors = discover_rotors(robot)
    by_number = {r.motor_number: r for r in rotors}
    assert sorted(by_number) == [0, 1, 2, 3]
    expected = {0: (ARM, -ARM, "ccw"), 1: (-ARM, ARM, "ccw"), 2: (ARM, ARM, "cw"), 3: (-ARM, -ARM, "cw")}
    for number, (x, y, direction) in expected.items():
        rotor = by_number[number]
        # Exact: the joint origin's numbers, read and copied (one parent at the identity).
        np.testing.assert_allclose(rotor.position_m, [x, y, 0.026])
        np.testing.assert_allclose(rotor.axis, [0, 0, 1])
        assert rotor.direction == direction
        # Exact: plugin text read by float() equals the literals.
        assert rotor.motor_constant == 8.54858e-06 and rotor.moment_constant == 0.016
        assert rotor.max_rot_velocity_rad_s == 838 and rotor.kind == "rotors"
        assert (rotor.time_constant_up_s, rotor.time_constant_down_s) == (0.0125, 0.025)
        assert rotor.rotor_drag_coefficient == 8.06428e-05
        assert rotor.rolling_moment_coefficient == 1e-6
    assert [d.rotor_count for d in declared_rotor_counts(robot)] == [6]


def test_allocation_matches_hand_derivation():
    rotors = sorted(discover_rotors(load_urdf_file(CORE / "quad_x_rotors.urdf")),
                    key=lambda r: r.motor_number)
    B = allocation_matrix(rotors, np.zeros(3))
    # Column i: [1, y_i, -x_i, -s_i * c_m] for an upright rotor at (x_i, y_i) with spin sign s_i.
    expected = np.array([
        [1, 1, 1, 1],
        [-ARM, ARM, ARM, -ARM],
        [-ARM, ARM, -ARM, ARM],
        [-0.016, -0.016, 0.016, 0.016],
    ])
    # Cross products of <= 0.2 m positions with unit axes: a few ulps (< 1e-16).
    np.testing.assert_allclose(B, expected, atol=1e-15)
    assert np.linalg.matrix_rank(B) == 4


def test_three_plugin_families_and_tilt():
    robot = load_urdf_file(CORE / "tilted_mixed.urdf")
    rotors = {r.link: r for r in discover_rotors(robot)}
    assert {r.kind for r in rotors.values()} == {"rotors", "px4", "gz"}
    a = rotors["rotor_a"]
    # Composed joint transforms with rotations: a few ulps of 0.2 m (~1e-16).
    np.testing.assert_allclose(a.position_m, [0.1, 0.2, 0.05], atol=1e-12)
    np.testing.assert_allclose(a.axis, [np.sin(0.3), 0, np.cos(0.3)], atol=1e-12)
    assert rotors["rotor_b"].turning_sign == -1 and rotors["rotor_c"].turning_sign == 0
    assert rotors["rotor_c"].direction == "sideways"
    # Exact: the same expression, k * w_max ** 2, evaluated the same way.
    assert rotors["rotor_b"].max_thrust_N == 2e-5 * 900 ** 2
    # PX4 classic's interface declares no rotor count (its channels are outputs, R302
    # checks the motors' numbers against them); only RotorS's <rotor_count> does.
    assert [d.rotor_count for d in declared_rotor_counts(robot)] == []
    from reedtool.physics.rotors import command_vector
    vector = command_vector(robot)
    assert vector is not None and 0 in vector.indices
    # Tilted rotor's column: force along the axis, torque = r x a - s c_m a.
    B = allocation_matrix([a], np.zeros(3))
    axis = np.array([np.sin(0.3), 0, np.cos(0.3)])
    np.testing.assert_allclose(B[:, 0], [np.cos(0.3), *(np.cross([0.1, 0.2, 0.05], axis) - 0.02 * axis)])
