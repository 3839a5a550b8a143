"""The flight equations are one source: the generated engines compute what equations.py's
functions compute, bit for bit.

The reference is equations.py itself, run by the Python interpreter on floats, vehicle by
vehicle. The float engine's step (`scalar`) and the numpy batch's (`columns`) are traced
from it; the tracer folds constants and drops terms only where that is exact for finite
values (x * 0, x * 1, x + 0, x - x, a + (-b)), and numpy's and math's +, -, *, / and sqrt
are both IEEE correctly rounded, so the results must be equal, not close. A tracer that
dropped, reordered or re-associated a term would differ in the last bits.
"""

from __future__ import annotations

import numpy as np
import pytest
from test_sim import tilted_hex

from reedtool.sim import HoverConfig, columns, equations, layout
from reedtool.sim.batch import Spreads, perturbed_plant, sample_perturbations
from reedtool.sim.controller import ControllerGains
from reedtool.sim.layout import ERROR, ROTATION, as_constants, state_names
from reedtool.sim.scalar import step_lines
from reedtool.sim.params import symmetric_multirotor

VEHICLES = {"quad": lambda: symmetric_multirotor(4), "tilted-hex": tilted_hex,
            "racing-lead": lambda: symmetric_multirotor(4, time_constant_up_s=0.08,
                                                        time_constant_down_s=0.12)}


def random_states(n_rotors: int, count: int, seed: int) -> np.ndarray:
    """States near a disturbed hover: metres off, tilted, turning (|w| below the series'
    range of equations.cot_ratio, as in flight), rotors around the trim; some saturate."""
    rng = np.random.default_rng(seed)
    x = np.zeros((count, 16 + n_rotors))
    x[:, 0:3] = rng.normal(scale=0.15, size=(count, 3)) + [0.0, 0.0, 2.0]
    x[:, 3:6] = rng.normal(scale=0.2, size=(count, 3))
    q = rng.normal(size=(count, 4)) * [0.0, 0.06, 0.06, 0.004] + [1.0, 0.0, 0.0, 0.0]
    x[:, 6:10] = q / np.linalg.norm(q, axis=1, keepdims=True)
    x[:, 10:13] = rng.normal(scale=[0.5, 0.5, 0.05], size=(count, 3))
    x[:, 13:16] = rng.normal(scale=0.1, size=(count, 3))
    x[:, 16:] = rng.uniform(300.0, 800.0, size=(count, n_rotors))
    return x


def by_the_equations(the, j: int, state: np.ndarray):
    """control_state then advance_state run by the interpreter on floats."""
    n = len(the.thrust_max)
    x = [float(v) for v in state]
    R, e, T = [0.0] * 9, [0.0] * 3, [0.0] * n
    saturated, worst = equations.control_state(as_constants(the.ctl), as_constants(the.pinv),
                                               as_constants(the.thrust_max), as_constants(the.setpoint),
                                               x, R, e, T)
    controlled = (*R, *e, *T, saturated, worst if saturated else 0)
    equations.advance_state(as_constants(the.vehicle(j)), x, T, R, e)
    return controlled, tuple(x)


@pytest.mark.parametrize("name", sorted(VEHICLES))
def test_traced_float_step_is_the_equations_bit_for_bit(name):
    params = VEHICLES[name]()
    gains = ControllerGains.from_params(params)
    config = HoverConfig()
    setpoint = (0.0, 0.0, config.hover_altitude_m)
    namespace: dict = {}
    before, after = step_lines(params, gains, config, setpoint, namespace)
    n = params.n_rotors
    names = state_names(n)
    controlled = [*ROTATION, *ERROR, *(f"T{i}" for i in range(n)), "saturated", "worst"]
    body = "\n".join("    " + line for line in [*before, f"c = ({', '.join(controlled)},)",
                                                 *after, f"return c, ({', '.join(names)},)"])
    exec(f"def step({', '.join(names)}):\n{body}\n", namespace)
    import math
    namespace.update(sqrt=math.sqrt, tan=math.tan)
    the = layout.inputs(params, gains, config, setpoint_m=setpoint)
    states = random_states(n, 200, seed=4)
    saturating = 0
    for state in states:
        got = namespace["step"](*state)
        want = by_the_equations(the, 0, state)
        assert got == want
        saturating += bool(want[0][-2])
    # the states exercise the desaturation as well as the plain allocation
    assert 10 < saturating < 190
    if name == "racing-lead":
        assert gains.has_motor_lead


