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

import functools
import math
from dataclasses import dataclass
from typing import Callable

import numpy as np

from reedtool.sim.motor import drag_matrices
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
# The same columns as [ww xx yy zz | wx xy yz | wy xz | wz | 1]: four array calls make
# these products (q*q, q[0:3]*q[1:4], q[0:2]*q[2:4], qw*qz). Each R entry keeps the order
# of its non-zero terms, so the matrix product sums them as before.
_ROT_FROM_GROUPED_PRODUCTS = _ROT_FROM_PRODUCTS[:, [0, 4, 7, 9, 1, 5, 8, 2, 6, 3, 10]]


def rotation_kernel(q: np.ndarray, products: np.ndarray, R9: np.ndarray) -> Callable[[], None]:
    """`rotate()`: R9 (9, N), rows R00 R01 ... R22, <- the rotations of q (4, N).

    `products` is (11, N) scratch. The arrays are bound once: the engines call this every
    step, where building views would cost as much as the arithmetic.
    """
    mul, matmul = np.multiply, np.matmul
    products[10] = 1.0
    qw, qx, qy, qz = q
    if q.shape[1] == 1:
        # One vehicle: numpy hands the product to BLAS's matrix-vector routine, which
        # sums the terms in another order than the matrix-matrix one; the original column
        # order keeps a lone vehicle flying exactly as a column of a batch does.
        pairs = [(a, b, products[i]) for i, (a, b) in enumerate(
            [(qw, qw), (qw, qx), (qw, qy), (qw, qz), (qx, qx), (qx, qy), (qx, qz), (qy, qy),
             (qy, qz), (qz, qz)])]

        def rotate() -> None:
            for a, b, out in pairs:
                mul(a, b, out)
            matmul(_ROT_FROM_PRODUCTS, products, R9)

        return rotate

    q03, q13, q02, q24 = q[0:3], q[1:4], q[0:2], q[2:4]
    squares, p3, p2, p1 = products[0:4], products[4:7], products[7:9], products[9]

    def rotate() -> None:
        mul(q, q, squares)
        mul(q03, q13, p3)
        mul(q02, q24, p2)
        mul(qw, qz, p1)
        matmul(_ROT_FROM_GROUPED_PRODUCTS, products, R9)

    return rotate


def rot_matrices(q: np.ndarray, products: np.ndarray | None = None) -> np.ndarray:
    """(3, 3, N) rotation matrices of (4, N) unit quaternions.

    `products` is an optional (11, N) scratch array to reuse.
    """
    N = q.shape[1]
    R9 = np.empty((9, N))
    rotation_kernel(q, np.empty((11, N)) if products is None else products, R9)()
    return R9.reshape(3, 3, N)


QUATERNION_WORK_ROWS = 11


