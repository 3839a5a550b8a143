"""One vehicle in plain Python floats, generated from the flight equations.

For one vehicle numpy's per-call overhead would dominate, so `run` steps the hover
simulation with scalar arithmetic: the step is `equations.control_state` and
`equations.advance_state` traced once with the vehicle's numbers (`trace`): rotors
unrolled, constants folded into literals, every term whose coefficient is exactly 0
dropped, the desaturation called as the function itself when its guard holds. So this
engine flies the same equations as the compiled one by construction.

`compile_vehicle` returns `fly(state, rec)`, which flies the whole run from `state`
(STATE order, then the rotor speeds) and judges it every `config.sample_every` steps by
`equations.judge_sample`, traced the same way (`judge_lines`), and at the end by
`equations.verdict`; `rec`, if not None, is called with each sample
(t, x, y, z, R00, R10, R20, R21, R22, position error, cos(attitude error), *omega). It
returns a Flight tuple: why it ended (equations' reason code) and what the judge tracked;
`run` turns that into a HoverRun.
"""

from __future__ import annotations

import functools
import math
from typing import Callable, NamedTuple

from reedtool.sim import equations, layout
from reedtool.sim.layout import (ERROR, JUDGE, ROTATION, STATE, as_constants, judge_settings,
                                 state_names)
from reedtool.sim.trace import Sym, Trace, Writer, leaf, literal

class Flight(NamedTuple):
    """What `fly` returns: how the run ended (equations' judge) and what the judge tracked
    on the samples."""

    reason: int                 # equations' reason code (batch.REASONS[reason])
    value: float                # the number that ended it (a rotor for "saturated")
    end_time_s: float
    settle_time_s: float        # NaN when it never settled
    max_position_error_m: float
    min_cos_attitude: float
    max_throttle: float
    longest_saturation_s: float
    position_error_m: float     # at the last sample
    cos_attitude: float
    omega_rad_s: tuple
    state: tuple                # p, v, q, w and the rotor speeds at the end


def compile_vehicle(params, gains, config, setpoint_m: tuple[float, float, float],
                    plant=None, vehicle: int = 0, judge_omega_max=None) -> Callable:
    """`fly` for `params` flown by `gains` as `config` says, towards `setpoint_m`; the
    plant is vehicle `vehicle` of `plant` (default: the nominal one). The judge reads the
    throttle against `judge_omega_max` (default: params')."""
    namespace: dict = {}
    source = _source(params, gains, config, setpoint_m, namespace, plant, vehicle,
                     params.omega_max_rad_s if judge_omega_max is None else judge_omega_max)
    namespace.update({"sqrt": math.sqrt, "tan": math.tan, "acos": math.acos,
                      "degrees": math.degrees, "isfinite": math.isfinite, "fabs": math.fabs,
                      "nan": math.nan, "Flight": Flight, "verdict": equations.verdict,
                      "settle_time": equations.settle_time})
    exec(_compiled(source, params.n_rotors), namespace)
    return namespace["fly"]


@functools.lru_cache(maxsize=8)
def _compiled(source: str, n_rotors: int):
    # Compiling is most of the set-up time; the same vehicle flown again (tests, a
    # benchmark's repeats) reuses the code.
    return compile(source, f"<reedtool.sim.scalar step, {n_rotors} rotors>", "exec")


def step_lines(params, gains, config, setpoint_m, namespace: dict, plant=None,
               vehicle: int = 0) -> tuple[list, list]:
    """(before, after): one step traced into statements, from the state named by STATE
    and om<i>. `before` runs equations.control_state (into ROTATION, ERROR, T<i>,
    `saturated`, `worst`) and computes equations.advance_state; `after` sets the new
    state. Traced together, so what both compute (w x J w) is computed once. Constants
    that are not numbers go into `namespace`. The plant: vehicle `vehicle` of `plant`
    (default: the nominal one)."""
    the = layout.inputs(params, gains, config, plant, setpoint_m=setpoint_m)
    n = params.n_rotors
    names = state_names(n)
    ctl, pinv, thrust_max, sp = (as_constants(v) for v in (the.ctl, the.pinv, the.thrust_max,
                                                          the.setpoint))
    trace = Trace()
    x = [leaf(name) for name in names]
    R, e, T = [0.0] * 9, [0.0] * 3, [0.0] * n
    saturated, worst = trace.control_state(ctl, pinv, thrust_max, sp, x, R, e, T)
    writer = Writer(namespace)
    for call in trace.guarded:
        for i, t in enumerate(call.args[-n:]):
            if isinstance(t, Sym):
                writer.name(t, f"T{i}")
        writer.name_results(call, "saturated", "worst")
    for target, value in [*zip(ROTATION, R), *zip(ERROR, e),
                          *((f"T{i}", t) for i, t in enumerate(T)),
                          ("saturated", saturated), ("worst", worst)]:
        if isinstance(value, Sym) and value.op not in ("leaf", "out"):
            writer.name(value, target)
        writer.assign(target, value, early=True)
    trace.advance_state(as_constants(the.vehicle(vehicle)), x, T, R, e)
    for target, value in zip(names, x):
        writer.assign(target, value)
    return writer.lines(split=True)