@pytest.mark.parametrize("name", ["quad", "tilted-hex"])
def test_column_step_is_the_equations_bit_for_bit(name):
    """The numpy batch's step, on perturbed vehicles (mass, inertia, COM, motors per
    column), against each vehicle's equations run alone."""
    params = VEHICLES[name]()
    gains = ControllerGains.from_params(params)
    config = HoverConfig()
    N = 64
    plant = perturbed_plant(params, sample_perturbations(
        N, params.n_rotors, Spreads(mass_rel=0.3, com_m=0.03, inertia_rel=0.2,
                                    motor_constant_rel=0.15), 5))
    control, advance = columns.build(params, gains, config, plant)
    the = layout.inputs(params, gains, config, plant)
    states = random_states(params.n_rotors, N, seed=9)
    rows = list(states.T.copy())
    out = control(*rows)
    n = params.n_rotors
    saturated = out[12 + n]
    worst = out[13 + n]
    new = advance(*rows, *out[12:12 + n], *out[0:9], *out[9:12])
    for j in range(N):
        want_controlled, want_state = by_the_equations(the, j, states[j])
        got_controlled = (*(float(np.broadcast_to(v, (N,))[j]) for v in out[:12 + n]),
                          bool(saturated[j]) if saturated is not None else False,
                          int(worst[j]) if saturated is not None else 0)
        assert got_controlled == want_controlled
        assert tuple(float(np.broadcast_to(v, (N,))[j]) for v in new) == want_state
    assert saturated is not None and 0 < saturated.sum() < N


# ------------------------------------------------------------------ the judge

def judged_samples(n_rotors: int, config: HoverConfig, count: int, seed: int):
    """(t, state, saturated, worst, J) samples that hit every ending of
    equations.judge_sample, some several at once (the first in its order must win), some
    exactly at a threshold (which must not end the flight), with records J mid-flight:
    saturated streaks running or not, inside the band or not."""
    rng = np.random.default_rng(seed)
    states = random_states(n_rotors, count, seed)
    samples = []
    for i, x in enumerate(states):
        kind = i % 10
        if kind == 1:       # non-finite: NaN or an infinity in p, q or w
            x[rng.choice([0, 1, 2, 6, 7, 8, 9, 10, 11, 12])] = rng.choice(
                [np.nan, np.inf, -np.inf])
        elif kind == 2:     # flipped: rolled past 90 degrees
            roll = rng.uniform(0.55, 1.0) * np.pi
            x[6:10] = [np.cos(roll / 2), np.sin(roll / 2), 0.0, 0.0]
        elif kind == 3:     # ground
            x[2] = -rng.uniform(0.0, 0.5)
        elif kind == 4:     # yaw spin, or exactly at the limit (not an ending)
            x[12] = rng.choice([-1.0, 1.0]) * config.yaw_spin_rad_s * rng.choice([1.0, 1.3])
        elif kind == 5:     # drifted
            x[0] += config.divergence_distance_m * rng.uniform(1.01, 2.0)
        elif kind == 6:     # roll/pitch rate, or exactly at the limit
            x[10] = config.diverged_rate_rad_s * rng.choice([1.0, 1.5])
        elif kind == 7:     # several at once: ground, yaw spin, drifted and rate
            x[2] = -0.2 - config.divergence_distance_m
            x[12] = 2.0 * config.yaw_spin_rad_s
            x[10] = 2.0 * config.diverged_rate_rad_s
        elif kind == 8:     # inside the band: the record's `within` and last-out paths
            x[0:3] = [0.0, 0.0, config.hover_altitude_m] + rng.normal(scale=0.01, size=3)
            x[6:10] = [1.0, 0.0, 0.0, 0.0]
        elif kind == 9:     # level, exactly on the band's edge: sqrt(tol^2) is tol
            x[0:3] = [config.position_tol_m, 0.0, config.hover_altitude_m]
            x[6:10] = [1.0, 0.0, 0.0, 0.0]
        t = 0.01 * rng.integers(1, 1000)
        J = [rng.uniform(0.0, 2.0), rng.uniform(0.5, 1.0), rng.uniform(0.5, 1.0),
             rng.uniform(0.0, 1.0), rng.uniform(0.5, 1.0), rng.uniform(0.0, t),
             float(rng.integers(2)), rng.choice([np.nan, rng.uniform(0.0, t)]),
             float(rng.integers(n_rotors)), rng.uniform(0.0, 1.0),
             float(rng.integers(n_rotors))]
        samples.append((t, x, bool(rng.integers(2)), int(rng.integers(n_rotors)), J))
    return samples


