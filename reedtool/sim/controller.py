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

This module designs the controller; the law itself is equations.attitude_control and
the allocation equations.pinv_thrusts and desaturate, which every engine flies.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

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
    speeds (the plant's RotorS terms, equations.rotor_wrench, which are linear in the
    airspeed): the 2-norm of that 2x2 block."""
    from reedtool.sim.equations import rotor_wrench

    hover = allocation_pinv @ np.array([params.weight_N, 0.0, 0.0, 0.0])
    omega = np.sqrt(np.clip(hover / params.motor_constant, 0.0, params.omega_max_rad_s ** 2))
    torque = np.zeros((2, 2))
    for i in range(params.n_rotors):
        constants = (*params.rotor_position_m[i], *params.rotor_axis[i], 0.0, 0.0, 0.0,
                     params.rotor_drag_coefficient[i], params.rolling_moment_coefficient[i],
                     0.0, float(omega[i]))
        for j in range(2):      # a unit airspeed along x, then y (body axes), no rotation
            xi = [0.0, 0.0, 0.0]
            xi[j] = 1.0
            torque[:, j] += rotor_wrench(*constants, *xi, 0.0, 0.0, 0.0)[3:5]
    return float(np.linalg.norm(torque, 2))


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
