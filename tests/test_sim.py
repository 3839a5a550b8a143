"""Hover simulation: physics against closed forms, the two engines against each other,
and every way a run ends (asserted by ExitStatus, not wording)."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from reedtool.sim import ExitStatus, HoverConfig
from reedtool.sim.batch import (
    Spreads,
    perturbed_plant,
    robustness_batch,
    sample_perturbations,
    simulate_batch,
)
from reedtool.sim import equations
from reedtool.sim.controller import ControllerGains
from reedtool.sim.dynamics import (
    Plant,
    State,
    body_wrench,
    quat_from_rpy,
    rot_matrices,
    step_rigid_body,
)
from reedtool.sim.motor import speed_command, speed_filter_factors
from reedtool.sim.params import VehicleParams, symmetric_multirotor
from reedtool.sim.run import simulate_hover

G = 9.80665


def tilted_hex() -> VehicleParams:
    """An awkward vehicle: tilted rotors, full inertia tensor, COM off the rotor plane."""
    base = symmetric_multirotor(6, arm_m=0.3, mass_kg=2.0)
    rng = np.random.default_rng(7)
    axes = np.array([[0.0, 0.0, 1.0]] * 6) + rng.normal(scale=0.03, size=(6, 3)) * [1, 1, 0]
    J = np.array([[0.05, 0.002, -0.001], [0.002, 0.055, 0.0015], [-0.001, 0.0015, 0.09]])
    return base.with_changes(rotor_axis=axes, inertia_kg_m2=J,
                             rotor_position_m=base.rotor_position_m + [0.004, -0.002, 0.04])


# ------------------------------------------------------------------ physics

def one_vehicle_state(params: VehicleParams, omega) -> State:
    return State(p=np.zeros((3, 1)), v=np.zeros((3, 1)),
                 q=np.array([[1.0], [0.0], [0.0], [0.0]]), w=np.zeros((3, 1)),
                 omega=np.asarray(omega, dtype=float).reshape(-1, 1))


def test_free_fall_follows_the_discrete_kinematics():
    params = symmetric_multirotor(4)
    plant = Plant.from_params(params)
    state = one_vehicle_state(params, np.zeros(4))
    dt, steps = 1e-3, 500
    for _ in range(steps):
        R = rot_matrices(state.q)
        force, torque = body_wrench(plant, state, R)
        step_rigid_body(plant, state, R, force, torque, dt)
    # Semi-implicit Euler: v_k = -g k dt, z_k = -g dt^2 k (k + 1) / 2.
    assert state.v[2, 0] == pytest.approx(-G * steps * dt, rel=1e-12)
    assert state.p[2, 0] == pytest.approx(-G * dt * dt * steps * (steps + 1) / 2, rel=1e-12)
    assert state.p[2, 0] == pytest.approx(-0.5 * G * (steps * dt) ** 2, rel=2 * 1.0 / steps)


def test_torque_free_tumbling_keeps_angular_momentum_and_energy():
    params = tilted_hex()
    plant = Plant.from_params(params)
    state = one_vehicle_state(params, np.zeros(6))
    state.w[:, 0] = [3.0, -1.0, 2.0]
    J = params.inertia_kg_m2

    def momentum_world_and_energy():
        R = rot_matrices(state.q)[:, :, 0]
        w = state.w[:, 0]
        return R @ J @ w, 0.5 * w @ J @ w

    L0, E0 = momentum_world_and_energy()
    plant.g_m_s2 = 0.0
    for _ in range(2000):
        R = rot_matrices(state.q)
        step_rigid_body(plant, state, R, np.zeros((3, 1)), np.zeros((3, 1)), 5e-4)
    L1, E1 = momentum_world_and_energy()
    # First-order integrator: step halving gives |dL|/|L| = 1.0e-3, 5.0e-4, 2.5e-4 and
    # |dE|/E = 1.1e-3, 5.6e-4, 2.8e-4 at dt 1, 0.5, 0.25 ms (error ~ dt, as the order says);
    # at 0.5 ms that is 5e-4, and 5e-3 is 10x it: a wrong gyroscopic term drifts by O(1).
    np.testing.assert_allclose(L1, L0, rtol=0, atol=5e-3 * np.linalg.norm(L0))
    assert E1 == pytest.approx(E0, rel=5e-3)


def test_thrust_and_yaw_reaction_follow_rotors_conventions():
    # One ccw rotor at (l, 0, 0): thrust k w^2 up, pitch torque -l T, and the RotorS
    # reaction -turning_sign * c_m * T about the axis (a ccw rotor pushes the body cw).
    params = symmetric_multirotor(4, rotor_drag_coefficient=0.0, rolling_moment_coefficient=0.0)
    params = params.with_changes(rotor_position_m=[[0.2, 0, 0], [0, 0.2, 0], [-0.2, 0, 0],
                                                   [0, -0.2, 0]])
    omega = np.array([600.0, 0.0, 0.0, 0.0])
    force, torque = body_wrench(Plant.from_params(params), one_vehicle_state(params, omega),
                                rot_matrices(np.array([[1.0], [0], [0], [0]])))
    T = params.motor_constant[0] * 600.0 ** 2
    # T ~ 3 N from a few products: rounding ~1e-15 N; 1e-12 leaves margin, a wrong
    # sign or lever arm (0.2 m) is O(1) N.
    np.testing.assert_allclose(force[:, 0], [0, 0, T], atol=1e-12)
    np.testing.assert_allclose(torque[:, 0], [0, -0.2 * T, -params.moment_constant[0] * T],
                               atol=1e-12)


def test_rotor_drag_matches_the_per_rotor_formula():
    # equations.rotor_wrench's drag against RotorS' formula written here with numpy's
    # cross products: force -w c_d u_perp at the rotor, its moment r x F, rolling moment
    # -w c_r u_perp, u the rotor's airspeed v + w x r without its part along the axis.
    params = tilted_hex()
    rng = np.random.default_rng(1)
    v, w = rng.normal(size=3), rng.normal(size=3)
    speed = 500.0
    for i in range(params.n_rotors):
        r, a = params.rotor_position_m[i], params.rotor_axis[i]
        u = v + np.cross(w, r)
        u_perp = u - (u @ a) * a
        force = -speed * params.rotor_drag_coefficient[i] * u_perp
        expected = np.concatenate([force, np.cross(r, force)
                                   - speed * params.rolling_moment_coefficient[i] * u_perp])
        got = equations.rotor_wrench(*r, *a, 0.0, 0.0, 0.0, params.rotor_drag_coefficient[i],
                                     params.rolling_moment_coefficient[i], 0.0, speed, *v, *w)
        # Entries ~0.04 N (drag coefficients ~1e-4 times 500 rad/s, O(1) speeds):
        # rounding ~1e-17; 1e-13 is far above it and far below the entries themselves.
        np.testing.assert_allclose(got, expected, atol=1e-13)


def test_motor_response_and_command_limits():
    up, down = speed_filter_factors(1e-3, np.array([0.0125]), np.array([0.025]))
    # Same formula in numpy and math: pytest.approx's default rel 1e-6 is only a ceiling
    # (the values agree to an ulp); a wrong time constant moves them by ~1e-2.
    assert up[0] == pytest.approx(math.exp(-1e-3 / 0.0125))
    assert down[0] == pytest.approx(math.exp(-1e-3 / 0.025))
    cmd = speed_command(np.array([-1.0, 2.0, 1e9]), np.array([1e-5] * 3), np.array([800.0] * 3))
    # Exact limits (0 and 800 are clamps) and one sqrt (correctly rounded): the default
    # rtol 1e-7 is only a ceiling.
    np.testing.assert_allclose(cmd, [0.0, math.sqrt(2.0 / 1e-5), 800.0])


def test_allocation_desaturates_keeping_the_torque_direction():
    params = symmetric_multirotor(4)
    gains = ControllerGains.from_params(params)
    t_max = params.thrust_max_N
    wrench = np.array([[params.weight_N], [3.0], [1.5], [0.4]])   # far beyond authority
    pinv = tuple(float(x) for x in gains.allocation_pinv.ravel())
    thrust = [0.0] * 4
    equations.pinv_thrusts(pinv, *wrench[:, 0], thrust)
    saturated, _ = equations.desaturate(pinv, tuple(t_max), *wrench[:, 0], thrust)
    thrust = np.array(thrust)[:, None]
    assert saturated
    assert np.all(thrust >= -1e-12) and np.all(thrust <= t_max[:, None] + 1e-9)
    achieved = params.allocation() @ thrust[:, 0]
    assert achieved[0] == pytest.approx(params.weight_N)         # thrust kept
    roll_pitch = achieved[1:3] / np.linalg.norm(achieved[1:3])
    np.testing.assert_allclose(roll_pitch, np.array([3.0, 1.5]) / math.hypot(3.0, 1.5),
                               atol=1e-12)                        # direction kept


# ------------------------------------------------------------------ the two engines

# Engines (plain floats, numpy arrays, numba) and batch widths compute the same steps with
# other kernels and summation orders: a few ulps apart per step. Their results are held to
# ENGINE_RTOL, which test_engine_tolerance_stands_far_above_the_ulp_floor keeps at least
# 20x above what these flights make of a 1- or 16-ulp change of their inputs (measured:
# up to 1.3e-10 relative, in the saturating spread batch, where a few ulps decide the step
# at which the allocation switches), and below what a wrong equation does (a 1e-6 change
# of the mass moves the results by more than 10x ENGINE_RTOL).
ENGINE_RTOL = 1e-8
ENGINE_CONFIG = HoverConfig(duration_s=2.5, offset_m=(0.3, -0.2, 0.25), roll_rad=0.15,
                            pitch_rad=-0.1, yaw_rad=0.3)


def relative_change(a, b) -> float:
    """Largest change of the compared outcome fields, relative to each field's scale."""
    worst = 0.0
    for name in ("final_omega_rad_s", "max_position_error_m", "max_attitude_error_deg",
                 "longest_saturation_s"):
        x, y = np.asarray(getattr(a, name), float), np.asarray(getattr(b, name), float)
        scale = float(np.nanmax(np.abs(x))) if np.isfinite(x).any() else 0.0
        if scale > 0:
            worst = max(worst, float(np.nanmax(np.abs(x - y))) / scale)
    return worst