def quaternion_kernel(q: np.ndarray, w: np.ndarray, dt_s: float,
                      work: np.ndarray) -> Callable[[], None]:
    """`advance()`: q <- q * exp(w dt / 2), renormalised, in place. q (4, N), w (3, N).

    exp(w dt / 2) = (cos h, sin h w / |w|) with h = |w| dt / 2. The result is renormalised,
    so any positive multiple of it will do: (|w| / tan h, w) needs one tangent instead
    of a cosine and a sine (numpy vectorises tan but not cos and sin). Where w = 0 (or h
    underflows) the step is the identity, (1, 0). `work` is (QUATERNION_WORK_ROWS, N).
    """
    mul, add, sub, sqrt, div = np.multiply, np.add, np.subtract, np.sqrt, np.divide
    out, tmp, rate, tan_h, a = work[0:4], work[4:8], work[8], work[9], work[10]
    o0, o123 = out[0], out[1:4]
    t0, t1, t2, t3, t123, t3rows = tmp[0], tmp[1], tmp[2], tmp[3], tmp[1:4], tmp[0:3]
    qw, qx, qy, qz = q
    wx, wy, wz = w
    o = list(out)
    half_dt = 0.5 * dt_s

    def advance() -> None:
        mul(w, w, t3rows)
        add(t0, t1, rate)
        add(rate, t2, rate)
        sqrt(rate, rate)
        mul(rate, half_dt, tan_h)
        np.tan(tan_h, tan_h)
        if tan_h.all():
            div(rate, tan_h, a)
        else:
            a.fill(1.0)
            div(rate, tan_h, out=a, where=tan_h != 0.0)
        # q * (a, w), the Hamilton product: the four products of each term, then one
        # array call adds (or subtracts) them to the four components.
        mul(qw, a, o[0])
        mul(qx, a, o[1])
        mul(qy, a, o[2])
        mul(qz, a, o[3])
        mul(qx, wx, t0)
        mul(qw, wx, t1)
        mul(qw, wy, t2)
        mul(qw, wz, t3)
        sub(o0, t0, o0)
        add(o123, t123, o123)
        mul(qy, wy, t0)
        mul(qy, wz, t1)
        mul(qz, wx, t2)
        mul(qx, wy, t3)
        sub(o0, t0, o0)
        add(o123, t123, o123)
        mul(qz, wz, t0)
        mul(qz, wy, t1)
        mul(qx, wz, t2)
        mul(qy, wx, t3)
        sub(out, tmp, out)
        mul(out, out, tmp)
        add(t0, t1, rate)
        add(rate, t2, rate)
        add(rate, t3, rate)
        sqrt(rate, rate)
        div(1.0, rate, rate)
        mul(o[0], rate, qw)
        mul(o[1], rate, qx)
        mul(o[2], rate, qy)
        mul(o[3], rate, qz)

    return advance


def integrate_quat(q: np.ndarray, w: np.ndarray, dt_s: float) -> np.ndarray:
    """q * exp(w dt / 2), renormalised, as a new array. q (4, N), w (3, N) body rates."""
    out = np.array(q, dtype=float)
    quaternion_kernel(out, w, dt_s, np.empty((QUATERNION_WORK_ROWS, q.shape[1])))()
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
    """What the plant's step would otherwise re-derive every step.

    Built from a Plant once per run (after any change to the plant's arrays): the wrench
    map and per-vehicle factors, as full (k, N) arrays because numpy broadcasting a (k, 1)
    operand costs more than the arithmetic at these sizes.

    Rotor thrust, yaw drag, rotor drag and rolling moment are all linear in the rows
    [k_i w_i^2; w_i * xi_j] (xi the body twist at the nominal COM), so one matrix product
    gives force and torque for every vehicle. Twist components that no rotor's drag
    depends on (e.g. the velocity along the rotor axes) are left out.
    """

    def __init__(self, plant: Plant):
        n = plant.motor_constant.shape[0]
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
        self.n_rows = wrench_map.shape[1]
        self.n_rotors = n
        self.has_shift = bool(np.any(plant.com_shift_m != 0.0))
        s = plant.com_shift_m
        self.shift5 = s[[0, 1, 2, 0, 1]]
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


def rates_buffer(w: np.ndarray) -> np.ndarray:
    """(5, N) [w0 w1 w2 w0 w1]: body rates "wrapped", so that the cross products with w
    are products of (3, N) blocks. The kernels below take w as rows 0:3 of such a buffer
    and refresh rows 3:5 themselves before using them."""
    w5 = np.empty((5, w.shape[1]))
    w5[0:3] = w
    return w5


