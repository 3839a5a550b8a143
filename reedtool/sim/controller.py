"""Geometric (Lee) position + attitude controller with gains derived from the model.

Position: a PID on the position error whose closed loop has a triple pole at
-omega_p (kp = 3 w^2, kd = 3 w, ki = w^3, per unit mass); the integral removes the
offset a mis-estimated mass or thrust constant would leave (the robustness batch flies
perturbed vehicles on the nominal controller). Attitude: Lee, Leok and McClamroch (2010),
tau = -J (kR e_R + kw e_w) + w x J w with kR = omega_a^2, kw = 2 zeta omega_a, so the
torque scales with the model's full inertia tensor. The bandwidths follow from the
vehicle (ControllerGains.from_params; docs/hover-test.md, "Tuning"): 12 rad/s, raised
against the rotors' drag moments, capped by the torque authority for the design tilt and
by the motors' lag (which a lead on their speed command shortens). Allocation: the
pseudo-inverse of the nominal allocation matrix.

`control` is the batched law used by the batch engine (columns are vehicles); the
single-vehicle engine (`scalar`) generates the same equations in plain floats.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from typing import Callable

import numpy as np

from reedtool.sim.params import VehicleParams


@dataclass(frozen=True)
class ControllerDesign:
    """The once-for-all design choices; everything model-specific is derived from these
    (docs/hover-test.md, "Tuning", gives the derivation and a worked example)."""

    attitude_natural_frequency_rad_s: float = 12.0  # the most asked of any vehicle
    attitude_damping: float = 0.9
    motor_bandwidth_fraction: float = 1.0 / 3.0   # omega_a <= fraction / tau_motor
    position_to_attitude_ratio: float = 1.0 / 6.0  # omega_p = ratio * omega_a
    max_tilt_rad: float = math.radians(30.0)
    max_vertical_accel_g: float = 0.5
    max_integral_accel_g: float = 0.25              # anti-windup: |ki * integral| cap
    # The disturbance the gains are designed for (fixed, whatever --roll asks): the
    # attitude loop's first demand, omega_a^2 * tilt, stays within the angular
    # acceleration the rotors can give from hover about the weakest of roll and pitch.
    design_tilt_rad: float = 0.2
    authority_cap: bool = True        # False: omega_a capped by the motors only
    aerodynamic_stiffening: bool = True  # raise omega_a against the rotors' drag moments
    # Motors slower than the attitude loop needs get a lead on their speed command
    # (the first-order lag inverted, as an ESC's speed loop does) down to
    # fraction / omega_a; False flies the bare lag and caps omega_a by it instead.
    motor_lead: bool = True
    # Tilt cap from the thrust margin: the collective needed at the cap, weight / cos,
    # stays within this fraction of the rotors' maximum upward thrust.
    tilt_thrust_fraction: float = 0.9
    min_tilt_rad: float = math.radians(5.0)


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
    # What the design chose and why (ControllerDesign; docs/hover-test.md, "Tuning"):
    attitude_bandwidth_rad_s: float = math.nan   # omega_a: kR = omega_a^2
    position_bandwidth_rad_s: float = math.nan   # omega_p: the PID's triple pole
    limited_by: str = "design"       # what capped omega_a: design, motor lag, torque authority
    angular_authority_rad_s2: float = math.nan   # weakest of roll/pitch from hover
    # The motors' lag (n,) and the lag their speed command is led down to (n,); equal
    # (or None) where no lead is needed.
    motor_time_constant_up_s: np.ndarray | None = None
    motor_time_constant_down_s: np.ndarray | None = None
    motor_lead_time_constant_up_s: np.ndarray | None = None
    motor_lead_time_constant_down_s: np.ndarray | None = None

    @property
    def has_motor_lead(self) -> bool:
        return self.motor_lead_time_constant_up_s is not None and bool(
            np.any(self.motor_lead_time_constant_up_s < self.motor_time_constant_up_s)
            or np.any(self.motor_lead_time_constant_down_s < self.motor_time_constant_down_s))

    def motor_lead_factors(self, dt_s: float) -> tuple[np.ndarray, np.ndarray] | None:
        """(up, down) per rotor: the speed command is omega + factor * (omega_want - omega),
        which makes the plant's discrete lag omega' = cmd + (omega - cmd) exp(-dt / tau)
        step as the led one, omega' = want + (omega - want) exp(-dt / tau_lead), exactly
        (until the command meets 0 or omega_max). None when no rotor needs a lead."""
        if not self.has_motor_lead:
            return None

        def factor(tau_s, lead_s):
            return -np.expm1(-dt_s / lead_s) / -np.expm1(-dt_s / tau_s)

        return (factor(self.motor_time_constant_up_s, self.motor_lead_time_constant_up_s),
                factor(self.motor_time_constant_down_s, self.motor_lead_time_constant_down_s))

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
        pinv = np.linalg.pinv(params.allocation())
        tau_up = np.asarray(params.time_constant_up_s, dtype=float)
        tau_down = np.asarray(params.time_constant_down_s, dtype=float)
        omega_a, limited_by = design.attitude_natural_frequency_rad_s, "design"
        # The rotors' drag and rolling moments tilt the body in proportion to its speed
        # through the air; a loop too soft for them turns the position loop into a spiral
        # (docs/hover-test.md, "Tuning"). Stiff enough: the cross-coupling they cause
        # no faster than the position loop's damping.
        omega_aero = aerodynamic_bandwidth_rad_s(params, pinv, design)
        if design.aerodynamic_stiffening and omega_aero > omega_a:
            omega_a, limited_by = omega_aero, "rotor drag"
        alpha = angular_authority_rad_s2(params, pinv)
        omega_auth = math.sqrt(max(alpha, 0.0) / design.design_tilt_rad)
        if design.authority_cap and omega_auth < omega_a:
            # A vehicle with no authority at all is not flown (sim.verdict); the floor
            # only keeps the gains finite for the flights that do happen (a rotor failure).
            omega_a, limited_by = max(omega_auth, MIN_ATTITUDE_BANDWIDTH_RAD_S), \
                "torque authority"
        lead_up, lead_down = tau_up, tau_down
        if design.motor_lead and omega_a > 0:
            # Lead each lag down to what omega_a needs, by at most MAX_MOTOR_LEAD.
            need_s = design.motor_bandwidth_fraction / omega_a
            lead_up = np.minimum(tau_up, np.maximum(need_s, tau_up / MAX_MOTOR_LEAD))
            lead_down = np.minimum(tau_down, np.maximum(need_s, tau_down / MAX_MOTOR_LEAD))
        tau_motor_s = float(np.max(np.maximum(lead_up, lead_down))) if len(tau_up) else 0.0
        if tau_motor_s > 0 and design.motor_bandwidth_fraction / tau_motor_s < omega_a:
            omega_a, limited_by = design.motor_bandwidth_fraction / tau_motor_s, "motor lag"
        omega_p = design.position_to_attitude_ratio * omega_a
        g = params.g_m_s2
        ki = omega_p ** 3
        # Tilt cap from the thrust margin: weight / cos(tilt) within a fraction of the
        # rotors' upward maximum.
        lift_max_N = float(np.sum(params.thrust_max_N * params.rotor_axis[:, 2]))
        ratio = design.tilt_thrust_fraction * lift_max_N / params.weight_N
        max_tilt = design.max_tilt_rad
        if ratio > 1.0:
            max_tilt = min(max_tilt, math.acos(1.0 / ratio))
        max_tilt = max(max_tilt, min(design.min_tilt_rad, design.max_tilt_rad))
        return cls(
            mass_kg=params.mass_kg,
            inertia_kg_m2=params.inertia_kg_m2,
            g_m_s2=g,
            kp_1_s2=3.0 * omega_p ** 2,
            kd_1_s=3.0 * omega_p,
            ki_1_s3=ki,
            kR_1_s2=omega_a ** 2,
            kw_1_s=2.0 * design.attitude_damping * omega_a,
            max_horizontal_accel_m_s2=g * math.tan(max_tilt),
            max_vertical_accel_m_s2=design.max_vertical_accel_g * g,
            max_integral_m_s=design.max_integral_accel_g * g / ki,
            allocation_pinv=pinv,
            motor_constant=params.motor_constant,
            omega_max_rad_s=params.omega_max_rad_s,
            attitude_bandwidth_rad_s=omega_a,
            position_bandwidth_rad_s=omega_p,
            limited_by=limited_by,
            angular_authority_rad_s2=alpha,
            motor_time_constant_up_s=tau_up,
            motor_time_constant_down_s=tau_down,
            motor_lead_time_constant_up_s=lead_up,
            motor_lead_time_constant_down_s=lead_down,
        )

    def to_dict(self) -> dict:
        out = {"kp_1_s2": self.kp_1_s2, "kd_1_s": self.kd_1_s, "ki_1_s3": self.ki_1_s3,
               "kR_1_s2": self.kR_1_s2, "kw_1_s": self.kw_1_s,
               "attitude_bandwidth_rad_s": self.attitude_bandwidth_rad_s,
               "position_bandwidth_rad_s": self.position_bandwidth_rad_s,
               "limited_by": self.limited_by,
               "angular_authority_rad_s2": self.angular_authority_rad_s2,
               "max_tilt_deg": math.degrees(math.atan(self.max_horizontal_accel_m_s2
                                                      / self.g_m_s2)),
               "motor_lead": None}
        if self.has_motor_lead:
            out["motor_lead"] = {
                "time_constant_up_s": [float(v) for v in self.motor_time_constant_up_s],
                "time_constant_down_s": [float(v) for v in self.motor_time_constant_down_s],
                "led_up_s": [float(v) for v in self.motor_lead_time_constant_up_s],
                "led_down_s": [float(v) for v in self.motor_lead_time_constant_down_s]}
        return out


# A speed command at most this many times the change asked of the motor: a lag slower
# than MAX_MOTOR_LEAD times what the attitude loop needs caps the loop instead.
MAX_MOTOR_LEAD = 8.0
MIN_ATTITUDE_BANDWIDTH_RAD_S = 1.0


def aerodynamic_torque_per_speed(params: VehicleParams, allocation_pinv: np.ndarray) -> float:
    """[N*m / (m/s)] The roll/pitch torque the rotors' drag (through its lever about the
    COM) and rolling moments put on the body per m/s of horizontal airspeed at the hover
    speeds (the plant's RotorS terms, sim.motor.drag_matrices): the 2-norm of that 2x2
    block."""
    from reedtool.sim.motor import drag_matrices

    hover = allocation_pinv @ np.array([params.weight_N, 0.0, 0.0, 0.0])
    omega = np.sqrt(np.clip(hover / params.motor_constant, 0.0, params.omega_max_rad_s ** 2))
    K = drag_matrices(params.rotor_position_m, params.rotor_axis,
                      params.rotor_drag_coefficient, params.rolling_moment_coefficient)
    torque = np.einsum("ijn,n->ij", K[3:6, 0:3] + K[6:9, 0:3], omega)
    return float(np.linalg.norm(torque[0:2, 0:2], 2))


def aerodynamic_bandwidth_rad_s(params: VehicleParams, allocation_pinv: np.ndarray,
                                design: ControllerDesign) -> float:
    """The attitude bandwidth at which the drag moments' cross-coupling, g C / (J w_a^2)
    (C the torque per speed above: tilt per m/s times g), equals the position loop's
    damping kd = 3 ratio w_a: w_a = (g C / (3 ratio J))^(1/3), J the smaller of the
    roll and pitch inertias."""
    C = aerodynamic_torque_per_speed(params, allocation_pinv)
    J = float(min(params.inertia_kg_m2[0, 0], params.inertia_kg_m2[1, 1]))
    if not (C > 0 and J > 0):
        return 0.0
    return (params.g_m_s2 * C / (3.0 * design.position_to_attitude_ratio * J)) ** (1.0 / 3.0)


def angular_authority_rad_s2(params: VehicleParams, allocation_pinv: np.ndarray) -> float:
    """The weakest of the roll and pitch angular accelerations the rotors can give from the
    controller's hover split, in both signs, each axis alone (the way the controller
    allocates: along the pseudo-inverse's torque column until a rotor meets 0 or its
    maximum), per the inertia about that axis. 0 when the hover split is out of range."""
    hover = allocation_pinv @ np.array([params.weight_N, 0.0, 0.0, 0.0])
    hi = params.thrust_max_N
    worst = math.inf
    for axis in (0, 1):
        d = allocation_pinv[:, axis + 1]
        for step in (d, -d):
            with np.errstate(divide="ignore", invalid="ignore"):
                up = np.where(step > 0, (hi - hover) / step, np.inf)
                down = np.where(step < 0, -hover / step, np.inf)
            reach = float(min(up.min(), down.min()))
            worst = min(worst, max(reach, 0.0) / params.inertia_kg_m2[axis, axis])
    return worst if math.isfinite(worst) else 0.0


def control_kernel(gains: ControllerGains, evi: np.ndarray, R9: np.ndarray, w: np.ndarray,
                   wrench: np.ndarray) -> Callable[[], None]:
    """`compute()`: the batched Lee control law towards a setpoint at heading 0, into
    wrench (4, N) = [thrust along body z, roll, pitch, yaw torque] (columns are vehicles).

    evi (9, N): position error, velocity and the integral of the position error (world);
    R9 (9, N): rows R00 R01 ... R22 of the body -> world rotations; w (3, N): body rates.

    Written as one numpy call per row operation on rows bound once: at N ~ 1000 a call's
    overhead costs about as much as its arithmetic, and broadcasting, einsum, fresh
    temporaries and building views each cost more than that. A few calls cover two or
    three rows where the operands lie next to each other.
    """
    mul, add, sub, sqrt, div = np.multiply, np.add, np.subtract, np.sqrt, np.divide
    maximum, minimum, matmul, copyto = np.maximum, np.minimum, np.matmul, np.copyto
    N = evi.shape[1]
    products = gains.gyro_products
    work = np.empty((27 + len(products), N))
    a, t, F = work[0:3], work[3:6], work[6:9]
    a01, ax, ay, az = a[0:2], a[0], a[1], a[2]
    t01, t0, t1, t2 = t[0:2], t[0], t[1], t[2]
    Fx, Fy, Fz = F
    F_norm, inv_F, n_sq, inv_n, b1x, u, A1, A2 = (work[i] for i in range(9, 17))
    b3 = work[17:20]
    b3x, b3y, b3z = b3
    b3yz = b3[1:3]
    x = work[20:27 + len(products)]
    x0, x1, x2, x3, x_w = x[0], x[1], x[2], x[3], x[4:7]
    gyro = [(w[i], w[j], x[row]) for row, (i, j) in enumerate(products, start=7)]
    R00, R01, R02, R10, R11, R12, R20, R21, R22 = R9
    pid, W = gains.pid_matrix, gains.wrench_matrix
    m, g = gains.mass_kg, gains.g_m_s2
    a_h_max, a_v = gains.max_horizontal_accel_m_s2, gains.max_vertical_accel_m_s2
    m_a_h_max = m * a_h_max

    def compute() -> None:
        matmul(pid, evi, a)          # -kp e - kd v - ki integral
        # Tilt limit: cap the horizontal acceleration, keeping its direction.
        mul(a01, a01, t01)
        add(t0, t1, t0)
        sqrt(t0, t0)
        maximum(t0, a_h_max, out=t0)
        div(m_a_h_max, t0, t0)
        mul(t0, ax, Fx)
        mul(t0, ay, Fy)
        maximum(az, -a_v, out=Fz)
        minimum(Fz, a_v, out=Fz)
        add(Fz, g, Fz)
        mul(Fz, m, Fz)
        mul(F, F, t)
        add(t0, t1, F_norm)
        add(F_norm, t2, F_norm)
        sqrt(F_norm, F_norm)
        div(1.0, F_norm, inv_F)
        mul(Fx, inv_F, b3x)
        mul(Fy, inv_F, b3y)
        mul(Fz, inv_F, b3z)
        # Heading 0, b1c = (1, 0, 0): b2 = b3 x b1c / |.| = (0, b3z, -b3y) / n and
        # b1 = b2 x b3 = (n, -b3x b3y / n, -b3x b3z / n) with n = sqrt(b3y^2 + b3z^2).
        mul(b3yz, b3yz, t01)
        add(t0, t1, n_sq)
        sqrt(n_sq, inv_n)
        div(1.0, inv_n, inv_n)
        mul(n_sq, inv_n, b1x)
        mul(inv_n, b3x, u)
        # x = [thrust; vee(Rd^T R - R^T Rd) = 2 e_R; w; products w_i w_j]: the wrench is
        # linear in these (gains.wrench_matrix). (Rd^T R)_ij = b_i . R[:, j] =: M_ij.
        mul(b3y, R11, A1)
        mul(b3z, R21, t0)
        add(A1, t0, A1)
        mul(b3y, R12, A2)
        mul(b3z, R22, t0)
        add(A2, t0, A2)
        mul(b3x, R02, t0)                                   # thrust F . R[:, 2]
        add(t0, A2, t0)
        mul(F_norm, t0, x0)
        mul(b3x, R01, t0)                                   # M21 - M12
        add(t0, A1, t0)
        mul(b3z, R12, t1)
        mul(b3y, R22, t2)
        sub(t1, t2, t1)
        mul(t1, inv_n, t1)
        sub(t0, t1, x1)
        mul(b1x, R02, t0)                                   # M02 - M20
        mul(u, A2, t1)
        sub(t0, t1, t0)
        mul(b3x, R00, t1)
        mul(b3y, R10, t2)
        add(t1, t2, t1)
        mul(b3z, R20, t2)
        add(t1, t2, t1)
        sub(t0, t1, x2)
        mul(b3z, R10, t0)                                   # M10 - M01
        mul(b3y, R20, t1)
        sub(t0, t1, t0)
        mul(t0, inv_n, t0)
        mul(b1x, R01, t1)
        mul(u, A1, t2)
        sub(t1, t2, t1)
        sub(t0, t1, x3)
        copyto(x_w, w)
        for wi, wj, row in gyro:
            mul(wi, wj, row)
        matmul(W, x, wrench)

    return compute


def control(gains: ControllerGains, evi: np.ndarray, R: np.ndarray, w: np.ndarray) -> np.ndarray:
    """The control law (control_kernel) once: the wrench (4, N) for R (3, 3, N)."""
    wrench = np.empty((4, evi.shape[1]))
    control_kernel(gains, evi, np.ascontiguousarray(R).reshape(9, -1), w, wrench)()
    return wrench


def allocation_kernel(allocation_pinv: np.ndarray, wrench: np.ndarray, thrust_max_N: np.ndarray,
                      thrust: np.ndarray) -> Callable[[bool], tuple]:
    """`allocate(want_worst)`: per-rotor thrusts (n, N) into `thrust` for the wrenches
    (4, N), desaturated when out of range.

    The pseudo-inverse solution is used whenever every rotor can deliver it. When some
    cannot, clipping each rotor on its own would distort the torque (a saturated quad then
    couples roll into pitch and yaw and can limit-cycle), so, as PX4's mixer does, that
    vehicle's wrench is split into its collective-thrust, roll/pitch and yaw parts and
    they are added in priority order: the thrust part (scaled into range if it alone
    saturates), then as much of the roll/pitch part as fits, then of the yaw part. The
    torques keep their direction.

    Returns (saturated (N,) bool, most-out-of-range rotor (N,) int, or None when not
    `want_worst`), or (None, None) when no rotor of any vehicle is out of range: the
    per-vehicle answers cost more than that check. `thrust_max_N` is (n, N).
    """
    less, greater, logical_or, matmul = np.less, np.greater, np.logical_or, np.matmul
    hi = thrust_max_N
    below = np.empty(thrust.shape, dtype=bool)
    above = np.empty(thrust.shape, dtype=bool)

    def allocate(want_worst: bool) -> tuple:
        matmul(allocation_pinv, wrench, thrust)
        less(thrust, 0.0, below)
        greater(thrust, hi, above)
        if not (below.any() or above.any()):
            return None, None
        saturated = logical_or.reduce(logical_or(below, above, below), axis=0)
        worst = ((np.maximum(-thrust, thrust - hi) / hi).argmax(axis=0) if want_worst
                 else None)
        cols = np.flatnonzero(saturated)
        thrust[:, cols] = _prioritised(allocation_pinv, wrench[:, cols], hi[:, cols])
        return saturated, worst

    return allocate


def allocate(allocation_pinv: np.ndarray, wrench: np.ndarray, thrust_max_N: np.ndarray,
             want_worst: bool = True) -> tuple[np.ndarray, np.ndarray, np.ndarray | None]:
    """allocation_kernel once: (thrust (n, N), saturated (N,) bool, most-out-of-range
    rotor (N,) int or None when not `want_worst`). `thrust_max_N` is (n,) or (n, N)."""
    n, N = allocation_pinv.shape[0], wrench.shape[1]
    hi = np.broadcast_to(thrust_max_N.reshape(n, -1), (n, N)).copy()
    thrust = np.empty((n, N))
    saturated, worst = allocation_kernel(allocation_pinv, wrench, hi, thrust)(True)
    if saturated is None:
        saturated, worst = np.zeros(N, dtype=bool), np.zeros(N, dtype=np.int64)
        if want_worst:   # every rotor in range: the one closest to a limit
            worst = (np.maximum(-thrust, thrust - hi) / hi).argmax(axis=0)
    return thrust, saturated, (worst if want_worst else None)


def most_out_of_range_one(T, thrust_max) -> int:
    """The rotor whose thrust is furthest out of its range, relative to its maximum (the
    first on a tie): what a saturation streak reports. One source for the per-vehicle
    engines, as `prioritised_one` (run calls it, compiled jits it); `allocation_kernel`
    takes the same argmax over columns."""
    worst = 0
    best = -math.inf
    for i in range(len(T)):
        b, hi = T[i], thrust_max[i]
        excess = (b - hi if b - hi > -b else -b) / hi      # max(-b, b - hi), as Python's
        if excess > best:
            best = excess
            worst = i
    return worst


def prioritised_one(rows, thrust_max, f, t0, t1, t2, T) -> None:
    """The desaturation of `allocation_kernel` for one vehicle, into T: thrust, then
    roll/pitch, then yaw, each as much as fits.

    The single source of the per-vehicle engines: run (the generated float step) calls it
    as it is, on tuples and a list; compiled jits this very function (numba) for its
    kernels, on arrays. So it is written in the subset both run: index loops, `rows[i][k]`
    (row i of the pseudo-inverse), comparisons instead of min/max (the same NaN
    behaviour in both). The vectorised `_prioritised` below is the same rule over the
    columns of a batch; tests/test_sim.py and test_compiled.py hold them together.
    """
    n = len(T)
    fit = 1.0
    any_over = False
    for i in range(n):
        b = rows[i][0] * f
        T[i] = b
        if b > thrust_max[i]:
            ratio = thrust_max[i] / b
            if not any_over or ratio < fit:
                fit = ratio
            any_over = True
    for i in range(n):
        b = T[i] * fit if any_over else T[i]
        hi = thrust_max[i]
        T[i] = hi if b > hi else (0.0 if b < 0.0 else b)
    for stage in range(2):
        scale = math.inf
        for i in range(n):
            d = rows[i][1] * t0 + rows[i][2] * t1 if stage == 0 else rows[i][3] * t2
            if d > 0.0:
                room = (thrust_max[i] - T[i]) / d
                if room < scale:
                    scale = room
            elif d < 0.0:
                room = -T[i] / d
                if room < scale:
                    scale = room
        scale = 0.0 if scale < 0.0 else (1.0 if scale > 1.0 else scale)
        for i in range(n):
            d = rows[i][1] * t0 + rows[i][2] * t1 if stage == 0 else rows[i][3] * t2
            T[i] = T[i] + scale * d
    for i in range(n):
        b, hi = T[i], thrust_max[i]
        T[i] = hi if b > hi else (0.0 if b < 0.0 else b)


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
