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
single-vehicle engine in `run` transcribes the same equations in plain floats.
"""

from __future__ import annotations

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


def control(gains: ControllerGains, p_err: np.ndarray, v: np.ndarray, integral: np.ndarray,
            R: tuple, w: np.ndarray, yaw_cos: float, yaw_sin: float) -> np.ndarray:
    """Batched Lee control law. Vectors are (3, N); R is the 9 entries R[i][j] as (N,) arrays.

    Returns the wrench (4, N) = [thrust along body z, roll, pitch, yaw torque].
    """
    g = gains.g_m_s2
    m = gains.mass_kg
    a = -gains.kp_1_s2 * p_err - gains.kd_1_s * v - gains.ki_1_s3 * integral
    ax, ay, az = a
    # Tilt limit: cap the horizontal acceleration, keeping its direction.
    a_h_max = gains.max_horizontal_accel_m_s2
    scale = m * a_h_max / np.maximum(np.sqrt(ax * ax + ay * ay), a_h_max)
    a_v = gains.max_vertical_accel_m_s2
    Fx, Fy, Fz = scale * ax, scale * ay, m * (np.minimum(np.maximum(az, -a_v), a_v) + g)
    inv_F = 1.0 / np.sqrt(Fx * Fx + Fy * Fy + Fz * Fz)
    b3x, b3y, b3z = Fx * inv_F, Fy * inv_F, Fz * inv_F
    # b2 = b3 x b1c / |.| with the heading b1c = (cos yaw, sin yaw, 0).
    b2x, b2y, b2z = -b3z * yaw_sin, b3z * yaw_cos, b3x * yaw_sin - b3y * yaw_cos
    inv_n2 = 1.0 / np.sqrt(b2x * b2x + b2y * b2y + b2z * b2z)
    b2x, b2y, b2z = b2x * inv_n2, b2y * inv_n2, b2z * inv_n2
    b1x, b1y, b1z = b2y * b3z - b2z * b3y, b2z * b3x - b2x * b3z, b2x * b3y - b2y * b3x
    R00, R01, R02, R10, R11, R12, R20, R21, R22 = R
    thrust = Fx * R02 + Fy * R12 + Fz * R22
    # e_R = 1/2 vee(Rd^T R - R^T Rd); (Rd^T R)_ij = b_i . R[:, j].
    M21 = b3x * R01 + b3y * R11 + b3z * R21
    M12 = b2x * R02 + b2y * R12 + b2z * R22
    M02 = b1x * R02 + b1y * R12 + b1z * R22
    M20 = b3x * R00 + b3y * R10 + b3z * R20
    M10 = b2x * R00 + b2y * R10 + b2z * R20
    M01 = b1x * R01 + b1y * R11 + b1z * R21
    s = gains.kR_1_s2 * 0.5 * np.array([M21 - M12, M02 - M20, M10 - M01]) + gains.kw_1_s * w
    J = gains.inertia_kg_m2
    Jw = J @ w
    wrench = np.empty((4, len(thrust)))
    wrench[0] = thrust
    wrench[1:] = -(J @ s)
    wrench[1] += w[1] * Jw[2] - w[2] * Jw[1]
    wrench[2] += w[2] * Jw[0] - w[0] * Jw[2]
    wrench[3] += w[0] * Jw[1] - w[1] * Jw[0]
    return wrench


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
    when not `want_worst`).
    """
    hi = thrust_max_N[:, None]
    thrust = allocation_pinv @ wrench
    saturated = (thrust < 0.0).any(axis=0) | (thrust > hi).any(axis=0)
    worst = (np.maximum(-thrust, thrust - hi) / hi).argmax(axis=0) if want_worst else None
    if saturated.any():
        cols = np.flatnonzero(saturated)
        thrust[:, cols] = _prioritised(allocation_pinv, wrench[:, cols], hi)
    return thrust, saturated, worst


def _prioritised(allocation_pinv: np.ndarray, wrench: np.ndarray, hi: np.ndarray) -> np.ndarray:
    base = allocation_pinv[:, 0:1] * wrench[0]
    over = base > hi
    if over.any():
        base = base * np.where(over, hi / np.where(over, base, 1.0), 1.0).min(axis=0)
    base = np.minimum(np.maximum(base, 0.0), hi)
    for part in (allocation_pinv[:, 1:3] @ wrench[1:3], allocation_pinv[:, 3:4] * wrench[3]):
        room = np.where(part > 0.0, hi - base, -base)
        with np.errstate(divide="ignore", invalid="ignore"):
            limits = np.where(part != 0.0, room / part, np.inf)
        base = base + np.clip(limits.min(axis=0), 0.0, 1.0) * part
    return np.minimum(np.maximum(base, 0.0), hi)