def judge_lines(omega_max, config) -> list[str]:
    """equations.judge_sample traced into statements: from the state (STATE, om<i>),
    ROTATION, ERROR, `t`, `saturated`, `worst` and the record J (layout.JUDGE), into J,
    `reason` and `value`. Its intermediate names start with `_j` (it runs between the
    step's two halves)."""
    return list(_judge_lines(tuple(float(w) for w in omega_max),
                             as_constants(judge_settings(config))))


@functools.lru_cache(maxsize=8)
def _judge_lines(omega_max: tuple, jc: tuple) -> tuple:
    # Traced once per vehicle and settings (a run's set-up would trace it again).
    n = len(omega_max)
    trace = Trace()
    x = [leaf(name) for name in state_names(n)]
    J = [leaf(name) for name in JUDGE]
    reason, value = trace.judge_sample(
        jc, omega_max, leaf("t"), x, [leaf(name) for name in ROTATION],
        [leaf(name) for name in ERROR], leaf("saturated"), leaf("worst"), J)
    writer = Writer({}, prefix="_j")
    for target, out in [*zip(JUDGE, J), ("reason", reason), ("value", value)]:
        writer.assign(target, out)
    return tuple(writer.lines())


def _source(params, gains, config, setpoint_m, namespace: dict, plant, vehicle,
            judge_omega_max) -> str:
    n = params.n_rotors
    om = [f"om{i}" for i in range(n)]
    before, after = step_lines(params, gains, config, setpoint_m, namespace, plant, vehicle)
    L = literal
    start = [0.0] * equations.JUDGE_SIZE
    equations.judge_start(start)
    namespace["jc"] = as_constants(judge_settings(config))
    # the judge, on the state at each sample; `saturated` and `worst` come from the
    # command at that state. An ending on the way returns at once; at the end, the
    # verdict (equations.verdict, run as itself: once a flight).
    judge = [
        "t = step * dt",
        *judge_lines(judge_omega_max, config),
        "if rec is not None:",
        f"    rec((t, px, py, pz, R00, R10, R20, R21, R22, pos, cos_att, {', '.join(om)}))",
        "if reason != 0 or step == n_steps:",
        f"    J = [{', '.join(JUDGE)}]",
        "    if reason == 0:",
        "        reason, value = verdict(jc, J)",
        "    return Flight(reason, value, t, settle_time(jc, reason, J), max_pos, min_cos,",
        f"                  max_throttle, sat_longest, pos, cos_att, ({', '.join(om)},),",
        f"                  ({', '.join(STATE[:13])}, {', '.join(om)}))",
    ]

    def indent(lines, depth):
        return "\n".join(" " * depth + line for line in lines)

    return "\n".join([
        "def fly(state, rec):",
        f"    ({', '.join(STATE)}, ({', '.join(om)},)) = state",
        f"    dt = {L(config.dt_s)}; n_steps = {config.n_steps}; every = {config.sample_every}",
        "    worst = 0",
        f"    {', '.join(JUDGE)} = {', '.join(L(v) for v in start)}",
        "    next_sample = 0",
        "    for step in range(n_steps + 1):",
        indent(before, 8),
        "        if step == next_sample:",      # every `every` steps, and the last
        "            next_sample = next_sample + every if next_sample + every < n_steps "
        "else n_steps",
        indent(judge, 12),
        indent(after, 8),
        "",
    ])
