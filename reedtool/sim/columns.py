"""The numpy batch's step, traced from the flight equations over arrays of vehicles.

`equations.control_state` and `equations.advance_state` (or `advance_plant`, under a
speed command of another controller) traced once (`trace`) with the nominal vehicle's
numbers as constants and what a robustness batch perturbs per vehicle (mass, inertia
scale, COM shift, motor constants) as named arrays where the vehicles differ: each traced operation becomes one
numpy operation on (N,) arrays, a select becomes `where`, and the desaturation is traced
the same way and runs on the vehicles whose guard holds. The same trace, with everything a
constant, is the float engine's step (`scalar`), so the two fly the same arithmetic.
"""

from __future__ import annotations

import functools
import math

import numpy as np

from reedtool.sim import layout
from reedtool.sim.layout import (ERROR, JUDGE, ROTATION, as_constants, judge_settings,
                                 state_names)
from reedtool.sim.trace import Trace, Writer, leaf

def _function(name: str, args: list[str], lines: list[str], returns: list[str]) -> str:
    body = "\n".join("    " + line for line in lines)
    return (f"def {name}({', '.join(args)}):\n{body}\n"
            f"    return ({', '.join(returns)},)\n")


def build(params, gains, config, plant, speed_command: bool = False) -> tuple:
    """(control, advance) for the vehicles of `plant` flown by `gains`.

    control(*x) -> (R (9), e (3), T (n), saturated (N,) bool or None, worst rotor or None)
    for the state rows x (equations' layout); None under a speed command. advance(*x,
    *u, *R, *e) -> the next state's rows, u the thrusts (or under a speed command: u the
    rotor speed commands, and no e).
    """
    the = layout.inputs(params, gains, config, plant)
    n = params.n_rotors
    names = state_names(n)
    namespace: dict = {"sqrt": np.sqrt, "tan": np.tan, "where": np.where,
                       "logical_or": np.logical_or, "logical_and": np.logical_and}
    per_vehicle = {"mass": the.mass, **{f"S{a}": the.S[:, a] for a in range(3)},
                   **{f"sh{a}": the.shift[:, a] for a in range(3)},
                   **{f"k{i}": the.k[:, i] for i in range(n)}}
    # A value every vehicle shares (all of them for a lone or unperturbed vehicle) is a
    # constant, folded as the float engine folds it; the others are arrays.
    value = {}
    for name, v in per_vehicle.items():
        if np.all(v == v[0]):
            value[name] = float(v[0])
        else:
            namespace[name] = np.ascontiguousarray(v)
            value[name] = leaf(name)
    dt, g, lead, i_max, pos, axis, tmap, cd, cr, J0, dt_J0inv, inv_k, up, down, lead_up, \
        lead_down, omega_max = as_constants(the.nominal)
    veh = (dt, g, value["mass"], lead, i_max, pos, axis, tmap, cd, cr,
           [value[f"k{i}"] for i in range(n)], [value[f"sh{a}"] for a in range(3)],
           [value[f"S{a}"] for a in range(3)], J0, dt_J0inv, inv_k, up, down, lead_up,
           lead_down, omega_max)
    control = None
    if not speed_command:
        trace = Trace()
        x = [leaf(name) for name in names]
        R, e, T = [0.0] * 9, [0.0] * 3, [0.0] * n
        ctl, pinv, thrust_max, sp = (as_constants(v) for v in (the.ctl, the.pinv,
                                                              the.thrust_max, the.setpoint))
        saturated, worst = trace.control_state(ctl, pinv, thrust_max, sp, x, R, e, T)
        writer = Writer(namespace, columns=True)
        for call in trace.guarded:
            writer.name_results(call, "saturated", "worst")
        outputs = [*zip(ROTATION, R), *zip(ERROR, e), *((f"T{i}", t) for i, t in enumerate(T)),
                   ("saturated", saturated), ("worst", worst)]
        for target, value in outputs:
            writer.assign(target, value)
        source = _function("control", names, writer.lines(), [t for t, _ in outputs])
        exec(compile(source, "<reedtool.sim.columns control>", "exec"), namespace)
        control = namespace["control"]
        # what equations.desaturate does where its guard holds, traced over columns
        trace = Trace()
        wrench = [leaf(name) for name in ("f", "t0", "t1", "t2")]
        T = [leaf(f"T{i}") for i in range(n)]
        worst = trace.most_out_of_range(list(T), thrust_max)
        trace.prioritised(pinv, thrust_max, *wrench, T)
        writer = Writer(namespace, columns=True)
        for target, value in [("worst", worst), *((f"T{i}", t) for i, t in enumerate(T))]:
            writer.assign(target, value)
        source = _function("desaturate_columns", ["f", "t0", "t1", "t2",
                                                  *(f"T{i}" for i in range(n))],
                           writer.lines(), ["worst", *(f"T{i}" for i in range(n))])
        exec(compile(source, "<reedtool.sim.columns desaturate>", "exec"), namespace)
    trace = Trace()
    x = [leaf(name) for name in names]
    u = [leaf(f"u{i}") for i in range(n)]
    R = [leaf(name) for name in ROTATION]
    if speed_command:
        trace.advance_plant(veh, x, u, R)
        args = [*names, *(f"u{i}" for i in range(n)), *ROTATION]
    else:
        trace.advance_state(veh, x, u, R, [leaf(name) for name in ERROR])
        args = [*names, *(f"u{i}" for i in range(n)), *ROTATION, *ERROR]
    writer = Writer(namespace, columns=True)
    for target, value in zip(names, x):
        writer.assign(target, value)
    source = _function("advance", args, writer.lines(), names)
    exec(compile(source, "<reedtool.sim.columns advance>", "exec"), namespace)
    return control, namespace["advance"]