def fly_alone(params, config, plant):
    """A one-vehicle plant's flight on the traced float step: the one-column batch bit for
    bit (test_equations; test_one_by_one_is_the_column_batch_exactly), ~20x faster, so the
    ulp studies below measure the same numbers in a fraction of the suite's time."""
    from reedtool.sim.batch import simulate_one_by_one
    from reedtool.sim.controller import ControllerDesign

    assert plant.n_vehicles == 1
    return simulate_one_by_one(params, config, plant, ControllerDesign(), None, False)


def batch_with_mass_scaled(params, config, plant_perturbation, scale):
    changed = replace(plant_perturbation, mass_scale=plant_perturbation.mass_scale * scale)
    plant = perturbed_plant(params, changed)
    fly = fly_alone if plant.n_vehicles == 1 else simulate_batch
    return fly(params, config, plant)


@pytest.mark.parametrize("case", ["quad", "tilted-hex", "spread-batch"])
def test_engine_tolerance_stands_far_above_the_ulp_floor(case):
    eps = np.finfo(float).eps
    if case == "spread-batch":   # test_compiled's batch: crashes, saturation and recovery
        params, config = symmetric_multirotor(4), HoverConfig(duration_s=3.0)
        perturbation = sample_perturbations(150, 4, Spreads(mass_rel=0.3, com_m=0.03,
                                                            inertia_rel=0.2,
                                                            motor_constant_rel=0.15), 3)
    else:
        params = symmetric_multirotor(4) if case == "quad" else tilted_hex()
        config = ENGINE_CONFIG
        perturbation = sample_perturbations(1, params.n_rotors, Spreads(0, 0, 0, 0), seed=1)
    ref = batch_with_mass_scaled(params, config, perturbation, 1.0)
    floor = max(relative_change(ref, batch_with_mass_scaled(params, config, perturbation,
                                                            1.0 + k * eps))
                for k in (1, 16, -16))
    assert floor * 20 <= ENGINE_RTOL
    # ... and a real change (1e-6 of the mass) is far above the tolerance: it can fail.
    assert relative_change(ref, batch_with_mass_scaled(params, config, perturbation,
                                                       1.0 + 1e-6)) > 10 * ENGINE_RTOL


