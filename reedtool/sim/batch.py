"""The vectorised engine: N vehicles advanced by one array step, and the robustness batch.

Every vehicle is a column; one loop iteration steps all of them with numpy (no Python loop
per vehicle): the step is the flight equations traced over arrays (`columns`), the same
trace as the single-vehicle float engine's (`scalar`), so the two fly the same arithmetic.
The robustness batch perturbs the plant (mass, inertia, COM, per-motor constants) and
flies every vehicle on the controller designed for the nominal model, as a real airframe
is flown on the model it was tuned from. The judge of a flight is equations' too
(`judge_sample`, `verdict`, `settle_time`), traced over the columns (`columns.build_judge`).
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass
from typing import Callable

import numpy as np

from reedtool.io.json_values import finite_or_none
from reedtool.sim import STATUS_CODES, STATUS_FROM_CODE, ExitStatus, HoverConfig
from reedtool.sim import columns, equations
from reedtool.sim.controller import ControllerDesign, ControllerGains
from reedtool.sim.dynamics import Plant, State, quat_from_rpy
from reedtool.sim.layout import hover_speeds
from reedtool.sim.params import VehicleParams

# Why a run ended, beyond its ExitStatus: REASONS[code] (equations' judge).
REASONS = equations.REASONS

STATUS_OF_REASON = {
    "settled": ExitStatus.PASSED, "not-settled": ExitStatus.NOT_SETTLED,
    "saturated": ExitStatus.SATURATED, "non-finite": ExitStatus.DIVERGED,
    "drifted": ExitStatus.DIVERGED, "rate": ExitStatus.DIVERGED,
    "ground": ExitStatus.CRASHED, "flipped": ExitStatus.CRASHED,
    "yaw-spin": ExitStatus.YAW_SPIN}
# status code by reason code (0: still flying)
_STATUS_CODE = np.array([0, *(STATUS_CODES[STATUS_OF_REASON[r]] for r in REASONS[1:])],
                        dtype=np.int64)


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
    # (samples, N) position error at every sample while the vehicle ran (NaN after it
    # ended), when asked for (`record=True`); None otherwise
    position_error_m: np.ndarray | None = None

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
                  n_vehicles: int, omega0: np.ndarray | None = None) -> tuple[State, np.ndarray]:
    """Disturbed start with the rotors at the nominal trim speeds (or `omega0`); also the
    setpoint (3,)."""
    N = n_vehicles
    setpoint = np.array([0.0, 0.0, config.hover_altitude_m])
    p0 = setpoint + np.asarray(config.offset_m, dtype=float)
    q0 = quat_from_rpy(config.roll_rad, config.pitch_rad, config.yaw_rad)
    omega0 = hover_speeds(params, gains) if omega0 is None else np.asarray(omega0, dtype=float)
    state = State(p=np.repeat(p0[:, None], N, axis=1), v=np.zeros((3, N)),
                  q=np.repeat(q0[:, None], N, axis=1), w=np.zeros((3, N)),
                  omega=np.repeat(omega0[:, None], N, axis=1))
    return state, setpoint


def simulate_batch(params: VehicleParams, config: HoverConfig = HoverConfig(),
                   plant: Plant | None = None, design: ControllerDesign = ControllerDesign(),
                   progress: Callable[[int], None] | None = None,
                   engine: str = "numpy", record: bool = False,
                   gains: ControllerGains | None = None,
                   initial_omega_rad_s: np.ndarray | None = None,
                   command: SpeedCommand | None = None) -> Outcome:
    """Fly every vehicle of `plant` (default: one nominal vehicle) on the nominal controller.

    `progress(steps)` is called now and then with the number of steps done since the last call.
    `engine`: "numpy" (this loop) or "numba" (`compiled`, across the cores).
    `gains` and `initial_omega_rad_s` override the designed controller and the starting
    rotor speeds, as in run.simulate_hover (sim.failure: the flight after a rotor fails);
    the numpy engine flies those. `command` replaces the controller and its allocation by
    another that commands rotor speeds itself (sim.lee_rotors: RotorS' Lee controller);
    the numpy engine only, from `initial_omega_rad_s`.
    """
    config.validate()
    plant = plant or Plant.from_params(params, 1)
    if engine == "numba":
        if gains is not None or initial_omega_rad_s is not None:
            raise ValueError("the compiled engine flies the designed controller from trim")
        outcome = _simulate_compiled(params, config, plant, design, record)
        if progress is not None:
            progress(config.n_steps)
        return outcome
    if command is not None and initial_omega_rad_s is None:
        raise ValueError("a speed command flies from the speeds it starts with")
    if gains is None and command is None:
        gains = ControllerGains.from_params(params, design)
    N, n = plant.n_vehicles, params.n_rotors
    dt = config.dt_s
    state, setpoint = initial_state(params, gains, config, N, initial_omega_rad_s)
    # The state as rows of one array, in equations' layout; `state` views into it.
    X = np.zeros((16 + n, N))
    X[0:3], X[3:6], X[6:10], X[10:13], X[16:] = state.p, state.v, state.q, state.w, state.omega
    state = State(p=X[0:3], v=X[3:6], q=X[6:10], w=X[10:13], omega=X[16:])
    rows = list(X)
    omega_park = state.omega[:, 0].copy()
    q_park = np.array([1.0, 0.0, 0.0, 0.0])
    control, advance = columns.build(
        params, gains if gains is not None else ControllerGains.from_params(params, design),
        config, plant, speed_command=command is not None)
    R9 = np.empty((9, N))
    if command is not None:
        omega_cmd = np.empty((n, N))
        speed_command_step = command(state, R9, setpoint, omega_cmd)

    judge, verdict, settle_time = columns.build_judge(
        params.omega_max_rad_s if command is not None else gains.omega_max_rad_s, config)
    reason = np.zeros(N, dtype=np.int64)
    reason_value = np.zeros(N)
    end_time = np.full(N, config.duration_s)
    # the judge's record J (equations' layout), one row per field
    start = [0.0] * equations.JUDGE_SIZE
    equations.judge_start(start)
    J = [np.full(N, v) for v in start]
    n_steps = config.n_steps
    every = config.sample_every
    report_every = max(1, n_steps // 100)
    recorded: list[np.ndarray] = []
    reported = 0

    # where() computes both sides of a select: the unused one may warn (sqrt of a
    # negative thrust command, a tumbling vehicle's tangent); the judge ends what is
    # not finite.
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        for step in range(n_steps + 1):
            t = step * dt
            last = step == n_steps
            sample = step % every == 0 or last
            if command is None:
                out = control(*rows)
                R_rows, e_rows, u = out[0:9], out[9:12], out[12:12 + n]
                saturated, worst_rotor = out[12 + n], out[13 + n]
            else:
                R_rows, e_rows = equations.rotation(*rows[6:10]), ()
            for k in range(9):
                R9[k] = R_rows[k]
            if command is not None:
                saturated, worst_rotor = speed_command_step(step, sample)
                u = list(omega_cmd)
            if sample:
                # ---- judge every running vehicle on the state at time t
                # (equations.judge_sample over the columns; the ended keep their record)
                running = reason == 0
                all_running = running.all()
                *judged, why, value = judge(
                    t, *rows, *R9, *(X[0:3] - setpoint[:, None]),
                    False if saturated is None else saturated,
                    0 if worst_rotor is None else worst_rotor, *J)
                if record:
                    recorded.append(np.where(running, judged[3], np.nan))
                J = judged if all_running else [np.where(running, new, old)
                                                for new, old in zip(judged, J)]
                ended = running & (why != 0)
                if ended.any():
                    reason[ended] = why[ended]
                    reason_value[ended] = value[ended]
                    end_time[ended] = t
                if last:
                    rest = reason == 0
                    why, value = verdict(*J)
                    reason[rest] = np.broadcast_to(why, (N,))[rest]
                    reason_value[rest] = np.broadcast_to(value, (N,))[rest]
                    break
                if ended.any():
                    # Park finished vehicles at a level hover so they stay finite and cheap.
                    X[0:3, ended] = setpoint[:, None]
                    X[3:6, ended] = 0.0
                    X[6:10, ended] = q_park[:, None]
                    X[10:16, ended] = 0.0
                    X[16:, ended] = omega_park[:, None]
                    if (reason != 0).all():
                        break
            # ---- advance all vehicles one step (equations.advance_state, or
            # advance_plant under a speed command)
            for k, row in enumerate(advance(*rows, *u, *R_rows, *e_rows)):
                X[k] = row
            if progress is not None and step - reported >= report_every:
                progress(step - reported)
                reported = step
    if progress is not None and n_steps > reported:
        progress(n_steps - reported)

    # Time each vehicle entered the band for good; NaN when it ended early or outside it.
    with np.errstate(invalid="ignore"):
        settle = np.broadcast_to(settle_time(reason, *J)[0], (N,)).astype(float)
    J = [np.array(np.broadcast_to(row, (N,)), dtype=float) for row in J]
    max_pos, min_cos_att, max_throttle, final_pos, final_cos = J[0], J[1], J[2], J[3], J[4]
    sat_longest = J[9]
    status = _STATUS_CODE[reason]
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
        final_state=state, config=config,
        position_error_m=_samples(recorded, config, N) if record else None)


# `command(state, R9, setpoint, omega_cmd)` -> `step(step_index, sample)`: writes the rotor
# speed command (n, N), within [0, omega_max], into omega_cmd for the state at that step;
# returns (saturated (N,) bool or None, most-out-of-range rotor (N,) int or None) as the
# allocation does.
SpeedCommand = Callable[[State, np.ndarray, np.ndarray, np.ndarray],
                        Callable[[int, bool], tuple]]


def simulate_one_by_one(params: VehicleParams, config: HoverConfig, plant: Plant,
                         design: ControllerDesign, progress: Callable[[int], None] | None,
                         record: bool) -> Outcome:
    """simulate_batch's Outcome, each vehicle flown on its own traced float step
    (`scalar`, the same equations and judge): for a few vehicles, faster than columns
    that pay numpy's per-call overhead at every step (FLOAT_ENGINE_MAX_VEHICLES)."""
    from reedtool.sim.scalar import compile_vehicle

    gains = ControllerGains.from_params(params, design)
    N, n = plant.n_vehicles, params.n_rotors
    state, setpoint = initial_state(params, gains, config, N)
    omega0 = tuple(float(w) for w in state.omega[:, 0])
    start = (*(float(v) for v in (*state.p[:, 0], *state.v[:, 0], *state.q[:, 0],
                                  *state.w[:, 0])), 0.0, 0.0, 0.0, omega0)
    # an ended vehicle's final state is the level hover it is parked at (as the columns'
    # and numba's batches park them)
    park = (*setpoint, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, *omega0)
    flights, recorded = [], []
    done = 0
    for j in range(N):
        fly = compile_vehicle(params, gains, config, tuple(float(v) for v in setpoint), plant,
                              j, gains.omega_max_rad_s)
        rec: list[tuple] = []
        flight = fly(start, rec.append if record else None)
        flights.append(flight)
        recorded.append([row[9] for row in rec])
        if progress is not None:
            progress(config.n_steps * (j + 1) // N - done)
            done = config.n_steps * (j + 1) // N
    reason = np.array([f.reason for f in flights], dtype=np.int64)
    reached_end = np.isin(reason, [equations.SETTLED, equations.NOT_SETTLED,
                                   equations.SATURATED])
    final = np.array([f.state if reached_end[j] else park for j, f in enumerate(flights)]).T
    final_state = State(p=final[0:3], v=final[3:6], q=final[6:10], w=final[10:13],
                        omega=final[13:13 + n])

    def column(field):
        return np.array([getattr(f, field) for f in flights], dtype=float)

    position_error = None
    if record:
        position_error = _samples([], config, N)
        for j, rows in enumerate(recorded):
            position_error[:len(rows), j] = rows
    return Outcome(
        status_code=_STATUS_CODE[reason], reason=reason, reason_value=column("value"),
        end_time_s=np.where(reached_end, config.duration_s, column("end_time_s")),
        settle_time_s=column("settle_time_s"),
        max_position_error_m=column("max_position_error_m"),
        max_attitude_error_deg=np.degrees(np.arccos(column("min_cos_attitude"))),
        final_position_error_m=column("position_error_m"),
        final_attitude_error_deg=np.degrees(np.arccos(column("cos_attitude"))),
        max_throttle=column("max_throttle"),
        longest_saturation_s=column("longest_saturation_s"),
        final_omega_rad_s=final_state.omega.copy(), final_state=final_state, config=config,
        position_error_m=position_error)


def _samples(recorded: list[np.ndarray], config: HoverConfig, N: int) -> np.ndarray:
    """(samples, N): the recorded rows, NaN-padded to every sample of the full run."""
    rows = config.n_steps // config.sample_every + (config.n_steps % config.sample_every != 0) + 1
    out = np.full((rows, N), np.nan)
    if recorded:
        out[:len(recorded)] = np.array(recorded)
    return out


def _simulate_compiled(params: VehicleParams, config: HoverConfig, plant: Plant,
                       design: ControllerDesign, record: bool = False) -> Outcome:
    """simulate_batch on the compiled kernel: the same Outcome."""
    from reedtool.sim.compiled import fly_batch

    out = fly_batch(params, config, plant, design, record)
    reason = out["reason"]
    status = _STATUS_CODE[reason]
    F = out["final"].T
    state = State(p=F[0:3].copy(), v=F[3:6].copy(), q=F[6:10].copy(), w=F[10:13].copy(),
                  omega=F[13:].copy())
    return Outcome(
        status_code=status, reason=reason, reason_value=out["reason_value"],
        end_time_s=out["end_time_s"], settle_time_s=out["settle_time_s"],
        max_position_error_m=out["max_position_error_m"],
        max_attitude_error_deg=np.degrees(np.arccos(out["min_cos_attitude"])),
        final_position_error_m=out["final_position_error_m"],
        final_attitude_error_deg=np.degrees(np.arccos(out["final_cos_attitude"])),
        max_throttle=out["max_throttle"], longest_saturation_s=out["longest_saturation_s"],
        final_omega_rad_s=state.omega.copy(), final_state=state, config=config,
        position_error_m=out.get("position_error_m"))


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


# Up to this many vehicles the numpy engine flies a robustness batch one vehicle at a
# time on the traced float step (same equations, same judge, same Outcome): numpy's
# columns pay a fixed per-call overhead at every step, which a few vehicles do not fill.
# Measured (benchmarks/bench_hover.py --numpy-vehicles, docs/hover-test.md "Speed").
FLOAT_ENGINE_MAX_VEHICLES = 32


@dataclass
class BatchReport:
    n_vehicles: int
    passed: int
    counts: dict[str, int]
    worst: list[dict]
    spreads: Spreads
    seed: int | None
    engine: str = "numpy"
    # percentiles of the position error over the vehicles still flying, per sample:
    # {"t_s", "p5", "p50", "p95", "flying"} when recorded (for the plot), else None
    envelope: dict[str, np.ndarray] | None = None

    @property
    def pass_rate(self) -> float:
        return self.passed / self.n_vehicles if self.n_vehicles else 0.0

    def to_dict(self) -> dict:
        return {"samples": self.n_vehicles, "passed": self.passed,
                "pass_rate": self.pass_rate, "counts": self.counts, "seed": self.seed,
                "engine": self.engine,
                "spreads": {"mass_rel": self.spreads.mass_rel, "com_m": self.spreads.com_m,
                            "inertia_rel": self.spreads.inertia_rel,
                            "motor_constant_rel": self.spreads.motor_constant_rel},
                "worst": self.worst}


def robustness_batch(params: VehicleParams, n_vehicles: int, config: HoverConfig = HoverConfig(),
                     spreads: Spreads = Spreads(), seed: int | None = 0, n_worst: int = 5,
                     design: ControllerDesign = ControllerDesign(),
                     progress: Callable[[int], None] | None = None,
                     engine: str = "numpy", record: bool = False) -> BatchReport:
    """Fly `n_vehicles` perturbed copies of `params`; pass rate and the worst cases.

    `engine`: "numpy" (this module) or "numba" (`compiled`, all cores).
    """
    perturbation = sample_perturbations(n_vehicles, params.n_rotors, spreads, seed)
    plant = perturbed_plant(params, perturbation)
    if engine == "numpy" and n_vehicles <= FLOAT_ENGINE_MAX_VEHICLES:
        outcome = simulate_one_by_one(params, config, plant, design, progress, record)
    else:
        outcome = simulate_batch(params, config, plant, design, progress, engine, record)
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
            "settle_time_s": finite_or_none(float(outcome.settle_time_s[i])),
        })
    return BatchReport(n_vehicles, int(passed.sum()), counts, worst, spreads, seed, engine,
                       _envelope(outcome.position_error_m, config)
                       if outcome.position_error_m is not None else None)


def _envelope(position_error_m: np.ndarray, config: HoverConfig) -> dict[str, np.ndarray]:
    """5th, 50th and 95th percentile of the position error over the vehicles still
    flying at each sample (NaN where none is)."""
    rows = position_error_m.shape[0]
    steps = np.minimum(np.arange(rows) * config.sample_every, config.n_steps)
    flying = np.isfinite(position_error_m).sum(axis=1)
    out = {"t_s": steps * config.dt_s, "flying": flying}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)     # all-NaN rows: NaN, as meant
        for q in (5, 50, 95):
            out[f"p{q}"] = np.nanpercentile(position_error_m, q, axis=1)
    return out
