"""The vectorised engine: N vehicles advanced by one array step, and the robustness batch.

Every vehicle is a column; one loop iteration steps all of them with numpy (no Python loop
per vehicle). The robustness batch perturbs the plant (mass, inertia, COM, per-motor
constants) and flies every vehicle on the controller designed for the nominal model, as a
real airframe is flown on the model it was tuned from.

The single-vehicle engine (`run`) implements the same equations in plain floats; a test
holds the two to the same trajectory.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable

import numpy as np

from . import STATUS_CODES, STATUS_FROM_CODE, ExitStatus, HoverConfig
from .controller import ControllerDesign, ControllerGains, allocate, control
from .dynamics import Plant, State, body_wrench, quat_from_rpy, rot_matrices, step_rigid_body
from .motor import speed_command, speed_filter_factors
from .params import VehicleParams

# Why a run ended, beyond its ExitStatus (index into REASONS).
REASONS = ("", "settled", "not-settled", "non-finite", "drifted", "rate", "ground", "flipped",
           "saturated", "yaw-spin")
_R = {name: i for i, name in enumerate(REASONS)}


@dataclass
class Outcome:
    """Per-vehicle results of one engine run; arrays are (N,) unless noted."""

    status_code: np.ndarray
    reason: np.ndarray
    reason_value: np.ndarray           # the number that ended the run (distance, rate, ...)
    end_time_s: np.ndarray
    settle_time_s: np.ndarray          # NaN when never settled
    max_position_error_m: np.ndarray
    max_attitude_error_deg: np.ndarray
    final_position_error_m: np.ndarray
    final_attitude_error_deg: np.ndarray
    max_throttle: np.ndarray
    longest_saturation_s: np.ndarray   # longest run of samples with the demand out of range
    final_omega_rad_s: np.ndarray      # (n, N)
    final_state: State
    config: HoverConfig

    def status(self, i: int = 0) -> ExitStatus:
        return STATUS_FROM_CODE[int(self.status_code[i])]

    def message(self, i: int = 0, rotor_names: tuple[str, ...] = ()) -> str:
        return describe(self.status(i), REASONS[int(self.reason[i])],
                        float(self.reason_value[i]), float(self.end_time_s[i]),
                        float(self.settle_time_s[i]), float(self.final_position_error_m[i]),
                        float(self.final_attitude_error_deg[i]), self.config, rotor_names,
                        float(self.longest_saturation_s[i]))


def describe(status: ExitStatus, reason: str, value: float, time_s: float, settle_s: float,
             final_pos_m: float, final_att_deg: float, config: HoverConfig,
             rotor_names: tuple[str, ...] = (), saturation_s: float = 0.0) -> str:
    """The one-line message of an ending (shared by both engines)."""
    tol = f"{100 * config.position_tol_m:g} cm and {config.attitude_tol_deg:g} deg"
    if status is ExitStatus.PASSED:
        return f"settled within {tol} after {settle_s:.2f} s and stayed"
    if status is ExitStatus.NOT_SETTLED:
        if math.isfinite(settle_s):
            return (f"entered {tol} only at {settle_s:.2f} s, less than {config.hold_s:g} s "
                    f"before the end")
        return (f"did not settle within {tol}: still {100 * final_pos_m:.1f} cm and "
                f"{final_att_deg:.1f} deg off after {time_s:.1f} s")
    at = f"at t = {time_s:.2f} s"
    if reason == "non-finite":
        return f"the state became non-finite {at}"
    if reason == "drifted":
        return f"drifted {value:.1f} m from the setpoint {at}"
    if reason == "rate":
        return f"roll/pitch rate reached {value:.0f} rad/s {at}"
    if reason == "ground":
        return f"hit the ground {at}"
    if reason == "flipped":
        return f"flipped over (tilt {value:.0f} deg) {at}"
    if reason == "saturated":
        name = rotor_names[int(value)] if 0 <= int(value) < len(rotor_names) else \
            f"rotor {int(value)}"
        return (f"did not settle: the controller asked for more than the rotors can give "
                f"for {saturation_s:.2f} s in a row ({name} furthest out of range); "
                f"still {100 * final_pos_m:.1f} cm and {final_att_deg:.1f} deg off")
    if reason == "yaw-spin":
        return f"spinning about the vertical at {value:.1f} rad/s {at}"
    return status.value


def initial_state(params: VehicleParams, gains: ControllerGains, config: HoverConfig,
                  n_vehicles: int) -> tuple[State, np.ndarray]:
    """Disturbed start with the rotors at the nominal trim speeds; also the setpoint (3,)."""
    N = n_vehicles
    setpoint = np.array([0.0, 0.0, config.hover_altitude_m])
    p0 = setpoint + np.asarray(config.offset_m, dtype=float)
    q0 = quat_from_rpy(config.roll_rad, config.pitch_rad, config.yaw_rad)
    omega0 = hover_speeds(params, gains)
    state = State(p=np.repeat(p0[:, None], N, axis=1), v=np.zeros((3, N)),
                  q=np.repeat(q0[:, None], N, axis=1), w=np.zeros((3, N)),
                  omega=np.repeat(omega0[:, None], N, axis=1))
    return state, setpoint


def hover_speeds(params: VehicleParams, gains: ControllerGains) -> np.ndarray:
    """The controller's allocation of [m*g, 0, 0, 0]: the minimum-norm trim speeds."""
    thrust = gains.allocation_pinv @ np.array([params.weight_N, 0.0, 0.0, 0.0])
    return speed_command(thrust, gains.motor_constant, gains.omega_max_rad_s)