@pytest.mark.parametrize("make", [lambda: symmetric_multirotor(4), tilted_hex])
def test_plain_float_engine_matches_the_array_engine(make):
    params = make()
    config = ENGINE_CONFIG
    run = simulate_hover(params, config, record=False)
    out = simulate_batch(params, config)
    assert out.status(0) is run.status
    # Two engines: ENGINE_RTOL (>= 20x this flight's measured ulp floor, see above).
    np.testing.assert_allclose(run.final_omega_rad_s, out.final_omega_rad_s[:, 0],
                               rtol=ENGINE_RTOL)
    assert run.max_position_error_m == pytest.approx(out.max_position_error_m[0],
                                                     rel=ENGINE_RTOL)
    assert run.max_attitude_error_deg == pytest.approx(out.max_attitude_error_deg[0],
                                                       rel=ENGINE_RTOL)
    # A final error of ~1e-5 m is the difference of two ~2 m coordinates: one ulp of 2 m
    # (4.4e-16 m) is 4e-11 of it before the flight amplifies it, so it keeps fewer digits
    # than ENGINE_RTOL: rel 1e-6 (100x ENGINE_RTOL), abs 1e-12 m for a settled 0.
    assert run.final_position_error_m == pytest.approx(out.final_position_error_m[0],
                                                       rel=1e-6, abs=1e-12)


