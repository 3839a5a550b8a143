"""One vehicle in plain Python floats, generated from the flight equations.

For one vehicle numpy's per-call overhead would dominate, so `run` steps the hover
simulation with scalar arithmetic: the step is `equations.control_state` and
`equations.advance_state` traced once with the vehicle's numbers (`trace`): rotors
unrolled, constants folded into literals, every term whose coefficient is exactly 0
dropped, the desaturation called as the function itself when its guard holds. So this
engine flies the same equations as the compiled one by construction.

`compile_vehicle` returns `fly(state, rec)`, which flies the whole run from `state`
(STATE order, then the rotor speeds) and judges it every `config.sample_every` steps,
as `batch.simulate_batch` does; `rec`, if not None, is called with each sample
(t, x, y, z, R00, R10, R20, R21, R22, position error, cos(attitude error), *omega). It
returns a Flight tuple: why it stopped early (None when it reached the end) and what the
judge tracked; `run` turns that into a HoverRun.
"""

from __future__ import annotations

import functools
import math
from typing import Callable, NamedTuple

from reedtool.sim import layout
from reedtool.sim.layout import ERROR, ROTATION, STATE, as_constants, state_names
from reedtool.sim.trace import Sym, Trace, Writer, leaf, literal

class Flight(NamedTuple):
    """What `fly` returns: how the run ended and what the judge tracked on the samples."""

    reason: str | None          # "non-finite", "flipped", "ground", "yaw-spin", "drifted",
    value: float                # "rate", or None at the end; and the value that ended it
    end_time_s: float
    max_position_error_m: float
    min_cos_attitude: float
    max_throttle: float
    last_out_s: float           # last sample time outside the tolerance band
    within: bool                # inside the band at the last sample
    longest_saturation_s: float
    longest_saturation_rotor: int
    position_error_m: float     # at the last sample
    cos_attitude: float
    omega_rad_s: tuple


def compile_vehicle(params, gains, config, setpoint_m: tuple[float, float, float]) -> Callable:
    """`fly` for `params` flown by `gains` as `config` says, towards `setpoint_m`."""
    namespace: dict = {}
    source = _source(params, gains, config, setpoint_m, namespace)
    namespace.update({"sqrt": math.sqrt, "tan": math.tan, "acos": math.acos,
                      "degrees": math.degrees, "isfinite": math.isfinite, "Flight": Flight})
    exec(_compiled(source, params.n_rotors), namespace)
    return namespace["fly"]


@functools.lru_cache(maxsize=8)
def _compiled(source: str, n_rotors: int):
    # Compiling is most of the set-up time; the same vehicle flown again (tests, a
    # benchmark's repeats) reuses the code.
    return compile(source, f"<reedtool.sim.scalar step, {n_rotors} rotors>", "exec")


def step_lines(params, gains, config, setpoint_m, namespace: dict) -> tuple[list, list]:
    """(before, after): one step traced into statements, from the state named by STATE
    and om<i>. `before` runs equations.control_state (into ROTATION, ERROR, T<i>,
    `saturated`, `worst`) and computes equations.advance_state; `after` sets the new
    state. Traced together, so what both compute (w x J w) is computed once. Constants
    that are not numbers go into `namespace`."""
    the = layout.inputs(params, gains, config, setpoint_m=setpoint_m)
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
    trace.advance_state(as_constants(the.vehicle(0)), x, T, R, e)
    for target, value in zip(names, x):
        writer.assign(target, value)
    return writer.lines(split=True)


def _source(params, gains, config, setpoint_m, namespace: dict) -> str:
    n = params.n_rotors
    om = [f"om{i}" for i in range(n)]
    before, after = step_lines(params, gains, config, setpoint_m, namespace)
    L = literal
    dt_s = config.dt_s
    # ---- the judge, on the state at each sample (batch.simulate_batch's rules); `saturated`
    # and `worst` come from the command at that state. Comparisons instead of min/max
    # calls, with the same NaN behaviour.
    omega_max = params.omega_max_rad_s
    judge = [
        "t = step * dt",
        "pos = sqrt(ex * ex + ey * ey + ez * ez)",
        # attitude error: the angle from the level hover attitude at heading 0
        "cos_att = 0.5 * (R00 + R11 + R22 - 1.0)",
        "cos_att = -1.0 if cos_att < -1.0 else (1.0 if cos_att > 1.0 else cos_att)",
        f"throttle = {om[0]} / {L(omega_max[0])}",
    ]
    for i in range(1, n):
        judge += [f"ratio = {om[i]} / {L(omega_max[i])}", "if ratio > throttle: throttle = ratio"]
    judge += [
        "if pos > max_pos: max_pos = pos",
        "if cos_att < min_cos: min_cos = cos_att",
        "if throttle > max_throttle: max_throttle = throttle",
        f"within = pos <= {L(config.position_tol_m)} "
        f"and cos_att >= {L(config.cos_attitude_tol)}",
        "if not within: last_out = t",
        "if saturated:",         # streaks: start, rotor furthest out then, longest so far
        "    if sat_since is None: sat_since = t; sat_rotor = worst",
        "    if t - sat_since > sat_longest:",
        "        sat_longest = t - sat_since; sat_rotor_longest = sat_rotor",
        "else:",
        "    sat_since = None",
        "if rec is not None:",
        f"    rec((t, px, py, pz, R00, R10, R20, R21, R22, pos, cos_att, {', '.join(om)}))",
        "if not (" + " and ".join(f"isfinite({v})" for v in ("px", "py", "pz", "qw", "qx",
                                                              "qy", "qz", "wx", "wy", "wz"))
        + "):",
        "    reason = 'non-finite'; value = 0.0",
        "elif R22 < 0.0:",
        "    reason = 'flipped'; value = degrees(acos(-1.0 if -1.0 > R22 else R22))",
        "elif pz < 0.0:",
        "    reason = 'ground'; value = pz",
        f"elif abs(wz) > {L(config.yaw_spin_rad_s)}:",
        "    reason = 'yaw-spin'; value = abs(wz)",
        f"elif pos > {L(config.divergence_distance_m)}:",
        "    reason = 'drifted'; value = pos",
        f"elif sqrt(wx * wx + wy * wy) > {L(config.diverged_rate_rad_s)}:",
        "    reason = 'rate'; value = sqrt(wx * wx + wy * wy)",
        "if reason is not None or step == n_steps:",
        "    return Flight(reason, value, t, max_pos, min_cos, max_throttle, last_out, within,",
        f"                  sat_longest, sat_rotor_longest, pos, cos_att, ({', '.join(om)},))",
    ]

    def indent(lines, depth):
        return "\n".join(" " * depth + line for line in lines)

    return "\n".join([
        "def fly(state, rec):",
        f"    ({', '.join(STATE)}, ({', '.join(om)},)) = state",
        f"    dt = {L(dt_s)}; n_steps = {config.n_steps}; every = {config.sample_every}",
        "    worst = 0; reason = None; value = 0.0",
        "    max_pos = 0.0; min_cos = 1.0; max_throttle = 0.0; last_out = 0.0",
        "    sat_since = None; sat_rotor = 0; sat_longest = 0.0; sat_rotor_longest = 0",
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