def simulate_batch(params: VehicleParams, config: HoverConfig = HoverConfig(),
                   plant: Plant | None = None, design: ControllerDesign = ControllerDesign(),
                   progress: Callable[[int], None] | None = None) -> Outcome:
    """Fly every vehicle of `plant` (default: one nominal vehicle) on the nominal controller.

    `progress(steps)` is called now and then with the number of steps done since the last call.
    """
    config.validate()
    plant = plant or Plant.from_params(params, 1)
    gains = ControllerGains.from_params(params, design)
    N, n = plant.n_vehicles, params.n_rotors
    dt = config.dt_s
    state, setpoint = initial_state(params, gains, config, N)
    omega_park = state.omega[:, 0].copy()
    q_park = np.array([1.0, 0.0, 0.0, 0.0])
    integral = np.zeros((3, N))
    up, down = (f[:, None] for f in speed_filter_factors(
        dt, params.time_constant_up_s, params.time_constant_down_s))
    inv_k_hat = 1.0 / gains.motor_constant[:, None]
    omega_max = gains.omega_max_rad_s[:, None]
    alloc = gains.allocation_pinv
    thrust_max = gains.motor_constant * gains.omega_max_rad_s ** 2
    i_max = gains.max_integral_m_s
    yaw_cos, yaw_sin = 1.0, 0.0
    p_col = setpoint[:, None]

    status = np.zeros(N, dtype=np.int64)
    reason = np.zeros(N, dtype=np.int64)
    reason_value = np.zeros(N)
    end_time = np.full(N, config.duration_s)
    last_out = np.zeros(N)                  # last sample time outside the tolerance band
    sat_since = np.full(N, np.nan)          # start of the current saturated streak
    sat_rotor = np.zeros(N, dtype=np.int64)
    sat_longest = np.zeros(N)               # longest streak so far [s] and its rotor
    sat_longest_rotor = np.zeros(N, dtype=np.int64)
    max_pos = np.zeros(N)
    min_cos_att = np.ones(N)
    max_throttle = np.zeros(N)
    final_pos = np.zeros(N)
    final_cos = np.ones(N)
    cos_tol = config.cos_attitude_tol
    every = config.sample_every
    sample_dt = every * dt
    n_steps = config.n_steps
    report_every = max(1, n_steps // 100)
    reported = 0

    for step in range(n_steps + 1):
        t = step * dt
        R = rot_matrices(state.q)
        p_err = state.p - p_col
        last = step == n_steps
        sample = step % every == 0 or last
        wrench = control(gains, p_err, state.v, integral, R.reshape(9, -1), state.w,
                         yaw_cos, yaw_sin)
        thrust_cmd, saturated, worst_rotor = allocate(alloc, wrench, thrust_max, sample)
        omega_sq = thrust_cmd * inv_k_hat
        if sample:
            # ---- judge every running vehicle on the state at time t
            running = status == 0
            pos = np.sqrt((p_err * p_err).sum(axis=0))
            R22 = R[2, 2]
            # Attitude error: the angle from the level hover attitude at the setpoint
            # heading (what the trim assumes), i.e. the rotation angle of R itself.
            trace = R[0, 0] + R[1, 1] + R22
            cos_att = np.clip(0.5 * (trace - 1.0), -1.0, 1.0)
            throttle = (state.omega / omega_max).max(axis=0)
            with np.errstate(invalid="ignore"):
                max_pos = np.where(running, np.fmax(max_pos, pos), max_pos)
                min_cos_att = np.where(running, np.fmin(min_cos_att, cos_att), min_cos_att)
                max_throttle = np.where(running, np.fmax(max_throttle, throttle), max_throttle)
                final_pos = np.where(running, pos, final_pos)
                final_cos = np.where(running, cos_att, final_cos)
                within = (pos <= config.position_tol_m) & (cos_att >= cos_tol)
                last_out = np.where(running & ~within, t, last_out)
                rate_xy = np.sqrt(state.w[0] ** 2 + state.w[1] ** 2)
                sat_since = np.where(saturated,
                                     np.where(np.isnan(sat_since), t, sat_since), np.nan)
                sat_rotor = np.where(saturated & (sat_since == t), worst_rotor, sat_rotor)
                longer = running & saturated & (t - sat_since > sat_longest)
                sat_longest = np.where(longer, t - sat_since, sat_longest)
                sat_longest_rotor = np.where(longer, sat_rotor, sat_longest_rotor)
                finite = (np.isfinite(state.p).all(axis=0) & np.isfinite(state.w).all(axis=0)
                          & np.isfinite(state.q).all(axis=0))
                events = [
                    (~finite, ExitStatus.DIVERGED, "non-finite", np.zeros(N)),
                    (R22 < 0.0, ExitStatus.CRASHED, "flipped",
                     np.degrees(np.arccos(np.clip(R22, -1.0, 1.0)))),
                    (state.p[2] < 0.0, ExitStatus.CRASHED, "ground", state.p[2]),
                    (np.abs(state.w[2]) > config.yaw_spin_rad_s, ExitStatus.YAW_SPIN,
                     "yaw-spin", np.abs(state.w[2])),
                    (pos > config.divergence_distance_m, ExitStatus.DIVERGED, "drifted", pos),
                    (rate_xy > config.diverged_rate_rad_s, ExitStatus.DIVERGED, "rate",
                     rate_xy),
                ]
            ended = np.zeros(N, dtype=bool)
            for hit, code, why, value in events:
                new = running & hit & ~ended
                if new.any():
                    status[new] = STATUS_CODES[code]
                    reason[new] = _R[why]
                    reason_value[new] = value[new]
                    end_time[new] = t
                    ended |= new
            if last:
                settled = (status == 0) & within & (last_out + sample_dt
                                                    <= config.duration_s - config.hold_s + 1e-9)
                status[settled] = STATUS_CODES[ExitStatus.PASSED]
                reason[settled] = _R["settled"]
                # Not settled with the rotors long at their limits: say so, it is the cause.
                starved = (status == 0) & (sat_longest >= config.saturation_limit_s - 1e-9)
                status[starved] = STATUS_CODES[ExitStatus.SATURATED]
                reason[starved] = _R["saturated"]
                reason_value[starved] = sat_longest_rotor[starved]
                rest = status == 0
                status[rest] = STATUS_CODES[ExitStatus.NOT_SETTLED]
                reason[rest] = _R["not-settled"]
                break
            if ended.any():
                # Park finished vehicles at a level hover so they stay finite and cheap.
                state.p[:, ended] = p_col
                state.v[:, ended] = 0.0
                state.q[:, ended] = q_park[:, None]
                state.w[:, ended] = 0.0
                state.omega[:, ended] = omega_park[:, None]
                integral[:, ended] = 0.0
                if (status != 0).all():
                    break
        # ---- advance all vehicles one step
        # The allocation keeps thrusts within [0, k w_max^2], so no clamp at the top.
        omega_cmd = np.sqrt(np.maximum(omega_sq, 0.0))
        force, torque = body_wrench(plant, state, R)
        step_rigid_body(plant, state, R, force, torque, dt)
        omega = state.omega
        state.omega = omega_cmd + (omega - omega_cmd) * np.where(omega_cmd > omega, up, down)
        integral = np.minimum(np.maximum(integral + dt * p_err, -i_max), i_max)
        if progress is not None and step - reported >= report_every:
            progress(step - reported)
            reported = step
    if progress is not None and n_steps > reported:
        progress(n_steps - reported)

    # Time each vehicle entered the band for good; NaN when it ended early or outside it.
    reached_end = np.isin(status, [STATUS_CODES[ExitStatus.PASSED],
                                   STATUS_CODES[ExitStatus.NOT_SETTLED],
                                   STATUS_CODES[ExitStatus.SATURATED]])
    settle = np.where(reached_end & within, last_out + sample_dt, np.nan)
    # A vehicle parked early has its parked speeds in state.omega; its own final speeds
    # are meaningless anyway, so report the state as is.
    return Outcome(
        status_code=status, reason=reason, reason_value=reason_value, end_time_s=end_time,
        settle_time_s=settle, max_position_error_m=max_pos,
        max_attitude_error_deg=np.degrees(np.arccos(min_cos_att)),
        final_position_error_m=final_pos,
        final_attitude_error_deg=np.degrees(np.arccos(final_cos)),
        max_throttle=max_throttle, longest_saturation_s=sat_longest,
        final_omega_rad_s=state.omega.copy(),
        final_state=state, config=config)


# ------------------------------------------------------------ robustness batch

@dataclass(frozen=True)
class Spreads:
    """Half-widths of the uniform perturbations of the robustness batch."""

    mass_rel: float = 0.10            # mass scaled by 1 +- this
    com_m: float = 0.01               # COM shifted by up to +- this on each axis [m]
    inertia_rel: float = 0.10         # each principal moment scaled by 1 +- this
    motor_constant_rel: float = 0.05  # each motor's constant scaled by 1 +- this


@dataclass
class Perturbation:
    mass_scale: np.ndarray         # (N,)
    com_shift_m: np.ndarray        # (3, N)
    inertia_scale: np.ndarray      # (3, N) applied as S J S with S = diag(sqrt(scale))
    motor_scale: np.ndarray        # (n, N)


def sample_perturbations(n_vehicles: int, n_rotors: int, spreads: Spreads,
                         seed: int | None) -> Perturbation:
    rng = np.random.default_rng(seed)
    N = n_vehicles

    def uniform(shape, half_width):
        return rng.uniform(-half_width, half_width, size=shape)

    return Perturbation(
        mass_scale=1.0 + uniform(N, spreads.mass_rel),
        com_shift_m=uniform((3, N), spreads.com_m),
        inertia_scale=1.0 + uniform((3, N), spreads.inertia_rel),
        motor_scale=1.0 + uniform((n_rotors, N), spreads.motor_constant_rel),
    )


def perturbed_plant(params: VehicleParams, perturbation: Perturbation) -> Plant:
    N = len(perturbation.mass_scale)
    plant = Plant.from_params(params, N)
    plant.mass_kg = params.mass_kg * perturbation.mass_scale
    plant.inertia_scale_sqrt = np.sqrt(perturbation.inertia_scale)
    plant.com_shift_m = perturbation.com_shift_m.copy()
    plant.motor_constant = params.motor_constant[:, None] * perturbation.motor_scale
    return plant


@dataclass
class BatchReport:
    n_vehicles: int
    passed: int
    counts: dict[str, int]
    worst: list[dict]
    spreads: Spreads
    seed: int | None

    @property
    def pass_rate(self) -> float:
        return self.passed / self.n_vehicles if self.n_vehicles else 0.0

    def to_dict(self) -> dict:
        return {"samples": self.n_vehicles, "passed": self.passed,
                "pass_rate": self.pass_rate, "counts": self.counts, "seed": self.seed,
                "spreads": {"mass_rel": self.spreads.mass_rel, "com_m": self.spreads.com_m,
                            "inertia_rel": self.spreads.inertia_rel,
                            "motor_constant_rel": self.spreads.motor_constant_rel},
                "worst": self.worst}


def robustness_batch(params: VehicleParams, n_vehicles: int, config: HoverConfig = HoverConfig(),
                     spreads: Spreads = Spreads(), seed: int | None = 0, n_worst: int = 5,
                     design: ControllerDesign = ControllerDesign(),
                     progress: Callable[[int], None] | None = None) -> BatchReport:
    """Fly `n_vehicles` perturbed copies of `params`; pass rate and the worst cases."""
    perturbation = sample_perturbations(n_vehicles, params.n_rotors, spreads, seed)
    outcome = simulate_batch(params, config, perturbed_plant(params, perturbation), design,
                             progress)
    passed = outcome.status_code == STATUS_CODES[ExitStatus.PASSED]
    counts: dict[str, int] = {}
    for code in outcome.status_code:
        name = STATUS_FROM_CODE[int(code)].value
        counts[name] = counts.get(name, 0) + 1
    # Worst: failures first (earliest end first), then passes by latest settling.
    order = sorted(range(n_vehicles), key=lambda i: (
        bool(passed[i]), float(outcome.end_time_s[i]) if not passed[i] else
        -float(outcome.settle_time_s[i])))
    worst = []
    for i in order[:n_worst]:
        worst.append({
            "index": i,
            "status": outcome.status(i).value,
            "message": outcome.message(i, params.rotor_names),
            "mass_kg": float(params.mass_kg * perturbation.mass_scale[i]),
            "com_shift_m": [float(v) for v in perturbation.com_shift_m[:, i]],
            "inertia_scale": [float(v) for v in perturbation.inertia_scale[:, i]],
            "motor_constant_scale": [float(v) for v in perturbation.motor_scale[:, i]],
            "max_position_error_m": float(outcome.max_position_error_m[i]),
            "max_attitude_error_deg": float(outcome.max_attitude_error_deg[i]),
            "settle_time_s": _finite_or_none(float(outcome.settle_time_s[i])),
        })
    return BatchReport(n_vehicles, int(passed.sum()), counts, worst, spreads, seed)


def _finite_or_none(value: float) -> float | None:
    return value if math.isfinite(value) else None