# ------------------------------------------------------------------ hover results

@pytest.mark.parametrize("n", [4, 6, 8])
def test_steady_hover_speed_equals_the_trim(n):
    params = symmetric_multirotor(n, mass_kg=1.0 + 0.2 * n)
    run = simulate_hover(params, HoverConfig(duration_s=12.0), record=False)
    assert run.status is ExitStatus.PASSED
    expected = math.sqrt(params.mass_kg * G / (n * params.motor_constant[0]))
    # Settled for ~9 s, the remaining error decays with the closed loop: measured 1.3e-9
    # of the hover speed for n = 4, 6, 8; 1e-6 is a margin over that, far below a wrong k.
    np.testing.assert_allclose(run.final_omega_rad_s, expected, rtol=1e-6)


def test_undisturbed_hover_stays_exactly_at_trim():
    params = symmetric_multirotor(6).with_changes(inertia_kg_m2=tilted_hex().inertia_kg_m2)
    config = HoverConfig(duration_s=2.0, offset_m=(0.0, 0.0, 0.0), roll_rad=0.0)
    run = simulate_hover(params, config)
    # Settled at the first sample (0.01 s at 100 Hz): exact up to approx's default
    # rel 1e-6 for the float product of steps and dt.
    assert run.status is ExitStatus.PASSED and run.settle_time_s == pytest.approx(0.01)
    # Undisturbed: the state moves only by rounding of the trim (measured 1.3e-15, a few
    # ulps) through a stable loop; 1e-9 is a wide margin, a drifting trim is 1e-3.
    np.testing.assert_allclose(run.final_omega_rad_s, run.initial_omega_rad_s, rtol=1e-9)
    assert run.max_position_error_m < 1e-3


def test_disturbed_awkward_vehicle_settles():
    run = simulate_hover(tilted_hex(), HoverConfig(duration_s=6.0))
    assert run.status is ExitStatus.PASSED
    assert 0.5 < run.settle_time_s < 5.0
    # The start offset is 0.5 m and the controller only shrinks it; 0.05 m allows the
    # overshoot of the tilted start (a controller design figure, not rounding).
    assert run.max_position_error_m == pytest.approx(0.5, abs=0.05)