def by_the_judge(config, omega_max, t, x, saturated, worst, J):
    """equations.judge_sample run by the interpreter on floats: (J, reason, value)."""
    R = list(equations.rotation(*(float(v) for v in x[6:10])))
    e = [float(x[a]) - sp for a, sp in enumerate((0.0, 0.0, config.hover_altitude_m))]
    J = [float(v) for v in J]
    reason, value = equations.judge_sample(
        as_constants(layout.judge_settings(config)), as_constants(np.asarray(omega_max)),
        t, [float(v) for v in x], R, e, saturated, worst, J)
    return J, reason, value, R, e


def same(a, b) -> bool:
    """Bit for bit: equal with the same sign, or both NaN."""
    a, b = float(a), float(b)
    return (a != a and b != b) or (a == b and np.copysign(1.0, a) == np.copysign(1.0, b))


def test_traced_float_judge_is_the_equations_bit_for_bit():
    """The float engine's judge (scalar.judge_lines, inside its generated fly) against
    equations.judge_sample run by the interpreter, on samples hitting every ending."""
    import math

    from reedtool.sim.layout import JUDGE
    from reedtool.sim.scalar import judge_lines

    params = VEHICLES["tilted-hex"]()
    config = HoverConfig()
    n = params.n_rotors
    namespace: dict = {"sqrt": math.sqrt, "acos": math.acos, "degrees": math.degrees,
                       "isfinite": math.isfinite, "fabs": math.fabs, "nan": math.nan}
    lines = judge_lines(params.omega_max_rad_s, config)
    args = ["t", *state_names(n), *ROTATION, *ERROR, "saturated", "worst", *JUDGE]
    body = "\n".join("    " + line for line in
                     [*lines, f"return ({', '.join(JUDGE)},), reason, value"])
    exec(f"def judge({', '.join(args)}):\n{body}\n", namespace)
    reasons = set()
    for t, x, saturated, worst, J in judged_samples(n, config, 450, seed=3):
        want_J, want_reason, want_value, R, e = by_the_judge(
            config, params.omega_max_rad_s, t, x, saturated, worst, J)
        got_J, got_reason, got_value = namespace["judge"](t, *(float(v) for v in x), *R, *e,
                                                          saturated, worst, *J)
        assert got_reason == want_reason
        assert same(got_value, want_value), (want_reason, got_value, want_value)
        assert all(same(a, b) for a, b in zip(got_J, want_J)), (got_J, want_J)
        reasons.add(want_reason)
    # the band's edge is inside it (the record says so)
    edge = [state for _, state, *_ in judged_samples(n, config, 450, seed=3)][9]
    assert edge[0] == config.position_tol_m
    # every ending, and flying on
    assert reasons == {0, equations.NON_FINITE, equations.FLIPPED, equations.GROUND,
                       equations.YAW_SPIN, equations.DRIFTED, equations.RATE}


