"""RotorS' Lee position controller (rotors_control lee_position_controller.cpp), flown on
the hover simulation's plant.

The controller is what ships with a RotorS package (`lee_controller_<mav>.yaml` and the
vehicle's `<mav>.yaml`), implemented from RotorS' equations; the plant is the model's own
(true mass, inertia, rotors from the URDF). With p, v the odometry frame's position and
world velocity, R its attitude, w its body rates, and the command a position p_ref at
heading psi (velocity, acceleration and yaw rate 0, as hovering_example sends):

    a     = (k_x o (p - p_ref) + k_v o v) / m_yaml - g e3        (ComputeDesiredAcceleration)
    b3d   = -a / |a|,  b2d = b3d x (cos psi, sin psi, 0) / |.|,  R_d = [b2d x b3d, b2d, b3d]
    e_R   = vee(R_d^T R - R^T R_d) / 2,  e_w = w
    alpha = -e_R o (k_R^T J_yaml^-1) - e_w o (k_w^T J_yaml^-1)  (ComputeDesiredAngularAcc;
                                                                 its w x w term is zero)
    T     = -m_yaml a . R e3
    w_i^2 = [A^T (A A^T)^-1 diag(J_yaml, 1)] [alpha; T],  w_i = sqrt(max(w_i^2, 0))
                                                               (CalculateRotorVelocities)

with g = 9.81 (rotors_control's constant) and A the 4 x n allocation of common.h, per
rotor i in terms of w_i^2: [sin(angle) l k_F; -cos(angle) l k_F; -direction k_F k_M; k_F].
For a diagonal J_yaml the normalisation cancels: the torque asked is -k_R o e_R - k_w o w,
so the attitude and angular-rate gains are torques per radian and per rad/s, and the
closed loop about one axis is J_true theta'' = -k_R theta - k_w theta' (small angles).
The position and velocity gains are forces per metre and per m/s. There is no integral
term: a mass that differs from the true one leaves an altitude offset (m_true - m_yaml)
g / k_z.

The controller runs at `control_rate_hz` (RotorS' basic.world steps physics at 100 Hz and
the odometry plugin publishes every step, without delay or noise, so the node commands
at 100 Hz) and holds its command in between; the motor plugin clamps the speed to
maxRotVelocity and lags it (sim.motor). A motor whose number has no controller entry gets
no command (the motor plugin refuses the out-of-range index and keeps 0).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from reedtool.sim import HoverConfig
from reedtool.sim.params import VehicleParams

ROTORS_GRAVITY_M_S2 = 9.81      # rotors_control parameters.h kDefaultGravity
# RotorS' basic.world: <max_step_size>0.01</max_step_size>, odometry every step.
ROTORS_CONTROL_RATE_HZ = 100.0


@dataclass(frozen=True)
class RotorsLee:
    """The Lee node's parameters: gains (3,) and what the vehicle YAML tells it."""

    position_gain: np.ndarray
    velocity_gain: np.ndarray
    attitude_gain: np.ndarray
    angular_rate_gain: np.ndarray
    mass_kg: float
    inertia_kg_m2: np.ndarray          # (3, 3)
    angle_rad: np.ndarray              # (n,) rotor_configuration, entry order
    arm_length_m: np.ndarray
    force_constant: np.ndarray
    moment_constant: np.ndarray
    direction: np.ndarray
    gravity_m_s2: float = ROTORS_GRAVITY_M_S2

    def __post_init__(self) -> None:
        for name in ("position_gain", "velocity_gain", "attitude_gain", "angular_rate_gain",
                     "angle_rad", "arm_length_m", "force_constant", "moment_constant",
                     "direction"):
            object.__setattr__(self, name, np.asarray(getattr(self, name), dtype=float).ravel())
        object.__setattr__(self, "inertia_kg_m2",
                           np.asarray(self.inertia_kg_m2, dtype=float).reshape(3, 3))

    @property
    def n_entries(self) -> int:
        return len(self.angle_rad)

    def allocation(self) -> np.ndarray:
        """(4, n) common.h calculateAllocationMatrix: rotor speed squared -> [roll, pitch,
        yaw torque; thrust]."""
        kF, l, a = self.force_constant, self.arm_length_m, self.angle_rad
        return np.vstack([np.sin(a) * l * kF, -np.cos(a) * l * kF,
                          -self.direction * kF * self.moment_constant, kF])

    def speed_map(self) -> np.ndarray:
        """(n, 4) A^T (A A^T)^-1 diag(J, 1): [angular acceleration; thrust] -> speed^2."""
        A = self.allocation()
        I4 = np.eye(4)
        I4[0:3, 0:3] = self.inertia_kg_m2
        return A.T @ np.linalg.inv(A @ A.T) @ I4

    def normalized_gains(self) -> tuple[np.ndarray, np.ndarray]:
        """(k_R^T J^-1, k_w^T J^-1): the gains per unit inertia RotorS works with."""
        J_inv = np.linalg.inv(self.inertia_kg_m2)
        return self.attitude_gain @ J_inv, self.angular_rate_gain @ J_inv

    def speeds_squared(self, p_m: np.ndarray, v_m_s: np.ndarray, R: np.ndarray,
                       w_rad_s: np.ndarray, p_ref_m: np.ndarray, yaw_ref_rad: float = 0.0,
                       speed_map: np.ndarray | None = None,
                       normalized: tuple | None = None) -> np.ndarray:
        """(n,) the rotor speeds squared the controller asks, before RotorS clamps them
        at 0 (p, v world; R body -> world; w body)."""
        M = self.speed_map() if speed_map is None else speed_map
        kR_n, kw_n = self.normalized_gains() if normalized is None else normalized
        m = self.mass_kg
        a = ((p_m - p_ref_m) * self.position_gain + v_m_s * self.velocity_gain) / m
        a[2] -= self.gravity_m_s2
        b1 = np.array([math.cos(yaw_ref_rad), math.sin(yaw_ref_rad), 0.0])
        b3 = -a / np.linalg.norm(a)
        b2 = np.cross(b3, b1)
        b2 /= np.linalg.norm(b2)
        R_d = np.column_stack([np.cross(b2, b3), b2, b3])
        E = 0.5 * (R_d.T @ R - R.T @ R_d)
        e_R = np.array([E[2, 1], E[0, 2], E[1, 0]])
        alpha = -e_R * kR_n - w_rad_s * kw_n
        thrust = -m * float(a @ R[:, 2])
        return M @ np.array([alpha[0], alpha[1], alpha[2], thrust])