def test_too_short_a_run_is_not_settled():
    run = simulate_hover(symmetric_multirotor(4), HoverConfig(duration_s=1.5))
    assert run.status is ExitStatus.NOT_SETTLED


def test_marginal_thrust_climb_ends_saturated():
    base = symmetric_multirotor(4)
    # Thrust-to-weight 1.03: holding is possible, climbing 1.5 m is not within 6 s.
    omega_max = math.sqrt(base.weight_N * 1.03 / (4 * base.motor_constant[0]))
    params = base.with_changes(omega_max_rad_s=omega_max)
    run = simulate_hover(params, HoverConfig(duration_s=6.0, offset_m=(0.0, 0.0, -1.5),
                                             roll_rad=0.0))
    assert run.status is ExitStatus.SATURATED
    assert run.longest_saturation_s >= 1.0


def test_three_times_heavier_than_modelled_crashes():
    params = symmetric_multirotor(4)
    plant = Plant.from_params(params)
    plant.mass_kg = plant.mass_kg * 3.0
    out = simulate_batch(params, HoverConfig(duration_s=3.0), plant)
    assert out.status(0) is ExitStatus.CRASHED


def test_a_rotor_spinning_the_other_way_than_modelled_spins_the_vehicle():
    params = symmetric_multirotor(4)
    plant = Plant.from_params(params)
    flipped = params.with_changes(turning_sign=params.turning_sign * [-1, 1, 1, 1])
    plant.torque_map = flipped.allocation()[1:4].copy()
    out = simulate_batch(params, HoverConfig(duration_s=6.0), plant)
    assert out.status(0) is ExitStatus.YAW_SPIN


def test_non_finite_state_is_divergence():
    params = symmetric_multirotor(4)
    plant = Plant.from_params(params)
    plant.mass_kg = np.array([np.nan])
    out = simulate_batch(params, HoverConfig(duration_s=2.0), plant)
    assert out.status(0) is ExitStatus.DIVERGED


# ------------------------------------------------------------------ robustness batch

def test_batch_without_spread_reproduces_the_single_vehicle():
    params = symmetric_multirotor(4)
    config = HoverConfig(duration_s=2.5)
    plant = perturbed_plant(params, sample_perturbations(5, 4, Spreads(0, 0, 0, 0), seed=1))
    out = simulate_batch(params, config, plant)
    run = simulate_hover(params, config, record=False)
    for i in range(5):
        assert out.status(i) is run.status
        # Batch of 5 against the plain-float engine: ENGINE_RTOL (see above).
        np.testing.assert_allclose(out.final_omega_rad_s[:, i], run.final_omega_rad_s,
                                   rtol=ENGINE_RTOL)


def ulp_sensitivity_m(params: VehicleParams, config: HoverConfig, alone) -> float:
    """How far the final position of the one-vehicle plant `alone` moves when its mass,
    motor constants or start offset change by 1 or 16 ulps: the flight's own noise floor.

    A batch of another width runs other SIMD kernels (numpy picks them per width and
    CPU): its matmuls sum in another order and its transcendentals may differ by their
    documented few ulps, so each step's numbers can differ by a few ulps. The flight
    turns such differences into what this measures. It is a floor, not a linear gain:
    a vehicle that enters and leaves saturation switches from the pseudo-inverse
    allocation to the prioritised one, and a few ulps decide at which step it switches,
    so 1 and 16 ulps move it alike (here ~2e-12 m for vehicle 0, ~1e-13 m for the
    always-saturated vehicle 2, whose response is linear)."""
    reference = fly_alone(params, config, perturbed_plant(params, alone)).final_state.p
    eps = np.finfo(float).eps
    worst = 0.0
    for k in (1, -16):
        scale = 1.0 + k * eps
        changed = [
            (config, replace(alone, mass_scale=alone.mass_scale * scale)),
            (config, replace(alone, motor_scale=alone.motor_scale * scale)),
            (replace(config, offset_m=tuple(v * scale for v in config.offset_m)), alone),
        ]
        for c, plant_perturbation in changed:
            p = fly_alone(params, c, perturbed_plant(params, plant_perturbation)).final_state.p
            worst = max(worst, float(np.abs(p - reference).max()))
    return worst