def _acos(x):
    """math.acos over an array: numpy's arccos differs from it in the last bit (its own
    approximation), and the judge's numbers are equations' to the bit; NaN outside
    [-1, 1] as numpy's. The judge asks it acos(0) for every vehicle that is not flipped
    (equations.tilt_deg): those are one value, the rest one call each."""
    x = np.asarray(x, dtype=float)
    out = np.full(x.shape, math.acos(0.0))
    other = np.flatnonzero(x != 0.0)
    out.flat[other] = [math.acos(v) if -1.0 <= v <= 1.0 else math.nan
                       for v in x.flat[other].tolist()]
    return out


def build_judge(omega_max, config) -> tuple:
    """(judge, verdict, settle): equations.judge_sample, verdict and settle_time traced
    over arrays of vehicles.

    judge(t, *x, *R, *e, saturated, worst, *J) -> (*J, reason, value) for the state rows
    x, the rotation R, the position error e and the record J (layout.JUDGE); verdict(*J)
    -> (reason, value); settle(reason, *J) -> the settle times.
    """
    return _judge_functions(tuple(float(w) for w in omega_max),
                            as_constants(judge_settings(config)))


@functools.lru_cache(maxsize=8)
def _judge_functions(omega_max: tuple, jc: tuple) -> tuple:
    # Traced once per vehicle and settings (the functions keep no state).
    n = len(omega_max)
    names = state_names(n)
    namespace: dict = {"sqrt": np.sqrt, "where": np.where, "logical_or": np.logical_or,
                       "logical_and": np.logical_and, "isfinite": np.isfinite,
                       "fabs": np.fabs, "acos": _acos, "degrees": np.degrees,
                       "nan": np.nan}
    J = [leaf(name) for name in JUDGE]
    trace = Trace()
    reason, value = trace.judge_sample(
        jc, omega_max, leaf("t"),
        [leaf(name) for name in names], [leaf(name) for name in ROTATION],
        [leaf(name) for name in ERROR], leaf("saturated"), leaf("worst"), J)
    sources = [(
        "judge", ["t", *names, *ROTATION, *ERROR, "saturated", "worst", *JUDGE],
        [*zip(JUDGE, J), ("reason", reason), ("value", value)])]
    trace = Trace()
    J = [leaf(name) for name in JUDGE]
    sources.append(("verdict", list(JUDGE), list(zip(("reason", "value"),
                                                     trace.verdict(jc, J)))))
    trace = Trace()
    J = [leaf(name) for name in JUDGE]
    sources.append(("settle", ["reason", *JUDGE],
                    [("settle", trace.settle_time(jc, leaf("reason"), J))]))
    for name, args, outputs in sources:
        writer = Writer(namespace, columns=True)
        for target, out in outputs:
            writer.assign(target, out)
        source = _function(name, args, writer.lines(), [t for t, _ in outputs])
        exec(compile(source, f"<reedtool.sim.columns {name}>", "exec"), namespace)
    return namespace["judge"], namespace["verdict"], namespace["settle"]
