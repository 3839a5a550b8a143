"""6-DoF rigid body with quaternion attitude, batched over vehicles (columns).

World frame: z up, gravity -z. Body frame: the base link's axes, origin at the COM.
State per vehicle: position p and velocity v (world), attitude quaternion q = (w, x, y, z)
(body -> world, Hamilton), body rates w (body), rotor speeds omega (n rotors).

Integration is semi-implicit (symplectic) Euler at a fixed step: velocities from the
forces at the start of the step, then positions and attitude from the new velocities,
the attitude through the exact exponential map (the quaternion stays a rotation).
Why not RK4: the controller runs at the same rate and holds its command over the step,
so the force is piecewise constant by construction and RK4's extra accuracy buys little;
semi-implicit Euler is stable for the body's modes at kHz rates (omega*dt ~ 0.02), costs
one force evaluation per step (4x less than RK4, which is what lets 1000 vehicles run in
one array step at millions of vehicle-steps per second) and its fixed point is exactly the
continuous equilibrium, so the steady hover speed equals the trim.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .motor import drag_matrices
from .params import VehicleParams


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


def rot_from_quat(qw, qx, qy, qz) -> tuple:
    """The 9 entries R00, R01, ..., R22 of the rotation of a unit quaternion.

    Plain arithmetic, so it serves floats and (N,) arrays alike.
    """
    xx, yy, zz = qx * qx, qy * qy, qz * qz
    xy, xz, yz = qx * qy, qx * qz, qy * qz
    wx, wy, wz = qw * qx, qw * qy, qw * qz
    return (1.0 - 2.0 * (yy + zz), 2.0 * (xy - wz), 2.0 * (xz + wy),
            2.0 * (xy + wz), 1.0 - 2.0 * (xx + zz), 2.0 * (yz - wx),
            2.0 * (xz - wy), 2.0 * (yz + wx), 1.0 - 2.0 * (xx + yy))


# R's entries are linear in the quaternion's products [ww wx wy wz xx xy xz yy yz zz] and
# 1 (the same formulas as rot_from_quat): one (9, 11) matrix product turns the products of
# N quaternions into their N rotation matrices.
_ROT_FROM_PRODUCTS = np.array([
    #  ww  wx  wy  wz  xx  xy  xz  yy  yz  zz   1
    [0, 0, 0, 0, 0, 0, 0, -2, 0, -2, 1],    # R00
    [0, 0, 0, -2, 0, 2, 0, 0, 0, 0, 0],     # R01
    [0, 0, 2, 0, 0, 0, 2, 0, 0, 0, 0],      # R02
    [0, 0, 0, 2, 0, 2, 0, 0, 0, 0, 0],      # R10
    [0, 0, 0, 0, -2, 0, 0, 0, 0, -2, 1],    # R11
    [0, -2, 0, 0, 0, 0, 0, 0, 2, 0, 0],     # R12
    [0, 0, -2, 0, 0, 0, 2, 0, 0, 0, 0],     # R20
    [0, 2, 0, 0, 0, 0, 0, 0, 2, 0, 0],      # R21
    [0, 0, 0, 0, -2, 0, 0, -2, 0, 0, 1],    # R22
], dtype=float)


def rot_matrices(q: np.ndarray, products: np.ndarray | None = None) -> np.ndarray:
    """(3, 3, N) rotation matrices of (4, N) unit quaternions.

    `products` is an optional (11, N) scratch array (last row all ones) to reuse.
    """
    N = q.shape[1]
    if products is None:
        products = np.empty((11, N))
        products[10] = 1.0
    mul = np.multiply
    qw, qx, qy, qz = q[0], q[1], q[2], q[3]
    mul(qw, qw, out=products[0])
    mul(qw, qx, out=products[1])
    mul(qw, qy, out=products[2])
    mul(qw, qz, out=products[3])
    mul(qx, qx, out=products[4])
    mul(qx, qy, out=products[5])
    mul(qx, qz, out=products[6])
    mul(qy, qy, out=products[7])
    mul(qy, qz, out=products[8])
    mul(qz, qz, out=products[9])
    return (_ROT_FROM_PRODUCTS @ products).reshape(3, 3, N)


def _sub_cross(out: np.ndarray, a: np.ndarray, b: np.ndarray, tmp: np.ndarray) -> None:
    """out -= a x b for (3, N) arrays, row by row through the (N,) scratch `tmp`."""
    mul = np.multiply
    for k, i, j in ((0, 1, 2), (1, 2, 0), (2, 0, 1)):
        out[k] -= mul(a[i], b[j], out=tmp)
        out[k] += mul(a[j], b[i], out=tmp)


def integrate_quat(q: np.ndarray, w: np.ndarray, dt_s: float) -> np.ndarray:
    """q * exp(w dt / 2), renormalised. q (4, N), w (3, N) body rates.

    exp(w dt / 2) = (cos h, sin h w / |w|) with h = |w| dt / 2. The result is renormalised,
    so any positive multiple of it will do: (|w| / tan h, w) needs one tangent instead
    of a cosine and a sine (numpy vectorises tan but not cos and sin). Where w = 0 (or h
    underflows) the step is the identity, (1, 0).
    """
    mul = np.multiply
    N = q.shape[1]
    work = np.empty((4, N))
    rate, tan_h, tmp, a = work[0], work[1], work[2], work[3]
    wx, wy, wz = w[0], w[1], w[2]
    qw, qx, qy, qz = q[0], q[1], q[2], q[3]
    sq = w * w
    np.add(sq[0], sq[1], out=rate)
    rate += sq[2]
    np.sqrt(rate, out=rate)
    mul(rate, 0.5 * dt_s, out=tan_h)
    np.tan(tan_h, out=tan_h)
    a.fill(1.0)
    np.divide(rate, tan_h, out=a, where=tan_h != 0.0)
    out = np.empty_like(q)
    # q * (a, w), the Hamilton product, row by row: +-(q component * p component)
    for o, first, rest in ((out[0], (qw, a), ((-1, qx, wx), (-1, qy, wy), (-1, qz, wz))),
                           (out[1], (qx, a), ((1, qw, wx), (1, qy, wz), (-1, qz, wy))),
                           (out[2], (qy, a), ((1, qw, wy), (1, qz, wx), (-1, qx, wz))),
                           (out[3], (qz, a), ((1, qw, wz), (1, qx, wy), (-1, qy, wx)))):
        mul(*first, out=o)
        for sign, qi, pi in rest:
            if sign > 0:
                o += mul(qi, pi, out=tmp)
            else:
                o -= mul(qi, pi, out=tmp)
    sq = out * out
    np.add(sq[0], sq[1], out=rate)
    rate += sq[2]
    rate += sq[3]
    np.sqrt(rate, out=rate)
    np.divide(1.0, rate, out=rate)
    for o in out:
        o *= rate
    return out


# ----------------------------------------------------------------- the plant

@dataclass
class Plant:
    """The vehicles being flown: nominal geometry shared, mass properties per vehicle.

    Perturbed vehicles differ from the nominal in mass, inertia (J = S J0 S with
    S = diag(inertia_scale_sqrt), which keeps it positive definite), COM (a shift of the
    true COM from the nominal one, body axes) and motor constants. Rotor positions stay
    relative to the nominal COM so the per-rotor maps are shared matrices and the COM
    shift enters as cross products.
    """

    mass_kg: np.ndarray              # (N,)
    inertia_kg_m2: np.ndarray        # (3, 3) nominal J0, about the COM
    inertia_inv_kg_m2: np.ndarray    # (3, 3) J0^-1
    inertia_scale_sqrt: np.ndarray   # (3, N) diagonal of S
    com_shift_m: np.ndarray          # (3, N) true COM minus nominal COM
    motor_constant: np.ndarray       # (n, N)
    force_map: np.ndarray            # (3, n) thrust -> body force
    torque_map: np.ndarray           # (3, n) thrust -> torque about the nominal COM
    drag_map: np.ndarray             # (54, n) rotor speed -> entries of the (9, 6) drag matrix
    has_drag: bool
    g_m_s2: float

    @property
    def n_vehicles(self) -> int:
        return len(self.mass_kg)

    @classmethod
    def from_params(cls, params: VehicleParams, n_vehicles: int = 1) -> "Plant":
        N, n = n_vehicles, params.n_rotors
        K = drag_matrices(params.rotor_position_m, params.rotor_axis,
                          params.rotor_drag_coefficient, params.rolling_moment_coefficient)
        return cls(
            mass_kg=np.full(N, params.mass_kg),
            inertia_kg_m2=params.inertia_kg_m2.copy(),
            inertia_inv_kg_m2=np.linalg.inv(params.inertia_kg_m2),
            inertia_scale_sqrt=np.ones((3, N)),
            com_shift_m=np.zeros((3, N)),
            motor_constant=np.repeat(params.motor_constant[:, None], N, axis=1),
            force_map=params.rotor_axis.T.copy(),
            torque_map=params.allocation()[1:4].copy(),
            drag_map=K.reshape(54, n),
            has_drag=bool(np.any(K != 0.0)),
            g_m_s2=params.g_m_s2,
        )


@dataclass
class State:
    p: np.ndarray       # (3, N) world position of the COM [m]
    v: np.ndarray       # (3, N) world velocity [m/s]
    q: np.ndarray       # (4, N) attitude (w, x, y, z), body -> world
    w: np.ndarray       # (3, N) body rates [rad/s]
    omega: np.ndarray   # (n, N) rotor speeds [rad/s]


class PlantKernel:
    """What body_wrench and step_rigid_body would otherwise re-derive every step.

    Built from a Plant once per run (after any change to the plant's arrays): the wrench
    map and per-vehicle factors, as full (k, N) arrays because numpy broadcasting a (k, 1)
    operand costs more than the arithmetic at these sizes.

    Rotor thrust, yaw drag, rotor drag and rolling moment are all linear in the rows
    [k_i w_i^2; w_i * xi_j] (xi the body twist at the nominal COM), so one matrix product
    gives force and torque for every vehicle. Twist components that no rotor's drag
    depends on (e.g. the velocity along the rotor axes) are left out.
    """

    def __init__(self, plant: Plant):
        N, n = plant.n_vehicles, plant.motor_constant.shape[0]
        K = plant.drag_map.reshape(9, 6, n)
        drag = K[0:6] + np.concatenate([np.zeros((3, 6, n)), K[6:9]])  # rolling: a torque
        used = np.flatnonzero(np.any(drag != 0.0, axis=(0, 2))) if plant.has_drag else []
        self.twist_used = [int(j) for j in used]
        wrench_map = np.hstack([np.vstack([plant.force_map, plant.torque_map]),
                                drag[:, self.twist_used, :].reshape(6, -1)])
        # Rows F0 F1 F2 F0 F1 T0 T1 T2: the force comes out "wrapped" (rows 1:4 and 2:5
        # are its components rotated by one and two), so shift x F is two products of
        # (3, N) blocks instead of six of rows.
        self.wrench_map = wrench_map[[0, 1, 2, 0, 1, 3, 4, 5]]
        self.rows = np.empty((wrench_map.shape[1], N))
        self.n_rotors = n
        self.has_shift = bool(np.any(plant.com_shift_m != 0.0))
        self.shift5 = plant.com_shift_m[[0, 1, 2, 0, 1]]
        self.w5 = np.empty((5, N))         # scratch: w wrapped
        self.unit_scale = bool(np.all(plant.inertia_scale_sqrt == 1.0))
        self.inv_scale = 1.0 / plant.inertia_scale_sqrt
        J0 = plant.inertia_kg_m2
        # A diagonal J0 stays diagonal as S J0 S: then w x J w = ((J2 - J1) w1 w2, ...) and
        # J^-1 is a division, per vehicle.
        self.diagonal = bool(np.all(J0 == np.diag(np.diag(J0))))
        if self.diagonal:
            J = np.diag(J0)[:, None] * plant.inertia_scale_sqrt ** 2       # (3, N)
            self.inertia_diag = J
            self.gyro = np.array([J[2] - J[1], J[0] - J[2], J[1] - J[0]])
        self.tmp = np.empty(N)             # scratch row
        self._dt_s = None

    def scaled(self, plant: Plant, dt_s: float) -> tuple[np.ndarray, np.ndarray | None]:
        """(3, N) dt / m and dt / S for this step size, computed once per run."""
        if self._dt_s != dt_s:
            self._dt_s = dt_s
            N = plant.n_vehicles
            self._dt_over_mass = np.broadcast_to(dt_s / plant.mass_kg, (3, N)).copy()
            self._dt_over_scale = (dt_s / self.inertia_diag if self.diagonal
                                   else None if self.unit_scale
                                   else dt_s / plant.inertia_scale_sqrt)
        return self._dt_over_mass, self._dt_over_scale


def body_wrench(plant: Plant, state: State, R: np.ndarray,
                kernel: PlantKernel | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Force and torque about the true COM, body axes: thrust, yaw drag, rotor drag."""
    kernel = kernel or PlantKernel(plant)
    n, rows, omega, tmp = kernel.n_rotors, kernel.rows, state.omega, kernel.tmp
    np.multiply(omega, omega, out=rows[:n])
    rows[:n] *= plant.motor_constant
    if kernel.twist_used:
        w, shift = state.w, plant.com_shift_m
        # velocity of the body point at the nominal COM (which rotor positions are taken
        # from), body axes: R^T v - w x shift
        v_o = np.einsum("jin,jn->in", R, state.v) if kernel.twist_used[0] < 3 else None
        for block, j in enumerate(kernel.twist_used, start=1):
            if j < 3:
                xi = v_o[j]
                if kernel.has_shift:
                    a, b = (j + 1) % 3, (j + 2) % 3
                    xi -= np.multiply(w[a], shift[b], out=tmp)
                    xi += np.multiply(w[b], shift[a], out=tmp)
            else:
                xi = w[j - 3]
            np.multiply(omega, xi, out=rows[n * block:n * (block + 1)])
    wrench = kernel.wrench_map @ rows
    force, torque = wrench[0:3], wrench[5:8]
    if kernel.has_shift:
        # Moments were taken about the nominal COM; about the true one: tau - shift x F,
        # (s x F)_k = s_{k+1} F_{k+2} - s_{k+2} F_{k+1} on the wrapped rows.
        s5, F5 = kernel.shift5, wrench[0:5]
        torque -= s5[1:4] * F5[2:5]
        torque += s5[2:5] * F5[1:4]
    return force, torque


def step_rigid_body(plant: Plant, state: State, R: np.ndarray, force_b: np.ndarray,
                    torque_b: np.ndarray, dt_s: float, kernel: PlantKernel | None = None) -> None:
    """Advance p, v, q, w one semi-implicit Euler step, in place."""
    kernel = kernel or PlantKernel(plant)
    dt_over_mass, dt_over_scale = kernel.scaled(plant, dt_s)
    v, w, tmp = state.v, state.w, kernel.tmp
    v += np.einsum("ijn,jn->in", R, force_b * dt_over_mass)
    v[2] -= dt_s * plant.g_m_s2
    # Euler's equations, J w' = tau - w x J w, with J = S J0 S.
    rhs = torque_b.copy()
    if kernel.diagonal:
        # (w x J w)_k = (J_{k+2} - J_{k+1}) w_{k+1} w_{k+2}; dt_over_scale is dt / J here
        w5 = kernel.w5
        w5[0:3] = w
        w5[3:5] = w[0:2]
        gyro = w5[1:4] * w5[2:5]
        gyro *= kernel.gyro
        rhs -= gyro
        rhs *= dt_over_scale
        w += rhs
    elif kernel.unit_scale:
        _sub_cross(rhs, w, plant.inertia_kg_m2 @ w, tmp)
        rhs *= dt_s
        w += plant.inertia_inv_kg_m2 @ rhs
    else:
        S = plant.inertia_scale_sqrt
        Jw = plant.inertia_kg_m2 @ (S * w)
        Jw *= S
        _sub_cross(rhs, w, Jw, tmp)
        rhs *= kernel.inv_scale
        dw = plant.inertia_inv_kg_m2 @ rhs
        dw *= dt_over_scale
        w += dw
    state.p += v * dt_s
    state.q = integrate_quat(state.q, w, dt_s)
