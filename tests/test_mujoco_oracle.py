"""The simulator's rigid body against MuJoCo, an engine nobody here wrote.

The same vehicle (mass, full inertia tensor, COM away from the body origin, tilted rotor
axes) is built as an MJCF body on a free joint; each rotor is a site whose z axis is the
rotor axis and a motor on it whose 6-D gear is (0, 0, 1, 0, 0, -turning_sign * c_m): a
control u applies thrust u along the axis at the rotor and the yaw reaction -s c_m u
about it. Both engines then fly open-loop through the SAME rotor-speed history,
u_i = k_i omega_i(t)^2 held over each 1 ms control step: the speeds reedtool's closed-loop
hover produced (recorded every step), or trim speeds with one rotor dead from t = 0.
Rotor drag (velocity-dependent) is off: MuJoCo's motors cannot express it.

Tolerance, from the integrators' orders. reedtool integrates with semi-implicit Euler at
dt = 1 ms: first order, global error e(dt) = C dt + O(dt^2). MuJoCo runs RK4 at 0.05 ms
(fourth order: its error is ~1e-12 of reedtool's, checked below against RK4 at 0.1 ms).
So the exact trajectory x* satisfies x(dt) - x* ~ C dt, and Richardson's estimate of
reedtool's error is E = 2 |x(dt) - x(dt/2)| (x(dt/2): reedtool's own integrator at half
the step, the rotor speeds held over two half steps). The test asserts
  |x_reedtool(dt) - x_mujoco| <= 1.5 E + 1e-9     (positions [m], attitude [rad])
and, as first order requires, that halving reedtool's step halves its distance to MuJoCo
(ratio within [1.6, 2.4]). A wrong inertia axis, lever arm, yaw-reaction sign or
quaternion convention is a difference that does not shrink with dt, and fails both.
"""

from __future__ import annotations

import numpy as np
import pytest

from reedtool.sim import HoverConfig
from reedtool.sim.dynamics import Plant, State, body_wrench, rot_matrices, step_rigid_body
from reedtool.sim.params import VehicleParams, symmetric_multirotor
from reedtool.sim.controller import ControllerDesign
from reedtool.sim.run import simulate_hover

mujoco = pytest.importorskip(
    "mujoco", reason="mujoco is not installed (pip install '.[test]'): no oracle to run")

DT = 1e-3
MJ_DT = 5e-5
FULLINERTIA = ((0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2))   # MJCF's order
COM_IN_BODY = np.array([0.012, -0.007, 0.03])     # body origin -> COM, body axes [m]


def vehicle() -> VehicleParams:
    """A hexarotor with slightly tilted rotors, a full inertia tensor and no rotor drag."""
    base = symmetric_multirotor(6, arm_m=0.3, mass_kg=2.0, rotor_drag_coefficient=0.0,
                                rolling_moment_coefficient=0.0)
    rng = np.random.default_rng(11)
    axes = np.array([[0.0, 0.0, 1.0]] * 6) + rng.normal(scale=0.05, size=(6, 3)) * [1, 1, 0]
    J = np.array([[0.05, 0.003, -0.002], [0.003, 0.058, 0.0015], [-0.002, 0.0015, 0.09]])
    return base.with_changes(rotor_axis=axes, inertia_kg_m2=J,
                             rotor_position_m=base.rotor_position_m + [0.0, 0.0, -0.03])


def num(x) -> str:
    """A float as MJCF reads it back exactly."""
    return f"{float(x):.17g}"


def mjcf(params: VehicleParams, mj_dt: float = MJ_DT) -> str:
    J = params.inertia_kg_m2
    sites, motors = [], []
    for i in range(params.n_rotors):
        r = params.rotor_position_m[i] + COM_IN_BODY          # rotor in the body frame
        a = params.rotor_axis[i]
        pos, zaxis = " ".join(map(num, r)), " ".join(map(num, a))
        sites.append(f'<site name="rotor{i}" pos="{pos}" zaxis="{zaxis}"/>')
        yaw = -params.turning_sign[i] * params.moment_constant[i]
        motors.append(f'<general site="rotor{i}" gear="0 0 1 0 0 {num(yaw)}" '
                      f'ctrllimited="false"/>')
    com = " ".join(map(num, COM_IN_BODY))
    inertia = " ".join(num(J[i, j]) for i, j in FULLINERTIA)
    return f"""<mujoco model="oracle">
  <option timestep="{num(mj_dt)}" integrator="RK4" gravity="0 0 {num(-params.g_m_s2)}"/>
  <worldbody>
    <body name="vehicle">
      <freejoint/>
      <inertial pos="{com}" mass="{num(params.mass_kg)}" fullinertia="{inertia}"/>
      {''.join(sites)}
    </body>
  </worldbody>
  <actuator>{''.join(motors)}</actuator>
</mujoco>"""


