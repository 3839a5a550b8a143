"""The frame catalogue, checked from first principles rather than against itself."""

from __future__ import annotations

import math

import numpy as np
import pytest

from reedtool.errors import ReedtoolError
from reedtool.generate.airframes import FRAMES, GROUND_FRAMES, MULTIROTOR_FRAMES, get_frame

K_M = 0.016  # moment constant [m], the seed's


def allocation(frame, arm_m=0.25, top_m=0.03):
    """Thrust per rotor -> [F_z, tau_x, tau_y, tau_z], built here from rigid-body mechanics.

    A thrust T along +z at r = (x, y, z) gives the torque r x (0, 0, T) = (y T, -x T, 0);
    a ccw rotor (seen from above) pushes the body clockwise: -k_m T about z.
    """
    positions = frame.rotor_positions_m(arm_m, top_m)
    columns = []
    for slot, (x, y, _z) in zip(frame.rotors, positions):
        spin = 1.0 if slot.direction == "ccw" else -1.0
        columns.append([1.0, y, -x, -spin * K_M])
    return np.array(columns).T


@pytest.mark.parametrize("name", MULTIROTOR_FRAMES)
def test_allocation_has_full_rank(name):
    assert np.linalg.matrix_rank(allocation(FRAMES[name])) == 4


@pytest.mark.parametrize("name", MULTIROTOR_FRAMES)
def test_equal_thrusts_hover_without_torque(name):
    """Yaw moments balance and the rotor centre is the origin (the body's COM)."""
    wrench = allocation(FRAMES[name]) @ np.ones(FRAMES[name].rotor_count)
    # A sum of n unit axes' z components (1.0): exact; approx's default is a ceiling.
    assert wrench[0] == pytest.approx(FRAMES[name].rotor_count)
    assert np.allclose(wrench[1:], 0.0, atol=1e-12)


@pytest.mark.parametrize("name", MULTIROTOR_FRAMES)
def test_numbering_and_spin(name):
    frame = FRAMES[name]
    assert [s.motor_number for s in frame.rotors] == list(range(frame.rotor_count))
    assert len({s.suffix for s in frame.rotors}) == frame.rotor_count
    assert {s.direction for s in frame.rotors} == {"ccw", "cw"}
    top = [s for s in frame.rotors if s.level > 0]
    if len(top) == frame.rotor_count:
        # Planar frames: neighbours around the ring spin opposite ways.
        ring = sorted(top, key=lambda s: s.bearing_deg % 360)
        for a, b in zip(ring, ring[1:] + ring[:1]):
            assert a.direction != b.direction, (a.suffix, b.suffix)
    else:
        # Coaxial: each lower rotor sits under an upper one and spins the other way.
        for lower in (s for s in frame.rotors if s.level < 0):
            upper = [s for s in top if s.bearing_deg == lower.bearing_deg]
            assert len(upper) == 1 and upper[0].direction != lower.direction


def test_quad_x_is_the_seeds_layout():
    """Seed 000 (reed_quad_x.xacro): motor 0 front_right (L, -L) ccw, 1 back_left (-L, L)
    ccw, 2 front_left (L, L) cw, 3 back_right (-L, -L) cw, at height 0.026."""
    frame = FRAMES["quad-x"]
    L = 0.18738
    positions = frame.rotor_positions_m(L, 0.026)
    expected = [("front_right", (L, -L, 0.026), "ccw"), ("back_left", (-L, L, 0.026), "ccw"),
                ("front_left", (L, L, 0.026), "cw"), ("back_right", (-L, -L, 0.026), "cw")]
    for slot, position, (suffix, xyz, direction) in zip(frame.rotors, positions, expected):
        assert (slot.suffix, slot.direction) == (suffix, direction)
        # The same cos/sin formula: a few ulps of 0.3 m (< 1e-16).
        assert np.allclose(position, xyz, atol=1e-15)


@pytest.mark.parametrize("name,first_suffix,bearing", [
    ("quad-plus", "right", 90.0), ("hex-x", "right", 90.0), ("hex-plus", "front", 0.0),
    ("octo-x", "front_right", 22.5), ("y6", "front_right_top", 60.0)])
def test_px4_motor_1_positions(name, first_suffix, bearing):
    """PX4 MAIN1 (RotorS motor 0) sits where PX4's airframe reference puts it."""
    frame = FRAMES[name]
    slot = frame.rotors[0]
    x, y, _ = frame.rotor_positions_m(1.0, 0.0)[0]
    assert slot.suffix == first_suffix
    # FLU: bearing clockwise from the nose seen from above -> y = -sin.
    assert (x, y) == pytest.approx((math.cos(math.radians(bearing)),
                                    -math.sin(math.radians(bearing))))


@pytest.mark.parametrize("name", [n for n in MULTIROTOR_FRAMES if n != "quad-x"])
def test_arm_length_is_centre_to_rotor(name):
    positions = FRAMES[name].rotor_positions_m(0.3, 0.0)
    # hypot of cos/sin products: a few ulps; allclose's default rtol 1e-5 is a ceiling.
    assert np.allclose(np.hypot(positions[:, 0], positions[:, 1]), 0.3)


@pytest.mark.parametrize("name", GROUND_FRAMES)
def test_ground_layouts_are_symmetric(name):
    layout = FRAMES[name]
    assert layout.rotor_count == 0
    assert sum(w.side for w in layout.wheels) == 0
    assert len({w.name for w in layout.wheels}) == len(layout.wheels)


def test_unknown_frame_suggests_a_close_one():
    with pytest.raises(ReedtoolError) as info:
        get_frame("hexx")
    assert "hex-x" in info.value.one_line()