def body_wrench_kernel(plant: Plant, kernel: PlantKernel, omega: np.ndarray, v: np.ndarray,
                       w5: np.ndarray, R9: np.ndarray, wrench8: np.ndarray) -> Callable[[], None]:
    """`evaluate()`: force and torque about the true COM, body axes, into wrench8 (8, N)
    (force in rows 0:3, torque in rows 5:8): thrust, yaw drag, rotor drag, rolling moment.

    omega (n, N) rotor speeds, v (3, N) world velocity, w5 rates_buffer, R9 (9, N) rows of
    the body -> world rotations.
    """
    mul, add, sub, matmul = np.multiply, np.add, np.subtract, np.matmul
    N, n = v.shape[1], kernel.n_rotors
    rows = np.empty((kernel.n_rows, N))
    thrust_rows = rows[:n]
    motor_constant = np.array(plant.motor_constant, dtype=float)
    wrench_map = kernel.wrench_map
    ops: list[tuple] = []               # the twist part, unrolled once
    if kernel.twist_used:
        xi = np.zeros((3, N))           # velocity of the nominal COM, body axes
        tmp = np.empty((2, 3, N))
        linear = [j for j in kernel.twist_used if j < 3]
        if linear:
            # R^T v for the rows needed (einsum sums exactly as the per-vehicle loop would)
            lo, hi = min(linear), max(linear) + 1
            ops.append((functools.partial(np.einsum, "jin,jn->in", R9.reshape(3, 3, N)[:, lo:hi],
                                          v, out=xi[lo:hi]),))
        if linear and kernel.has_shift:
            # minus w x shift: xi_j -= w_a s_b, xi_j += w_b s_a with a, b = j + 1, j + 2
            # (mod 3), for the rows lo..hi at once
            s = plant.com_shift_m
            s_b = np.array([s[(j + 2) % 3] for j in range(lo, hi)])
            s_a = np.array([s[(j + 1) % 3] for j in range(lo, hi)])
            ops += [(np.copyto, w5[3:5], w5[0:2]),
                    (mul, w5[lo + 1:hi + 1], s_b, tmp[0, :hi - lo]),
                    (sub, xi[lo:hi], tmp[0, :hi - lo], xi[lo:hi]),
                    (mul, w5[lo + 2:hi + 2], s_a, tmp[1, :hi - lo]),
                    (add, xi[lo:hi], tmp[1, :hi - lo], xi[lo:hi])]
        for block, j in enumerate(kernel.twist_used, start=1):
            ops.append((mul, omega, xi[j] if j < 3 else w5[j - 3],
                        rows[n * block:n * (block + 1)]))
    if kernel.has_shift:
        # Moments were taken about the nominal COM; about the true one: tau - shift x F,
        # (s x F)_k = s_{k+1} F_{k+2} - s_{k+2} F_{k+1} on the wrapped rows.
        s5, F5, torque = kernel.shift5, wrench8[0:5], wrench8[5:8]
        cross = np.empty((3, N))
        shift_ops = [(mul, s5[1:4], F5[2:5], cross), (sub, torque, cross, torque),
                     (mul, s5[2:5], F5[1:4], cross), (add, torque, cross, torque)]
    else:
        shift_ops = []

    def evaluate() -> None:
        mul(omega, omega, thrust_rows)
        mul(thrust_rows, motor_constant, thrust_rows)
        for f, *args in ops:
            f(*args)
        matmul(wrench_map, rows, wrench8)
        for f, *args in shift_ops:
            f(*args)

    return evaluate