def test_batch_columns_are_independent_vehicles():
    # Each vehicle of a perturbed batch flies as it would alone, up to the flight's own
    # sensitivity to ulp-level changes (ulp_sensitivity_m): bit-equality across batch
    # widths holds on one CPU and not on another. The bound is 4x the worst of the six
    # perturbed flights (margin for the sample maximum); a column mixing up another
    # vehicle's mass, inertia or motors (30 %, 10 % spreads here) moves it by millimetres.
    params = symmetric_multirotor(4)
    config = HoverConfig(duration_s=1.5)
    perturbation = sample_perturbations(3, 4, Spreads(0.3, 0.03, 0.3, 0.1), seed=3)
    together = simulate_batch(params, config, perturbed_plant(params, perturbation))
    for i in range(3):
        alone = type(perturbation)(
            perturbation.mass_scale[i:i + 1], perturbation.com_shift_m[:, i:i + 1],
            perturbation.inertia_scale[:, i:i + 1], perturbation.motor_scale[:, i:i + 1])
        single = fly_alone(params, config, perturbed_plant(params, alone))
        assert single.status(0) is together.status(i)
        bound_m = 4.0 * ulp_sensitivity_m(params, config, alone)
        assert 0.0 < bound_m < 1e-9     # the floor is ulps amplified, not a broken flight
        np.testing.assert_allclose(single.final_state.p[:, 0], together.final_state.p[:, i],
                                   rtol=0.0, atol=bound_m)


def test_robustness_batch_reports_pass_rate_and_worst_cases_reproducibly():
    params = symmetric_multirotor(4)
    config = HoverConfig(duration_s=2.5)
    first = robustness_batch(params, 24, config, Spreads(mass_rel=0.2), seed=11, n_worst=3)
    again = robustness_batch(params, 24, config, Spreads(mass_rel=0.2), seed=11, n_worst=3)
    assert first.to_dict() == again.to_dict()
    assert sum(first.counts.values()) == 24
    assert first.passed == first.counts.get("passed", 0)
    assert len(first.worst) == 3
    masses = [w["mass_kg"] for w in first.worst]
    assert all(0.8 * 1.5 - 1e-9 <= m <= 1.2 * 1.5 + 1e-9 for m in masses)


def test_heavy_spread_makes_some_vehicles_fail():
    params = symmetric_multirotor(4)   # thrust-to-weight 1.63
    report = robustness_batch(params, 16, HoverConfig(duration_s=4.0),
                              Spreads(mass_rel=0.6, com_m=0.0, inertia_rel=0.0,
                                      motor_constant_rel=0.0), seed=2)
    assert 0 < report.passed < 16
    failing = [w for w in report.worst if w["status"] != "passed"]
    # The nominal controller flies a vehicle 20% off its mass fine; the failures are
    # the far-off ones.
    assert failing and all(abs(w["mass_kg"] / 1.5 - 1.0) > 0.2 for w in failing)


def test_gains_follow_the_vehicles_accelerations_not_its_size():
    # Mass, inertia and motor constants ten times larger: the same accelerations, the
    # same gains per unit mass and inertia.
    base = symmetric_multirotor(4, mass_kg=0.5)
    big = base.with_changes(mass_kg=5.0, inertia_kg_m2=10 * base.inertia_kg_m2,
                            motor_constant=10 * base.motor_constant)
    small, large = ControllerGains.from_params(base), ControllerGains.from_params(big)
    assert large.kp_1_s2 == pytest.approx(small.kp_1_s2, rel=1e-12)
    assert large.kR_1_s2 == pytest.approx(small.kR_1_s2, rel=1e-12)
    assert large.mass_kg == pytest.approx(10 * small.mass_kg, rel=1e-15)