def fly_mujoco(params, p0, q0, omega_history, mj_dt=MJ_DT):
    """COM positions and attitude quaternions at the start of every control step."""
    model = mujoco.MjModel.from_xml_string(mjcf(params, mj_dt))
    data = mujoco.MjData(model)
    body = model.body("vehicle").id
    R0 = rot_matrices(np.asarray(q0, dtype=float).reshape(4, 1))[:, :, 0]
    data.qpos[0:3] = p0 - R0 @ COM_IN_BODY                 # free joint: the body origin
    data.qpos[3:7] = q0
    mujoco.mj_forward(model, data)
    substeps = int(round(DT / mj_dt))
    p, q = [], []
    for omega in omega_history:
        p.append(data.xipos[body].copy())
        q.append(data.xquat[body].copy())
        data.ctrl[:] = params.motor_constant * omega ** 2
        for _ in range(substeps):
            mujoco.mj_step(model, data)
    return np.array(p), np.array(q)


def fly_reedtool(params, p0, q0, omega_history, split=1):
    """reedtool's rigid body and rotor forces (the engines' step) over the same history,
    each control step split into `split` integrator steps."""
    plant = Plant.from_params(params)
    state = State(p=np.array(p0, dtype=float).reshape(3, 1), v=np.zeros((3, 1)),
                  q=np.array(q0, dtype=float).reshape(4, 1), w=np.zeros((3, 1)),
                  omega=np.zeros((params.n_rotors, 1)))
    p, q = [], []
    for omega in omega_history:
        p.append(state.p[:, 0].copy())
        q.append(state.q[:, 0].copy())
        state.omega[:, 0] = omega
        for _ in range(split):
            R = rot_matrices(state.q)
            force, torque = body_wrench(plant, state, R)
            step_rigid_body(plant, state, R, force, torque, DT / split)
    return np.array(p), np.array(q)


def attitude_distance(qa, qb):
    """Rotation angle between attitudes, per sample [rad]."""
    dots = np.abs(np.sum(qa * qb, axis=1)).clip(max=1.0)
    return 2.0 * np.arccos(dots)


def closed_loop_history(params, **start):
    """Rotor speeds of reedtool's closed-loop hover, every step, and where it started."""
    config = HoverConfig(duration_s=1.5, hold_s=0.5, sample_hz=1.0 / DT, **start)
    # The excitation: the fixed 12 rad/s attitude loop (not capped by this vehicle's
    # authority), which rolls it back well within the 1.5 s compared.
    run = simulate_hover(params, config, ControllerDesign(authority_cap=False))
    omega = np.column_stack([run.series[f"omega_{name}_rad_s"] for name in params.rotor_names])
    p = np.column_stack([run.series["x_m"], run.series["y_m"], run.series["z_m"]])
    from reedtool.sim.dynamics import quat_from_rpy

    q0 = quat_from_rpy(config.roll_rad, config.pitch_rad, config.yaw_rad)
    return omega[:-1], p, q0


def assert_agrees(params, p0, q0, omega_history):
    p_mj, q_mj = fly_mujoco(params, p0, q0, omega_history)
    p_1, q_1 = fly_reedtool(params, p0, q0, omega_history)
    p_2, q_2 = fly_reedtool(params, p0, q0, omega_history, split=2)
    pos_err = np.linalg.norm(p_1 - p_mj, axis=1)
    att_err = attitude_distance(q_1, q_mj)
    pos_bound = 1.5 * 2.0 * np.linalg.norm(p_1 - p_2, axis=1) + 1e-9
    att_bound = 1.5 * 2.0 * attitude_distance(q_1, q_2) + 1e-9
    assert np.all(pos_err <= pos_bound), (pos_err.max(), pos_bound[np.argmax(pos_err)])
    assert np.all(att_err <= att_bound), (att_err.max(), att_bound[np.argmax(att_err)])
    # first order: halving the step halves the distance to MuJoCo (where there is one)
    end_1 = np.linalg.norm(p_1[-1] - p_mj[-1])
    end_2 = np.linalg.norm(p_2[-1] - p_mj[-1])
    if end_1 > 1e-7:
        assert 1.6 <= end_1 / end_2 <= 2.4, (end_1, end_2)
    return p_1, q_1, pos_err, att_err