@dataclass(frozen=True)
class LeeLoops:
    """The linearised closed loops the gains give on the true vehicle (for the report and
    the pre-flight checks): per axis natural frequency [rad/s] and damping ratio."""

    attitude_natural_rad_s: np.ndarray   # (3,) sqrt(k_R / J_true), J_true's diagonal
    attitude_damping: np.ndarray         # (3,) k_w / (2 sqrt(k_R J_true))
    position_natural_rad_s: np.ndarray   # (3,) sqrt(k_x / m_true)
    position_damping: np.ndarray         # (3,) k_v / (2 sqrt(k_x m_true))

    def to_dict(self) -> dict:
        return {"attitude_natural_rad_s": [float(v) for v in self.attitude_natural_rad_s],
                "attitude_damping": [float(v) for v in self.attitude_damping],
                "position_natural_rad_s": [float(v) for v in self.position_natural_rad_s],
                "position_damping": [float(v) for v in self.position_damping]}


def loops(lee: RotorsLee, mass_kg: float, inertia_kg_m2: np.ndarray) -> LeeLoops:
    """Second-order loops: RotorS' normalisation makes the torque -k_R e_R - k_w w for a
    diagonal YAML inertia, so J_true theta'' + k_w theta' + k_R theta = 0 per axis; the
    thrust gives m_true x'' + k_v x' + k_x x = 0 (NaN where a gain is not positive)."""
    J = np.diag(np.asarray(inertia_kg_m2, dtype=float))
    with np.errstate(invalid="ignore", divide="ignore"):
        kR, kw = lee.attitude_gain, lee.angular_rate_gain
        kx, kv = lee.position_gain, lee.velocity_gain
        return LeeLoops(np.sqrt(kR / J), kw / (2.0 * np.sqrt(kR * J)),
                        np.sqrt(kx / mass_kg), kv / (2.0 * np.sqrt(kx * mass_kg)))


