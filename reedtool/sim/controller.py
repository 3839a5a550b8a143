"""Geometric (Lee) position + attitude controller with gains derived from the model.

Position: a PID on the position error whose closed loop has a triple pole at
-omega_p (kp = 3 w^2, kd = 3 w, ki = w^3, per unit mass); the integral removes the
offset a mis-estimated mass or thrust constant would leave (the robustness batch flies
perturbed vehicles on the nominal controller). Attitude: Lee, Leok and McClamroch (2010),
tau = -J (kR e_R + kw e_w) + w x J w with kR = omega_a^2, kw = 2 zeta omega_a, so the
torque scales with the model's full inertia tensor. The natural frequencies are chosen
once for every model; the only model-dependent cap is the motor lag, which an attitude
loop faster than about a third of the motors' bandwidth would fight. Allocation: the
pseudo-inverse of the nominal allocation matrix.

`control` is the batched law used by the batch engine (columns are vehicles); the
single-vehicle engine (`scalar`) generates the same equations in plain floats.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from .params import VehicleParams


@dataclass(frozen=True)
class ControllerDesign:
    """The once-for-all design choices; everything model-specific is derived from these."""

    attitude_natural_frequency_rad_s: float = 12.0
    attitude_damping: float = 0.9
    motor_bandwidth_fraction: float = 1.0 / 3.0   # omega_a <= fraction / tau_motor
    position_to_attitude_ratio: float = 1.0 / 6.0  # omega_p = ratio * omega_a
    max_tilt_rad: float = math.radians(30.0)
    max_vertical_accel_g: float = 0.5
    max_integral_accel_g: float = 0.25              # anti-windup: |ki * integral| cap


@dataclass(frozen=True)
class ControllerGains:
    mass_kg: float
    inertia_kg_m2: np.ndarray        # (3, 3) nominal, about the COM
    g_m_s2: float
    kp_1_s2: float                   # position gains, per unit mass
    kd_1_s: float
    ki_1_s3: float
    kR_1_s2: float                   # attitude gains, per unit inertia
    kw_1_s: float
    max_horizontal_accel_m_s2: float
    max_vertical_accel_m_s2: float
    max_integral_m_s: float          # |integral of position error| cap per axis [m*s]
    allocation_pinv: np.ndarray      # (n, 4) nominal [T, tau] -> per-rotor thrust
    motor_constant: np.ndarray       # (n,) nominal
    omega_max_rad_s: np.ndarray      # (n,)

    @functools.cached_property
    def pid_matrix(self) -> np.ndarray:
        """(3, 9): [position error; velocity; integral] -> commanded acceleration."""
        I3 = np.eye(3)
        return np.hstack([-self.kp_1_s2 * I3, -self.kd_1_s * I3, -self.ki_1_s3 * I3])

    @functools.cached_property
    def wrench_matrix(self) -> np.ndarray:
        """(4, 7 + k): [thrust; 2 e_R; w; gyro_products] -> [thrust; torque].

        The attitude law tau = -J (kR e_R + kw w) + w x J w is linear in e_R and w, and
        the gyroscopic term is a fixed quadratic form in w for the nominal J.
        """
        return self._wrench_and_products[0]

    @property
    def gyro_products(self) -> list[tuple[int, int]]:
        """The products w_i w_j (i <= j) with a non-zero column in the wrench matrix, in
        its column order (e.g. none of the squares when J is diagonal)."""
        return self._wrench_and_products[1]

    @functools.cached_property
    def _wrench_and_products(self) -> tuple[np.ndarray, list[tuple[int, int]]]:
        J = self.inertia_kg_m2
        levi = np.zeros((3, 3, 3))
        for i, j, k in ((0, 1, 2), (1, 2, 0), (2, 0, 1)):
            levi[i, j, k], levi[i, k, j] = 1.0, -1.0
        # (w x J w)_k = sum_il T[k, i, l] w_i w_l with T[k, i, l] = sum_j eps_kij J_jl.
        T = np.einsum("kij,jl->kil", levi, J)
        pairs = [(i, j) for i in range(3) for j in range(i, 3)]
        gyro = np.column_stack([T[:, i, i] if i == j else T[:, i, j] + T[:, j, i]
                                for i, j in pairs])
        used = [c for c in range(len(pairs)) if np.any(gyro[:, c] != 0.0)]
        W = np.zeros((4, 7 + len(used)))
        W[0, 0] = 1.0
        W[1:, 1:4] = -0.5 * self.kR_1_s2 * J
        W[1:, 4:7] = -self.kw_1_s * J
        W[1:, 7:] = gyro[:, used]
        return W, [pairs[c] for c in used]

    @classmethod
    def from_params(cls, params: VehicleParams,
                    design: ControllerDesign = ControllerDesign()) -> "ControllerGains":
        tau_motor_s = float(np.max(np.maximum(params.time_constant_up_s,
                                              params.time_constant_down_s)))
        omega_a = design.attitude_natural_frequency_rad_s
        if tau_motor_s > 0:
            omega_a = min(omega_a, design.motor_bandwidth_fraction / tau_motor_s)
        omega_p = design.position_to_attitude_ratio * omega_a
        g = params.g_m_s2
        ki = omega_p ** 3
        return cls(
            mass_kg=params.mass_kg,
            inertia_kg_m2=params.inertia_kg_m2,
            g_m_s2=g,
            kp_1_s2=3.0 * omega_p ** 2,
            kd_1_s=3.0 * omega_p,
            ki_1_s3=ki,
            kR_1_s2=omega_a ** 2,
            kw_1_s=2.0 * design.attitude_damping * omega_a,
            max_horizontal_accel_m_s2=g * math.tan(design.max_tilt_rad),
            max_vertical_accel_m_s2=design.max_vertical_accel_g * g,
            max_integral_m_s=design.max_integral_accel_g * g / ki,
            allocation_pinv=np.linalg.pinv(params.allocation()),
            motor_constant=params.motor_constant,
            omega_max_rad_s=params.omega_max_rad_s,
        )

    def to_dict(self) -> dict:
        return {"kp_1_s2": self.kp_1_s2, "kd_1_s": self.kd_1_s, "ki_1_s3": self.ki_1_s3,
                "kR_1_s2": self.kR_1_s2, "kw_1_s": self.kw_1_s}


# Rows of the scratch array `control` works in.
CONTROL_WORK_ROWS = 30


def control(gains: ControllerGains, evi: np.ndarray, R: np.ndarray, w: np.ndarray,
            work: np.ndarray | None = None) -> np.ndarray:
    """Batched Lee control law towards a setpoint at heading 0 (columns are vehicles).

    evi (9, N): position error, velocity and the integral of the position error (world);
    R (3, 3, N): body -> world rotations; w (3, N): body rates; `work`: optional
    (CONTROL_WORK_ROWS, N) scratch array to reuse between calls.
    Returns the wrench (4, N) = [thrust along body z, roll, pitch, yaw torque].

    Written as one numpy call per row operation into reused rows: at N ~ 1000 a call's
    overhead costs about as much as its arithmetic, and broadcasting, einsum and fresh
    temporaries each cost more than that.
    """
    N = evi.shape[1]
    if work is None:
        work = np.empty((CONTROL_WORK_ROWS, N))
    mul, sub, sqrt, div = np.multiply, np.subtract, np.sqrt, np.divide
    (t0, t1, t2, Fx, Fy, Fz, F_norm, inv_F, b3x, b3y, b3z, n_sq, inv_n, b1x, u, A1,
     A2) = (work[i] for i in range(17))
    x = work[17:30]
    R9 = R.reshape(9, N)
    R00, R01, R02, R10, R11, R12, R20, R21, R22 = (R9[i] for i in range(9))
    a = gains.pid_matrix @ evi      # -kp e - kd v - ki integral
    ax, ay, az = a[0], a[1], a[2]
    m, g = gains.mass_kg, gains.g_m_s2
    # Tilt limit: cap the horizontal acceleration, keeping its direction.
    a_h_max, a_v = gains.max_horizontal_accel_m_s2, gains.max_vertical_accel_m_s2
    mul(ax, ax, out=t0)
    t0 += mul(ay, ay, out=t1)
    sqrt(t0, out=t0)
    np.maximum(t0, a_h_max, out=t0)
    div(m * a_h_max, t0, out=t0)
    mul(t0, ax, out=Fx)
    mul(t0, ay, out=Fy)
    np.maximum(az, -a_v, out=Fz)
    np.minimum(Fz, a_v, out=Fz)
    Fz += g
    Fz *= m
    mul(Fx, Fx, out=F_norm)
    F_norm += mul(Fy, Fy, out=t0)
    F_norm += mul(Fz, Fz, out=t0)
    sqrt(F_norm, out=F_norm)
    div(1.0, F_norm, out=inv_F)
    mul(Fx, inv_F, out=b3x)
    mul(Fy, inv_F, out=b3y)
    mul(Fz, inv_F, out=b3z)
    # Heading 0, b1c = (1, 0, 0): b2 = b3 x b1c / |.| = (0, b3z, -b3y) / n and
    # b1 = b2 x b3 = (n, -b3x b3y / n, -b3x b3z / n) with n = sqrt(b3y^2 + b3z^2).
    mul(b3y, b3y, out=n_sq)
    n_sq += mul(b3z, b3z, out=t0)
    sqrt(n_sq, out=inv_n)
    div(1.0, inv_n, out=inv_n)
    mul(n_sq, inv_n, out=b1x)
    mul(inv_n, b3x, out=u)
    # x = [thrust; vee(Rd^T R - R^T Rd) = 2 e_R; w; products w_i w_j]: the wrench is
    # linear in these (gains.wrench_matrix). (Rd^T R)_ij = b_i . R[:, j] =: M_ij.
    mul(b3y, R11, out=A1)
    A1 += mul(b3z, R21, out=t0)
    mul(b3y, R12, out=A2)
    A2 += mul(b3z, R22, out=t0)
    mul(b3x, R02, out=t0)                                   # thrust F . R[:, 2]
    t0 += A2
    mul(F_norm, t0, out=x[0])
    mul(b3x, R01, out=t0)                                   # M21 - M12
    t0 += A1
    mul(b3z, R12, out=t1)
    t1 -= mul(b3y, R22, out=t2)
    t1 *= inv_n
    sub(t0, t1, out=x[1])
    mul(b1x, R02, out=t0)                                   # M02 - M20
    t0 -= mul(u, A2, out=t1)
    mul(b3x, R00, out=t1)
    t1 += mul(b3y, R10, out=t2)
    t1 += mul(b3z, R20, out=t2)
    sub(t0, t1, out=x[2])
    mul(b3z, R10, out=t0)                                   # M10 - M01
    t0 -= mul(b3y, R20, out=t1)
    t0 *= inv_n
    mul(b1x, R01, out=t1)
    t1 -= mul(u, A1, out=t2)
    sub(t0, t1, out=x[3])
    x[4:7] = w
    products = gains.gyro_products
    for row, (i, j) in enumerate(products, start=7):
        mul(w[i], w[j], out=x[row])
    return gains.wrench_matrix @ x[:7 + len(products)]


def allocate(allocation_pinv: np.ndarray, wrench: np.ndarray, thrust_max_N: np.ndarray,
             want_worst: bool = True) -> tuple[np.ndarray, np.ndarray, np.ndarray | None]:
    """Per-rotor thrusts (n, N) for the wrenches (4, N), desaturated when out of range.

    The pseudo-inverse solution is used whenever every rotor can deliver it. When some
    cannot, clipping each rotor on its own would distort the torque (a saturated quad then
    couples roll into pitch and yaw and can limit-cycle), so, as PX4's mixer does, that
    vehicle's wrench is split into its collective-thrust, roll/pitch and yaw parts and
    they are added in priority order: the thrust part (scaled into range if it alone
    saturates), then as much of the roll/pitch part as fits, then of the yaw part. The
    torques keep their direction.

    Returns (thrust (n, N), saturated (N,) bool, most-out-of-range rotor (N,) int or None
    when not `want_worst`). `thrust_max_N` is (n,), or (n, N) (faster: no broadcasting).
    """
    hi = thrust_max_N if thrust_max_N.ndim == 2 else thrust_max_N[:, None]
    thrust = allocation_pinv @ wrench
    saturated = ((thrust < 0.0) | (thrust > hi)).any(axis=0)
    worst = (np.maximum(-thrust, thrust - hi) / hi).argmax(axis=0) if want_worst else None
    if saturated.any():
        cols = np.flatnonzero(saturated)
        hi_cols = hi[:, cols] if hi.shape[1] > 1 else hi
        thrust[:, cols] = _prioritised(allocation_pinv, wrench[:, cols], hi_cols)
    return thrust, saturated, worst


def _prioritised(allocation_pinv: np.ndarray, wrench: np.ndarray, hi: np.ndarray) -> np.ndarray:
    base = allocation_pinv[:, 0:1] * wrench[0]
    over = base > hi
    if over.any():
        base = base * np.where(over, hi / np.where(over, base, 1.0), 1.0).min(axis=0)
    base = np.minimum(np.maximum(base, 0.0), hi)
    for part in (allocation_pinv[:, 1:3] @ wrench[1:3], allocation_pinv[:, 3:4] * wrench[3]):
        room = np.where(part > 0.0, hi - base, -base)
        limits = np.divide(room, part, out=np.full(part.shape, np.inf), where=part != 0.0)
        base = base + np.clip(limits.min(axis=0), 0.0, 1.0) * part
    return np.minimum(np.maximum(base, 0.0), hi)