def test_hover_holds_in_both():
    params = vehicle()
    omega, p_closed, q0 = closed_loop_history(params, offset_m=(0.0, 0.0, 0.0), roll_rad=0.0)
    p, _, pos_err, att_err = assert_agrees(params, p_closed[0], q0, omega)
    # it did hover (the tilted rotors' trim leaves a few cm of transient)
    assert np.abs(p - p_closed[0]).max() < 0.05
    print(f"hover: max |reedtool - MuJoCo| {pos_err.max():.2e} m, {att_err.max():.2e} rad")


def test_roll_step_recovery():
    params = vehicle()
    omega, p_closed, q0 = closed_loop_history(params, roll_rad=0.3, offset_m=(0.0, 0.0, 0.0))
    p, q, pos_err, att_err = assert_agrees(params, p_closed[0], q0, omega)
    print(f"roll: max |reedtool - MuJoCo| {pos_err.max():.2e} m, {att_err.max():.2e} rad")
    # open loop through reedtool's own speeds retraces its closed-loop flight
    # Two engines (the closed loop's plain floats, the array step here) on the same
    # speeds: measured 4e-15 m apart; a 16-ulp change of every recorded speed moves the
    # open-loop path by 9e-14 m (no feedback: errors only accumulate); 1e-12 is 10x that.
    np.testing.assert_allclose(p, p_closed[:-1], atol=1e-12)
    assert attitude_distance(q[:1], q[-1:])[0] > 0.25           # it did roll back


def test_yaw_step_recovery():
    params = vehicle()
    omega, p_closed, q0 = closed_loop_history(params, yaw_rad=0.6, roll_rad=0.0,
                                              offset_m=(0.0, 0.0, 0.0))
    _, q, pos_err, att_err = assert_agrees(params, p_closed[0], q0, omega)
    print(f"yaw: max |reedtool - MuJoCo| {pos_err.max():.2e} m, {att_err.max():.2e} rad")
    assert attitude_distance(q[:1], q[-1:])[0] > 0.1            # it did yaw


def test_rotor_failure_from_the_start():
    params = vehicle()
    omega_trim, p_closed, q0 = closed_loop_history(params, offset_m=(0.0, 0.0, 0.0),
                                                   roll_rad=0.0)
    history = np.repeat(omega_trim[:1], 400, axis=0)           # 0.4 s open loop
    history[:, 0] = 0.0                                         # rotor 0 dead from t = 0
    _, q, pos_err, att_err = assert_agrees(params, p_closed[0], q0, history)
    print(f"failure: max |reedtool - MuJoCo| {pos_err.max():.2e} m, {att_err.max():.2e} rad")
    assert attitude_distance(q[:1], q[-1:])[0] > 0.5            # it tumbles


def test_mujoco_step_is_converged():
    """RK4 at 0.05 ms against RK4 at 0.1 ms: MuJoCo's own error is far below reedtool's."""
    params = vehicle()
    omega_trim, p_closed, q0 = closed_loop_history(params, offset_m=(0.0, 0.0, 0.0),
                                                   roll_rad=0.0)
    history = np.repeat(omega_trim[:1], 300, axis=0)
    history[:, 0] = 0.0
    p_a, q_a = fly_mujoco(params, p_closed[0], q0, history)
    p_b, q_b = fly_mujoco(params, p_closed[0], q0, history, mj_dt=1e-4)
    p_r, _ = fly_reedtool(params, p_closed[0], q0, history)
    mj_err = np.linalg.norm(p_a - p_b, axis=1).max()
    rt_err = np.linalg.norm(p_r - p_a, axis=1).max()
    assert mj_err < 1e-3 * rt_err