def settle_time_s(loop: LeeLoops) -> float:
    """Time for the slowest position or attitude loop's envelope to fall to 2 %:
    4 / (zeta w_n) for zeta < 1, and the slow real pole's 4 / (w_n (zeta - sqrt(zeta^2 -
    1))) when overdamped. Infinite when a loop is not damped."""
    worst = 0.0
    for wn, zeta in ((loop.position_natural_rad_s, loop.position_damping),
                     (loop.attitude_natural_rad_s, loop.attitude_damping)):
        for w, z in zip(wn, zeta):
            if not (w > 0 and z > 0):
                return math.inf
            rate = z * w if z < 1 else w * (z - math.sqrt(z * z - 1.0))
            worst = max(worst, 4.0 / rate)
    return worst


@dataclass
class LeeGainsReport:
    """What a HoverRun's `gains` holds for a Lee flight (to_dict for JSON)."""

    lee: RotorsLee
    loop: LeeLoops
    control_rate_hz: float

    def to_dict(self) -> dict:
        lee = self.lee
        return {"controller": "rotors-lee",
                "control_rate_hz": self.control_rate_hz,
                "position_gain": lee.position_gain.tolist(),
                "velocity_gain": lee.velocity_gain.tolist(),
                "attitude_gain": lee.attitude_gain.tolist(),
                "angular_rate_gain": lee.angular_rate_gain.tolist(),
                "yaml_mass_kg": lee.mass_kg,
                "yaml_inertia_kg_m2": lee.inertia_kg_m2.tolist(),
                **self.loop.to_dict()}


def equilibrium_altitude_offset_m(params: VehicleParams, lee: RotorsLee,
                                  entry_of_rotor: np.ndarray | None = None) -> float:
    """Where the vehicle hovers, level, relative to the height it is sent: no integral
    term, so the collective T the controller asks, m_yaml g_c - k_z e_z, must give the
    weight through the true motors. A command T gives rotor speeds squared M[:, 3] T
    (entry order) and a true thrust c T with c = sum_i k_true,i M[entry_i, 3]; so
    e_z = (m_yaml g_c - m g / c) / k_z. NaN when k_z or c is not positive."""
    n = params.n_rotors
    entry = controller_entries(lee, np.arange(n) if entry_of_rotor is None else entry_of_rotor)
    column = lee.speed_map()[:, 3]
    c = float(sum(params.motor_constant[j] * column[entry[j]] for j in range(n)
                  if entry[j] >= 0))
    k_z = float(lee.position_gain[2])
    if not (c > 0 and k_z > 0):
        return math.nan
    return (lee.mass_kg * lee.gravity_m_s2 - params.weight_N / c) / k_z


def controller_entries(lee: RotorsLee, entry_of_rotor: np.ndarray):
    """(n_rotors,) index of the controller entry each of the plant's rotors obeys (-1: none)."""
    entry_of_rotor = np.asarray(entry_of_rotor, dtype=int)
    return np.where(entry_of_rotor < lee.n_entries, entry_of_rotor, -1)