def rigid_body_kernel(plant: Plant, kernel: PlantKernel, p: np.ndarray, v: np.ndarray,
                      q: np.ndarray, w5: np.ndarray, R9: np.ndarray, wrench8: np.ndarray,
                      dt_s: float) -> Callable[[], None]:
    """`advance()`: p, v, q, w one semi-implicit Euler step, in place, under the body
    wrench in wrench8 (body_wrench_kernel's layout). w5 is a rates_buffer."""
    mul, add, sub, matmul = np.multiply, np.add, np.subtract, np.matmul
    N = v.shape[1]
    dt_over_mass, dt_over_scale = kernel.scaled(plant, dt_s)
    force, torque = wrench8[0:3], wrench8[5:8]
    w = w5[0:3]
    R = R9.reshape(3, 3, N)
    scratch = np.empty((4, 3, N))
    fm, dv, rhs, tmp = scratch
    einsum = np.einsum
    vz, dt_g = v[2], dt_s * plant.g_m_s2
    # Euler's equations, J w' = tau - w x J w, with J = S J0 S
    if kernel.diagonal:
        # (w x J w)_k = (J_{k+2} - J_{k+1}) w_{k+1} w_{k+2}; dt_over_scale is dt / J here
        rotation = [(np.copyto, w5[3:5], w5[0:2]), (mul, w5[1:4], w5[2:5], tmp),
                    (mul, tmp, kernel.gyro, tmp), (sub, torque, tmp, rhs),
                    (mul, rhs, dt_over_scale, rhs), (add, w, rhs, w)]
    else:
        J0, J0_inv = plant.inertia_kg_m2, plant.inertia_inv_kg_m2
        Jw5 = np.empty((5, N))
        Jw = Jw5[0:3]
        rotation = [(np.copyto, w5[3:5], w5[0:2])]
        if kernel.unit_scale:
            rotation.append((matmul, J0, w, Jw))
        else:
            S = plant.inertia_scale_sqrt
            rotation += [(mul, S, w, tmp), (matmul, J0, tmp, Jw), (mul, Jw, S, Jw)]
        rotation += [
            (np.copyto, Jw5[3:5], Jw5[0:2]),
            # rhs = tau - w x J w: (w x b)_k = w_{k+1} b_{k+2} - w_{k+2} b_{k+1}
            (mul, w5[1:4], Jw5[2:5], tmp), (sub, torque, tmp, rhs),
            (mul, w5[2:5], Jw5[1:4], tmp), (add, rhs, tmp, rhs)]
        if kernel.unit_scale:
            rotation += [(mul, rhs, dt_s, rhs), (matmul, J0_inv, rhs, tmp), (add, w, tmp, w)]
        else:
            rotation += [(mul, rhs, kernel.inv_scale, rhs), (matmul, J0_inv, rhs, tmp),
                         (mul, tmp, dt_over_scale, tmp), (add, w, tmp, w)]
    rotate_q = quaternion_kernel(q, w, dt_s, np.empty((QUATERNION_WORK_ROWS, N)))

    def advance() -> None:
        mul(force, dt_over_mass, fm)
        einsum("ijn,jn->in", R, fm, out=dv)
        add(v, dv, v)
        sub(vz, dt_g, vz)
        for f, *args in rotation:
            f(*args)
        mul(v, dt_s, tmp)
        add(p, tmp, p)
        rotate_q()

    return advance


def body_wrench(plant: Plant, state: State, R: np.ndarray,
                kernel: PlantKernel | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Force and torque about the true COM, body axes: thrust, yaw drag, rotor drag."""
    kernel = kernel or PlantKernel(plant)
    wrench8 = np.empty((8, plant.n_vehicles))
    body_wrench_kernel(plant, kernel, state.omega, state.v, rates_buffer(state.w),
                       np.ascontiguousarray(R).reshape(9, -1), wrench8)()
    return wrench8[0:3], wrench8[5:8]


def step_rigid_body(plant: Plant, state: State, R: np.ndarray, force_b: np.ndarray,
                    torque_b: np.ndarray, dt_s: float, kernel: PlantKernel | None = None) -> None:
    """Advance p, v, q, w one semi-implicit Euler step, in place."""
    kernel = kernel or PlantKernel(plant)
    N = plant.n_vehicles
    wrench8 = np.empty((8, N))
    wrench8[0:3], wrench8[5:8] = force_b, torque_b
    w5 = rates_buffer(state.w)
    rigid_body_kernel(plant, kernel, state.p, state.v, state.q, w5,
                      np.ascontiguousarray(R).reshape(9, -1), wrench8, dt_s)()
    state.w[...] = w5[0:3]
