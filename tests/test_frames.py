"""Rotations against hand-written matrices; axis conventions against their definitions."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from reedtool.errors import ReedtoolError
from reedtool.frames import (
    RIGHT_HANDED_CODES,
    axis_convention,
    describe_rotation,
    invert_T,
    make_T,
    matrix_to_rpy,
    rpy_to_matrix,
)


def test_rpy_single_axes_match_textbook_matrices():
    a = 0.3
    c, s = np.cos(a), np.sin(a)
    # Same cos/sin products, one rounding each: entries within 1 ulp of 1 (1.1e-16).
    np.testing.assert_allclose(rpy_to_matrix([a, 0, 0]), [[1, 0, 0], [0, c, -s], [0, s, c]], atol=1e-15)
    np.testing.assert_allclose(rpy_to_matrix([0, a, 0]), [[c, 0, s], [0, 1, 0], [-s, 0, c]], atol=1e-15)
    np.testing.assert_allclose(rpy_to_matrix([0, 0, a]), [[c, -s, 0], [s, c, 0], [0, 0, 1]], atol=1e-15)


def test_rpy_is_fixed_axis_xyz_order():
    # Fixed-axis XYZ: roll first about world x, then pitch about world y, then yaw about
    # world z. roll=90deg then yaw=90deg: body y ends up along world z; body x along world y.
    R = rpy_to_matrix([np.pi / 2, 0, np.pi / 2])
    # cos(pi/2) = 6e-17, not 0: products of it stay below 1e-16.
    np.testing.assert_allclose(R @ [1, 0, 0], [0, 1, 0], atol=1e-15)
    np.testing.assert_allclose(R @ [0, 1, 0], [0, 0, 1], atol=1e-15)
    np.testing.assert_allclose(R @ [0, 0, 1], [1, 0, 0], atol=1e-15)


@settings(max_examples=50, deadline=None)
@given(st.floats(-3.1, 3.1), st.floats(-1.5, 1.5), st.floats(-3.1, 3.1))
def test_matrix_to_rpy_round_trip(roll, pitch, yaw):
    rpy = matrix_to_rpy(rpy_to_matrix([roll, pitch, yaw]))
    # atan2/asin round trip: asin loses digits near |pitch| = 1.5 (slope 1/cos = 14),
    # so ~1e-14 rad; 1e-9 is the margin hypothesis' near-lock samples need.
    np.testing.assert_allclose(rpy, [roll, pitch, yaw], atol=1e-9)


def test_matrix_to_rpy_at_gimbal_lock_reproduces_rotation():
    R = rpy_to_matrix([0.4, np.pi / 2, -0.2])
    # At gimbal lock only roll - yaw is defined; the matrix rebuilt from it is a few
    # products of unit entries (a few ulps, ~1e-15); 1e-12 leaves margin for asin near 1.
    np.testing.assert_allclose(rpy_to_matrix(matrix_to_rpy(R)), R, atol=1e-12)


def test_make_and_invert_T():
    T = make_T(rpy_to_matrix([0.1, -0.7, 2.0]), [1.0, -2.0, 0.5])
    # R^T R of a rotation: 3-term dot products of unit entries, ~3 ulps (7e-16) each;
    # the translation part (|t| ~ 2) cancels to a few ulps of 2 (4e-16 each).
    np.testing.assert_allclose(invert_T(T) @ T, np.eye(4), atol=1e-14)
    # Exact: the fourth column times 1, plus zeros (default rtol 1e-7 is only a ceiling).
    np.testing.assert_allclose(T @ [0, 0, 0, 1], [1.0, -2.0, 0.5, 1.0])


def test_ned_and_frd_are_180_degrees_about_x():
    for name in ("ned", "frd", "NED"):
        conv = axis_convention(name)
        # Exact: signed permutation matrices are built from 0 and +-1.
        np.testing.assert_array_equal(conv.R_flu_src, np.diag([1.0, -1.0, -1.0]))
        assert conv.rotation_text == "180° about x"
    assert conv.description.startswith("NED → FLU: 180° about x")


def test_flu_aliases_are_identity():
    for name in ("flu", "enu", "nwu", "z-up"):
        # Exact: the identity is built, not computed.
        np.testing.assert_array_equal(axis_convention(name).R_flu_src, np.eye(3))


def test_y_up_maps_cad_axes_to_flu():
    R = axis_convention("y-up").R_flu_src
    # CAD y (up) -> FLU z; CAD z (front) -> FLU x; CAD x (left) -> FLU y.
    # Exact: a signed permutation times a unit vector (0 and +-1 arithmetic).
    np.testing.assert_array_equal(R @ [0, 1, 0], [0, 0, 1])
    np.testing.assert_array_equal(R @ [0, 0, 1], [1, 0, 0])
    np.testing.assert_array_equal(R @ [1, 0, 0], [0, 1, 0])


def test_all_letter_codes_are_proper_rotations():
    assert len(RIGHT_HANDED_CODES) == 24
    for code in RIGHT_HANDED_CODES:
        R = axis_convention(code).R_flu_src
        # Signed permutations: R R^T and det are exact (0/+-1 arithmetic); the default
        # tolerances (rtol 1e-7) are only a ceiling.
        np.testing.assert_allclose(R @ R.T, np.eye(3))
        assert np.linalg.det(R) == pytest.approx(1.0)


def test_unknown_and_left_handed_names_raise():
    with pytest.raises(ReedtoolError, match="unknown axis convention") as info:
        axis_convention("sideways")
    assert "ned" in info.value.hint and "frd" in info.value.hint
    with pytest.raises(ReedtoolError, match="left-handed"):
        axis_convention("fru")


def test_describe_rotation_general_axis():
    assert describe_rotation(np.eye(3)).startswith("identity")
    text = describe_rotation(axis_convention("luf").R_flu_src)
    assert text.startswith("120° about (0.577, 0.577, 0.577)")