def simulate_lee(params: VehicleParams, lee: RotorsLee, config: HoverConfig = HoverConfig(),
                 *, entry_of_rotor: np.ndarray | None = None,
                 odometry_from_com_m: np.ndarray | None = None,
                 control_rate_hz: float = ROTORS_CONTROL_RATE_HZ, record: bool = False,
                 reference_offset_m: float = 0.0):
    """Fly `params` (the true vehicle) under RotorS' Lee controller from config's start;
    a sim.run.HoverRun judged as every hover flight is.

    `entry_of_rotor[j]`: the controller entry (motor speed index) rotor j of `params`
    obeys (its motor number; default j). `odometry_from_com_m`: where the odometry frame's
    origin (the base link) sits relative to the COM, body axes (default: at the COM).
    `reference_offset_m`: the controller is sent the setpoint height minus this, so a
    vehicle that hovers that far off what it is sent (equilibrium_altitude_offset_m) is
    judged about where it settles. The numpy engine only (sim.batch with a speed command).
    """
    from reedtool.sim.batch import REASONS, simulate_batch
    from reedtool.sim.run import HoverRun, sample_series

    config.validate()
    n = params.n_rotors
    entry = controller_entries(lee, np.arange(n) if entry_of_rotor is None else entry_of_rotor)
    r_odo = np.zeros(3) if odometry_from_com_m is None else np.asarray(odometry_from_com_m,
                                                                      dtype=float)
    hold = max(1, int(round(config.rate_hz / control_rate_hz)))
    M = lee.speed_map()
    normalized = lee.normalized_gains()
    omega_max = params.omega_max_rad_s
    setpoint_com = np.array([0.0, 0.0, config.hover_altitude_m])
    # The controller is sent the setpoint for its odometry frame: the base link where it
    # hovers level with the COM at the hover setpoint.
    p_ref = setpoint_com + r_odo - np.array([0.0, 0.0, reference_offset_m])
    has_entry = entry >= 0

    def command_of(p, v, R, w) -> tuple[np.ndarray, bool, int]:
        p_odo = p + R @ r_odo
        v_odo = v + R @ np.cross(w, r_odo)
        sq = lee.speeds_squared(p_odo, v_odo, R, w, p_ref, 0.0, M, normalized)
        want = np.zeros(n)
        want[has_entry] = sq[entry[has_entry]]
        with np.errstate(invalid="ignore"):
            speed = np.sqrt(np.clip(want, 0.0, None))
            excess = np.maximum(-want, want - omega_max ** 2) / omega_max ** 2
        cmd = np.minimum(speed, omega_max)
        if not np.all(np.isfinite(cmd)):
            cmd = np.where(np.isfinite(cmd), cmd, 0.0)
        out = bool(np.any(excess[has_entry] > 0.0)) if has_entry.any() else False
        return cmd, out, int(np.nanargmax(excess)) if np.any(np.isfinite(excess)) else 0

    omega0, _, _ = command_of(setpoint_com.copy(), np.zeros(3), np.eye(3), np.zeros(3))
    recorded: list[tuple] = []

    def factory(state, R9, setpoint, omega_cmd):
        held = {"saturated": None, "worst": None}

        def step(index: int, sample: bool) -> tuple:
            if index % hold == 0:
                R = R9[:, 0].reshape(3, 3)
                cmd, out, worst = command_of(state.p[:, 0], state.v[:, 0], R, state.w[:, 0])
                omega_cmd[:, 0] = cmd
                held["saturated"] = np.array([out]) if out else None
                held["worst"] = np.array([worst]) if out else None
            if record and sample:
                R = R9[:, 0]
                e = state.p[:, 0] - setpoint
                pos = float(np.sqrt(e @ e))
                cos_att = min(max(0.5 * (R[0] + R[4] + R[8] - 1.0), -1.0), 1.0)
                recorded.append((index * config.dt_s, *state.p[:, 0], R[0], R[3], R[6], R[7],
                                 R[8], pos, cos_att, *state.omega[:, 0]))
            if held["saturated"] is None:
                return None, None
            return held["saturated"], held["worst"]

        return step

    outcome = simulate_batch(params, config, initial_omega_rad_s=omega0, command=factory)
    status = outcome.status(0)
    report = LeeGainsReport(lee, loops(lee, params.mass_kg, params.inertia_kg_m2),
                            control_rate_hz)
    return HoverRun(
        status=status, reason=REASONS[int(outcome.reason[0])],
        message=outcome.message(0, params.rotor_names),
        end_time_s=float(outcome.end_time_s[0]), settle_time_s=float(outcome.settle_time_s[0]),
        max_position_error_m=float(outcome.max_position_error_m[0]),
        max_attitude_error_deg=float(outcome.max_attitude_error_deg[0]),
        final_position_error_m=float(outcome.final_position_error_m[0]),
        final_attitude_error_deg=float(outcome.final_attitude_error_deg[0]),
        max_throttle=float(outcome.max_throttle[0]),
        longest_saturation_s=float(outcome.longest_saturation_s[0]),
        final_omega_rad_s=outcome.final_omega_rad_s[:, 0].copy(),
        initial_omega_rad_s=omega0, gains=report, config=config,
        rotor_names=params.rotor_names,
        series=sample_series(recorded, params.rotor_names) if record else {},
        engine="numpy")
