"""The vehicles a hover simulation flies: the plant's numbers, the state, and the rigid body
step over columns of vehicles, from the flight equations (`equations`).

World frame: z up, gravity -z. Body frame: the base link's axes, origin at the COM.
State per vehicle: position p and velocity v (world), attitude quaternion q = (w, x, y, z)
(body -> world, Hamilton), body rates w (body), rotor speeds omega (n rotors).

Integration is semi-implicit (symplectic) Euler at a fixed step: velocities from the
forces at the start of the step, then positions and attitude from the new velocities,
the attitude through the exact exponential map (the quaternion stays a rotation).
Why not RK4: the controller runs at the same rate and holds its command over the step,
so the force is piecewise constant by construction and RK4's extra accuracy buys little;
semi-implicit Euler is stable for the body's modes at kHz rates (omega*dt ~ 0.02), costs
one force evaluation per step (4x less than RK4, which is what lets thousands of vehicles
fly at tens of millions of vehicle-steps per second) and its fixed point is exactly the
continuous equilibrium, so the steady hover speed equals the trim.

`rot_matrices`, `body_wrench` and `step_rigid_body` apply equations' functions to each
vehicle (tests and oracles drive the plant with them); the engines fly the same
functions compiled (`compiled`) or traced (`scalar`, `columns`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from reedtool.sim import equations
from reedtool.sim.params import VehicleParams

# ----------------------------------------------------------------- rotations

def quat_from_rpy(roll: float, pitch: float, yaw: float) -> np.ndarray:
    """(w, x, y, z) of R = Rz(yaw) Ry(pitch) Rx(roll), the URDF rpy convention."""
    cr, sr = math.cos(roll / 2), math.sin(roll / 2)
    cp, sp = math.cos(pitch / 2), math.sin(pitch / 2)
    cy, sy = math.cos(yaw / 2), math.sin(yaw / 2)
    return np.array([cy * cp * cr + sy * sp * sr,
                     cy * cp * sr - sy * sp * cr,
                     cy * sp * cr + sy * cp * sr,
                     sy * cp * cr - cy * sp * sr])


def rot_matrices(q: np.ndarray) -> np.ndarray:
    """(3, 3, N) rotation matrices of (4, N) unit quaternions (equations.rotation: plain
    arithmetic, so it takes the rows of N vehicles at once)."""
    q = np.asarray(q, dtype=float)
    return np.array(equations.rotation(q[0], q[1], q[2], q[3])).reshape(3, 3, q.shape[1])


# ----------------------------------------------------------------- the plant

@dataclass
class Plant:
    """The vehicles being flown: nominal geometry shared, mass properties per vehicle.

    Perturbed vehicles differ from the nominal in mass, inertia (J = S J0 S with
    S = diag(inertia_scale_sqrt), which keeps it positive definite), COM (a shift of the
    true COM from the nominal one, body axes) and motor constants. Rotor positions stay
    relative to the nominal COM so the per-rotor maps are shared and the COM shift enters
    as cross products (equations.body_wrench).
    """

    mass_kg: np.ndarray              # (N,)
    inertia_kg_m2: np.ndarray        # (3, 3) nominal J0, about the COM
    inertia_scale_sqrt: np.ndarray   # (3, N) diagonal of S
    com_shift_m: np.ndarray          # (3, N) true COM minus nominal COM
    motor_constant: np.ndarray       # (n, N)
    force_map: np.ndarray            # (3, n) thrust -> body force (the rotor axes)
    torque_map: np.ndarray           # (3, n) thrust -> torque about the nominal COM
    rotor_position_m: np.ndarray     # (n, 3) about the nominal COM
    rotor_drag_coefficient: np.ndarray      # (n,)
    rolling_moment_coefficient: np.ndarray  # (n,)
    g_m_s2: float

    @property
    def n_vehicles(self) -> int:
        return len(self.mass_kg)

    @classmethod
    def from_params(cls, params: VehicleParams, n_vehicles: int = 1) -> "Plant":
        N = n_vehicles
        return cls(
            mass_kg=np.full(N, params.mass_kg),
            inertia_kg_m2=params.inertia_kg_m2.copy(),
            inertia_scale_sqrt=np.ones((3, N)),
            com_shift_m=np.zeros((3, N)),
            motor_constant=np.repeat(params.motor_constant[:, None], N, axis=1),
            force_map=params.rotor_axis.T.copy(),
            torque_map=params.allocation()[1:4].copy(),
            rotor_position_m=params.rotor_position_m.copy(),
            rotor_drag_coefficient=params.rotor_drag_coefficient.copy(),
            rolling_moment_coefficient=params.rolling_moment_coefficient.copy(),
            g_m_s2=params.g_m_s2,
        )


@dataclass
class State:
    p: np.ndarray       # (3, N) world position of the COM [m]
    v: np.ndarray       # (3, N) world velocity [m/s]
    q: np.ndarray       # (4, N) attitude (w, x, y, z), body -> world
    w: np.ndarray       # (3, N) body rates [rad/s]
    omega: np.ndarray   # (n, N) rotor speeds [rad/s]


def _flat(x) -> np.ndarray:
    return np.ascontiguousarray(np.asarray(x, dtype=float).ravel())


def body_wrench(plant: Plant, state: "State", R: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Force and torque about each vehicle's true COM, body axes (3, N) each:
    equations.body_wrench, vehicle by vehicle (thrust, yaw drag, rotor drag, rolling
    moment). R (3, 3, N): the vehicles' rotations."""
    N = plant.n_vehicles
    pos, axis, tmap = (_flat(plant.rotor_position_m), _flat(np.asarray(plant.force_map).T),
                       _flat(np.asarray(plant.torque_map).T))
    cd, cr = _flat(plant.rotor_drag_coefficient), _flat(plant.rolling_moment_coefficient)
    R9 = np.asarray(R, dtype=float).reshape(9, N)
    out = np.empty((6, N))
    for j in range(N):
        out[:, j] = equations.body_wrench(
            pos, axis, tmap, cd, cr, _flat(plant.motor_constant[:, j]),
            _flat(plant.com_shift_m[:, j]), _flat(state.omega[:, j]), *R9[:, j],
            *state.v[:, j], *state.w[:, j])
    return out[0:3], out[3:6]


def step_rigid_body(plant: Plant, state: "State", R: np.ndarray, force_b: np.ndarray,
                    torque_b: np.ndarray, dt_s: float) -> None:
    """Advance p, v, q, w one semi-implicit Euler step, in place: equations.rigid_body,
    vehicle by vehicle, under the body force and torque (3, N)."""
    N = plant.n_vehicles
    J0 = _flat(plant.inertia_kg_m2)
    dt_J0inv = _flat(dt_s * np.linalg.inv(plant.inertia_kg_m2))
    R9 = np.asarray(R, dtype=float).reshape(9, N)
    for j in range(N):
        new = equations.rigid_body(
            dt_s, plant.g_m_s2, float(plant.mass_kg[j]), J0, dt_J0inv,
            _flat(plant.inertia_scale_sqrt[:, j]), R9[:, j], *force_b[:, j], *torque_b[:, j],
            *state.p[:, j], *state.v[:, j], *state.q[:, j], *state.w[:, j])
        state.p[:, j], state.v[:, j] = new[0:3], new[3:6]
        state.q[:, j], state.w[:, j] = new[6:10], new[10:13]
