"""Static hover trim: closed-form references and named causes of infeasibility."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from reedtool.model import SourceLoc
from reedtool.physics.allocation import allocation_matrix
from reedtool.physics.rotors import Rotor
from reedtool.physics.trim import BOUND_MARGIN, TrimCause, solve_trim
from reedtool.sim.params import VehicleParams

G = 9.80665
K = 8.54858e-06
C_M = 0.016
OMEGA_MAX = 838.0


def rotor(i: int, position, direction: str, *, k: float = K, axis=(0.0, 0.0, 1.0),
          omega_max: float = OMEGA_MAX, c_m: float = C_M) -> Rotor:
    return Rotor(name=f"rotor_{i}", joint=f"rotor_{i}_joint", link=f"rotor_{i}",
                 position_m=np.asarray(position, dtype=float),
                 axis=np.asarray(axis, dtype=float) / np.linalg.norm(axis),
                 direction=direction, turning_sign={"ccw": 1, "cw": -1}.get(direction, 0),
                 motor_number=i, motor_constant=k, moment_constant=c_m,
                 max_rot_velocity_rad_s=omega_max, time_constant_up_s=0.0125,
                 time_constant_down_s=0.025, rotor_drag_coefficient=8.06428e-05,
                 rolling_moment_coefficient=1e-6, kind="rotors", plugin=None,
                 loc=SourceLoc("test.urdf", i + 1))


def ring(n: int, arm_m: float = 0.25, height_m: float = 0.03, **kw) -> list[Rotor]:
    """n rotors evenly on a circle, alternating ccw/cw (a flat symmetric frame)."""
    out = []
    for i in range(n):
        angle = 2 * math.pi * (i + 0.5) / n
        out.append(rotor(i, (arm_m * math.cos(angle), arm_m * math.sin(angle), height_m),
                         "ccw" if i % 2 == 0 else "cw", **kw))
    return out


@pytest.mark.parametrize("n", [4, 6, 8])
@pytest.mark.parametrize("mass_kg", [0.8, 1.535, 2.2])
def test_symmetric_frames_hover_at_sqrt_mg_over_nk(n, mass_kg):
    trim = solve_trim(mass_kg, np.array([0.0, 0.0, 0.01]), ring(n))
    assert trim.feasible and trim.cause is None
    expected = math.sqrt(mass_kg * G / (n * K))
    # The pseudo-inverse (SVD) solution of a symmetric frame: ~cond(A) = O(10) ulps
    # from the closed form, ~1e-15; 1e-9 allows any LAPACK's SVD, a wrong k is 1e-1.
    np.testing.assert_allclose(trim.omega_rad_s, expected, rtol=1e-9, atol=0)
    np.testing.assert_allclose(trim.throttle, expected / OMEGA_MAX, rtol=1e-9)
    # A sum of n equal products vs n times one: n roundings, ~1e-15; rel 1e-12 holds.
    assert trim.thrust_to_weight == pytest.approx(n * K * OMEGA_MAX ** 2 / (mass_kg * G),
                                                  rel=1e-12)
    assert trim.rank == 4
    # A @ pinv(A) @ w - w: cond(A) ulps of the weight (~1e-14 of it); 1e-9 of it holds.
    np.testing.assert_allclose(trim.residual_wrench, 0.0, atol=1e-9 * mass_kg * G)


def test_quad_torque_authority_matches_the_closed_form():
    # Quad 'x' with rotors at (+-a, +-a): a pure roll torque moves the four thrusts by
    # -+tau / (4a); the first rotor to hit 0 or its maximum bounds the authority.
    mass_kg, arm = 1.5, 0.25
    rotors = ring(4, arm_m=arm, height_m=0.0)
    trim = solve_trim(mass_kg, np.zeros(3), rotors)
    a = arm / math.sqrt(2)
    hover, t_max = mass_kg * G / 4, K * OMEGA_MAX ** 2
    roll_pitch = 4 * a * min(hover, t_max - hover)
    yaw = 4 * C_M * min(hover, t_max - hover)
    # Closed form vs the pseudo-inverse's columns: O(10) ulps; 1e-9 allows any LAPACK.
    np.testing.assert_allclose(trim.torque_authority_N_m, [roll_pitch, roll_pitch, yaw],
                               rtol=1e-9)


def test_one_rotor_direction_flipped_cannot_balance_yaw():
    rotors = ring(4)
    assert rotors[2].direction == "ccw"
    rotors[2] = rotor(2, rotors[2].position_m, "cw")
    trim = solve_trim(1.5, np.zeros(3), rotors)
    assert not trim.feasible
    assert trim.cause is TrimCause.YAW_UNBALANCED


def test_all_rotors_one_direction_lose_yaw_rank():
    rotors = [rotor(i, r.position_m, "ccw") for i, r in enumerate(ring(4))]
    trim = solve_trim(1.5, np.zeros(3), rotors)
    assert (trim.feasible, trim.cause, trim.rank) == (False, TrimCause.YAW_UNBALANCED, 3)


def test_motor_constant_divided_by_ten_lacks_thrust():
    trim = solve_trim(1.535, np.zeros(3), ring(4, k=K / 10))
    assert not trim.feasible
    assert trim.cause is TrimCause.INSUFFICIENT_THRUST
    # The same products in another order: a few ulps; default rel 1e-6 is a ceiling.
    assert trim.thrust_to_weight == pytest.approx(4 * K / 10 * OMEGA_MAX ** 2 / (1.535 * G))


@pytest.mark.parametrize("com_m", [(0.30, 0.0, 0.0), (0.0, -0.26, 0.0), (0.2, 0.2, 0.1)])
def test_com_outside_the_rotor_polygon_cannot_be_balanced(com_m):
    trim = solve_trim(1.5, np.array(com_m), ring(4, arm_m=0.25))
    assert not trim.feasible
    assert trim.cause is TrimCause.COM_UNBALANCED
    assert np.min(trim.demand_N) < 0.0   # the least-squares demand pulls a rotor down
    assert "min" in trim.limits()        # ... and that rotor is shown at 0, not below


def test_com_inside_the_polygon_is_balanced_by_uneven_thrust():
    com = np.array([0.05, -0.02, 0.0])
    rotors = ring(4)
    trim = solve_trim(1.5, com, rotors)
    assert trim.feasible
    # Independent check of the claim: the thrusts hold the weight about the COM.
    A = allocation_matrix(rotors, com)
    np.testing.assert_allclose(A @ trim.thrust_N, [1.5 * G, 0, 0, 0], atol=1e-9)
    assert len(set(np.round(trim.thrust_N, 9))) > 1


def test_no_rotors_and_invalid_rotors_are_named():
    assert solve_trim(1.0, np.zeros(3), []).cause is TrimCause.NO_ROTORS
    bad = ring(4)
    bad[1] = rotor(1, bad[1].position_m, "cw", k=float("nan"))
    assert solve_trim(1.0, np.zeros(3), bad).cause is TrimCause.INVALID_PARAMETERS


def test_rotors_in_a_line_cannot_control_roll():
    rotors = [rotor(i, (x, 0.0, 0.0), d) for i, (x, d) in
              enumerate([(-0.3, "ccw"), (-0.1, "cw"), (0.1, "ccw"), (0.3, "cw")])]
    trim = solve_trim(1.0, np.zeros(3), rotors)
    assert (trim.feasible, trim.cause) == (False, TrimCause.RANK_DEFICIENT)


def test_hexacopter_redistributes_when_the_minimum_norm_split_does_not_fit():
    # A hex whose COM sits towards rotors 0 and 5: the pseudo-inverse asks rotors 2 and 3
    # for negative thrust, yet a split with every rotor in range exists (the null space
    # of a hex's allocation has two dimensions). Found by the null-space search.
    rotors = ring(6, arm_m=0.25, height_m=0.0)
    com = np.array([0.145, 0.0, 0.0])
    A = allocation_matrix(rotors, com)
    demand = np.linalg.pinv(A) @ [1.0 * G, 0, 0, 0]
    assert demand.min() < 0
    trim = solve_trim(1.0, com, rotors)
    assert trim.feasible
    t_max = K * OMEGA_MAX ** 2
    assert np.all(trim.thrust_N > 0) and np.all(trim.thrust_N < t_max)
    # A redistributed (LP-like) solution: a few ulps times cond(A) ~ 1e2 of ~10 N,
    # ~1e-13 N; 1e-8 N holds any solver's rounding, a wrong split is O(1) N.
    np.testing.assert_allclose(A @ trim.thrust_N, [1.0 * G, 0, 0, 0], atol=1e-8)


def test_sim_allocation_matches_the_lead_allocation_for_tilted_rotors():
    rng = np.random.default_rng(4)
    rotors = [rotor(i, rng.uniform(-0.3, 0.3, 3), "ccw" if i % 2 else "cw",
                    axis=rng.normal(size=3) * [0.3, 0.3, 1] + [0, 0, 2]) for i in range(6)]
    com = rng.uniform(-0.02, 0.02, 3)
    params = VehicleParams.from_rotors(2.0, com, np.diag([0.03, 0.03, 0.05]), rotors)
    # Two implementations of the same cross products (entries <= 0.3 m): a few ulps,
    # < 1e-16; 1e-15 holds.
    np.testing.assert_allclose(params.allocation(), allocation_matrix(rotors, com),
                               atol=1e-15)


@settings(max_examples=60, deadline=None)
@given(n=st.sampled_from([4, 6, 8]),
       com=st.tuples(*[st.floats(-0.2, 0.2)] * 2, st.floats(-0.05, 0.05)),
       k=st.floats(2e-6, 2e-5), mass=st.floats(0.5, 4.0), flip=st.integers(-1, 7))
def test_a_feasible_trim_always_holds_the_weight_within_limits(n, com, k, mass, flip):
    rotors = ring(n, k=k)
    if 0 <= flip < n:
        r = rotors[flip]
        rotors[flip] = rotor(flip, r.position_m, "cw" if r.direction == "ccw" else "ccw", k=k)
    trim = solve_trim(mass, np.array(com), rotors)
    t_max = k * OMEGA_MAX ** 2
    if trim.feasible:
        A = allocation_matrix(rotors, np.array(com))
        # Random layouts: cond(A) up to ~1e4 near infeasibility times ulps of the weight,
        # ~1e-12 of it; 1e-7 of the weight holds them, a wrong split is O(1).
        np.testing.assert_allclose(A @ trim.thrust_N, [mass * G, 0, 0, 0],
                                   atol=1e-7 * mass * G)
        assert np.all(trim.thrust_N > 0) and np.all(trim.thrust_N < t_max)
        # sqrt then square: 2-3 roundings (~7e-16); 1e-12 holds.
        np.testing.assert_allclose(k * trim.omega_rad_s ** 2, trim.thrust_N, rtol=1e-12)
    else:
        assert trim.cause in (TrimCause.INSUFFICIENT_THRUST, TrimCause.COM_UNBALANCED,
                              TrimCause.YAW_UNBALANCED)
        if trim.cause is TrimCause.INSUFFICIENT_THRUST:
            assert n * t_max < mass * G


@pytest.mark.parametrize("case", ["heavy", "com", "yaw"])
def test_an_infeasible_trim_shows_each_rotor_at_what_it_can_give(case):
    # Issue 19: the table listed 12.57 N at 1000 rad/s for a rotor whose maximum is
    # k*w_max^2 = 8.55 N, and -1.07 N at 0 rad/s. Each row must be a thrust the rotor can
    # make, k*w^2 of the speed beside it; the demand beyond a limit is kept beside it.
    rotors = ring(4)
    if case == "yaw":
        rotors[1] = rotor(1, rotors[1].position_m, "ccw")          # three ccw, one cw
    mass, com = {"heavy": (3.2, np.zeros(3)), "com": (1.5, np.array([0.3, 0.0, 0.0])),
                 "yaw": (1.5, np.zeros(3))}[case]
    trim = solve_trim(mass, com, rotors)
    assert not trim.feasible
    t_max = K * OMEGA_MAX ** 2
    assert np.all(trim.thrust_N >= 0.0) and np.all(trim.thrust_N <= t_max)
    assert not np.any(np.signbit(trim.thrust_N))                     # no "-0.0000 N"
    # One multiplication and a square root apart: a few ulps (rtol 1e-12 is ~4500).
    np.testing.assert_allclose(K * trim.omega_rad_s ** 2, trim.thrust_N, rtol=1e-12, atol=0)
    limits = trim.limits()
    for want, got, limit in zip(trim.demand_N, trim.thrust_N, limits):
        if limit == "max":
            assert want > t_max and got == t_max                     # clipped: exact
        elif limit == "min":
            assert want < 0.0 and got == 0.0
        else:   # within round-off of its range (BOUND_MARGIN) of where it is shown
            assert abs(got - want) <= BOUND_MARGIN * t_max
    assert any(limits)
    rows = trim.to_dict()["rotors"]
    assert [r["limit"] for r in rows] == limits
    assert trim.cause is {"heavy": TrimCause.INSUFFICIENT_THRUST,
                          "com": TrimCause.COM_UNBALANCED,
                          "yaw": TrimCause.YAW_UNBALANCED}[case]