def test_attitude_bandwidth_is_capped_by_the_torque_authority():
    # Twenty times the inertia of the 1.5 kg quad: 12 rad/s would ask J * 144 * 0.2 rad,
    # beyond the rotors. By hand for an 'x' quad (arm a, lever a / sqrt 2 on both axes):
    # a pure roll torque moves the four thrusts by +-d, so it reaches
    # 4 (a / sqrt 2) (T_max - T_hover) before the two rising rotors saturate
    # (T_hover > T_max / 2 here, so they meet their top before the others meet 0).
    base = symmetric_multirotor(4)
    heavy = base.with_changes(inertia_kg_m2=20 * base.inertia_kg_m2)
    T_max = base.motor_constant[0] * 838.0 ** 2
    T_hover = base.weight_N / 4
    assert T_hover > T_max / 2
    torque_N_m = 4 * (0.2 / math.sqrt(2)) * (T_max - T_hover)
    alpha = torque_N_m / (20 * 0.03)
    gains = ControllerGains.from_params(heavy)
    assert gains.limited_by == "torque authority"
    assert gains.angular_authority_rad_s2 == pytest.approx(alpha, rel=1e-12)
    # the design start tilt (0.2 rad) asks exactly that acceleration: kR * 0.2 = alpha
    assert gains.kR_1_s2 == pytest.approx(alpha / 0.2, rel=1e-12)
    assert gains.position_bandwidth_rad_s == pytest.approx(
        gains.attitude_bandwidth_rad_s / 6, rel=1e-15)
    # the 1.5 kg quad itself keeps the 12 rad/s of the fixed design
    assert ControllerGains.from_params(base).attitude_bandwidth_rad_s == 12.0


def test_initial_attitude_is_the_urdf_rpy_convention():
    from reedtool.frames import rpy_to_matrix

    q = quat_from_rpy(0.3, -0.2, 1.1)
    R = rot_matrices(q.reshape(4, 1))[:, :, 0]
    # Quaternion products vs Euler products of unit entries: a few ulps (~1e-15).
    np.testing.assert_allclose(R, rpy_to_matrix((0.3, -0.2, 1.1)), atol=1e-12)


def test_one_by_one_is_the_column_batch_exactly():
    """A small numpy batch flown one vehicle at a time on the traced float step
    (batch.simulate_one_by_one, what robustness_batch picks for a few vehicles) is the
    column batch: both steps and judges equal equations.py run by the interpreter, bit for
    bit (test_equations), so whole flights are equal, endings, parked states and the
    recorded position errors included."""
    from reedtool.sim.batch import simulate_one_by_one
    from reedtool.sim.controller import ControllerDesign

    params = symmetric_multirotor(4)   # thrust-to-weight 1.63: the heavy ones fail
    config = HoverConfig(duration_s=4.0)
    plant = perturbed_plant(params, sample_perturbations(
        12, 4, Spreads(mass_rel=0.6, com_m=0.02, inertia_rel=0.2, motor_constant_rel=0.1),
        seed=2))
    columns = simulate_batch(params, config, plant, record=True)
    single = simulate_one_by_one(params, config, plant, ControllerDesign(), None, True)
    statuses = {columns.status(i) for i in range(12)}
    assert ExitStatus.PASSED in statuses and len(statuses) > 1
    for name in ("status_code", "reason", "reason_value", "end_time_s", "settle_time_s",
                 "max_position_error_m", "max_attitude_error_deg", "final_position_error_m",
                 "final_attitude_error_deg", "max_throttle", "longest_saturation_s",
                 "position_error_m"):
        np.testing.assert_array_equal(getattr(single, name), getattr(columns, name), name)
    # The final state of the vehicles that flew to the end (an ended vehicle's is its
    # parked state, which the columns fly on to the end: meaningless either way).
    flew = columns.end_time_s == config.duration_s
    assert 0 < flew.sum() < 12
    for name in ("p", "v", "q", "w", "omega"):
        np.testing.assert_array_equal(getattr(single.final_state, name)[:, flew],
                                      getattr(columns.final_state, name)[:, flew], name)