def verdict_records(config: HoverConfig, count: int, seed: int) -> list[list[float]]:
    """Records J at the end of a run: inside the band or not, the last time outside it at
    and around the hold boundary, saturated streaks at and around the limit."""
    rng = np.random.default_rng(seed)
    sample_dt = config.sample_every * config.dt_s
    boundary = config.duration_s - config.hold_s - sample_dt
    records = []
    for _ in range(count):
        J = [0.3, 0.9, 0.8, 0.01, 0.99, 0.0, 0.0, np.nan, 1.0, 0.0, 2.0]
        J[6] = float(rng.integers(2))
        J[5] = boundary + rng.choice([0.0, -sample_dt, sample_dt, 1e-10, 2e-9, -3.0])
        J[9] = config.saturation_limit_s + rng.choice([0.0, -5e-10, -2e-9, 1.0, -1.0])
        J[10] = float(rng.integers(4))
        records.append(J)
    return records


@pytest.mark.parametrize("name", ["quad", "tilted-hex"])
def test_column_judge_is_the_equations_bit_for_bit(name):
    """The numpy batch's judge, verdict and settle time (columns.build_judge) against
    equations' run by the interpreter, vehicle by vehicle."""
    params = VEHICLES[name]()
    config = HoverConfig()
    n = params.n_rotors
    judge, verdict, settle = columns.build_judge(params.omega_max_rad_s, config)
    jc = as_constants(layout.judge_settings(config))
    samples = judged_samples(n, config, 450, seed=11)
    t = samples[0][0]       # one time for the batch
    X = np.array([x for _, x, _, _, _ in samples]).T
    Jrows = np.array([J for *_, J in samples]).T
    saturated = np.array([s for _, _, s, _, _ in samples])
    worst = np.array([w for *_, w, _ in samples])
    wants = [by_the_judge(config, params.omega_max_rad_s, t, x, s, w, J)
             for _, x, s, w, J in samples]
    R = np.array([want[3] for want in wants]).T
    e = np.array([want[4] for want in wants]).T
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        *got_J, got_reason, got_value = judge(t, *X, *R, *e, saturated, worst, *Jrows)
    N = len(samples)
    for j, (want_J, want_reason, want_value, _, _) in enumerate(wants):
        assert int(np.broadcast_to(got_reason, (N,))[j]) == want_reason
        assert same(np.broadcast_to(got_value, (N,))[j], want_value)
        assert all(same(np.broadcast_to(g, (N,))[j], w) for g, w in zip(got_J, want_J))
    assert len(set(want[1] for want in wants)) == 7
    # at the end of the run: the verdict and the settle time
    records = verdict_records(config, 300, seed=2)
    rows = np.array(records).T
    with np.errstate(invalid="ignore"):
        why, value = verdict(*rows)
    endings = set()
    for j, J in enumerate(records):
        want_reason, want_value = equations.verdict(jc, J)
        assert int(np.broadcast_to(why, (len(records),))[j]) == want_reason
        assert same(np.broadcast_to(value, (len(records),))[j], want_value)
        endings.add(want_reason)
    assert endings == {equations.SETTLED, equations.SATURATED, equations.NOT_SETTLED}
    reasons = np.array([equations.verdict(jc, J)[0] if j % 3 else equations.GROUND
                        for j, J in enumerate(records)])
    with np.errstate(invalid="ignore"):
        got = np.broadcast_to(settle(reasons, *rows)[0], (len(records),))
    for j, J in enumerate(records):
        assert same(got[j], equations.settle_time(jc, int(reasons[j]), J))
