"""The single-vehicle step in plain floats, generated for one vehicle.

For one vehicle numpy's per-call overhead would dominate, so `run` steps the hover
simulation with scalar arithmetic. A generic loop over the rotors spends most of its
time on the loop itself and on terms that are zero for every real frame (thrust axes
along body z, rotors in the COM's plane, a diagonal inertia), so the step is written out
for the vehicle at hand, as dataclasses and namedtuple write their methods: the rotors
unrolled, the constants inlined as literals, and every term whose coefficient is exactly
0 dropped (x * 0.0 only adds 0 to a finite sum) or 1 simplified. The equations are those
of the array engine, term for term: the motor model (`motor`), the rigid body
(`dynamics`), the Lee controller at heading 0 and the allocation (`controller`).
tests/test_sim.py holds the two engines to the same trajectory.

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

import numpy as np

STATE = ("px", "py", "pz", "vx", "vy", "vz", "qw", "qx", "qy", "qz", "wx", "wy", "wz",
         "ix", "iy", "iz")


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


def compile_vehicle(params, gains, config, setpoint_m: tuple[float, float, float],
                    most_out_of_range: Callable, prioritised: Callable) -> Callable:
    """`fly` for `params` flown by `gains` as `config` says, towards `setpoint_m`.

    `most_out_of_range(thrusts, thrust_max)` and `prioritised(rows, thrust_max, f, t0, t1,
    t2)` are the (rarely needed) desaturation helpers, called when a rotor saturates.
    """
    code = _compiled(_source(params, gains, config, setpoint_m), params.n_rotors)
    namespace = {"sqrt": math.sqrt, "tan": math.tan,
                 "acos": math.acos, "degrees": math.degrees, "isfinite": math.isfinite,
                 "Flight": Flight,
                 "most_out_of_range": most_out_of_range, "prioritised": prioritised,
                 "alloc_rows": [tuple(float(x) for x in row) for row in gains.allocation_pinv],
                 "thrust_max": [float(x) for x in gains.motor_constant
                                * gains.omega_max_rad_s ** 2]}
    exec(code, namespace)
    return namespace["fly"]


@functools.lru_cache(maxsize=8)
def _compiled(source: str, n_rotors: int):
    # Compiling is most of the set-up time; the same vehicle flown again (tests, a
    # benchmark's repeats) reuses the code.
    return compile(source, f"<reedtool.sim.scalar step, {n_rotors} rotors>", "exec")


# ------------------------------------------------------------------ code generation

def _lit(x: float) -> str:
    """A float literal that reads back exactly, parenthesised when negative."""
    x = float(x)
    if not math.isfinite(x):
        return f"float({repr(str(x))})"
    return f"({x!r})" if x < 0 or (x == 0 and math.copysign(1.0, x) < 0) else repr(x)


def _lin(terms) -> str | None:
    """sum(coef * expr) without the terms whose coefficient is 0.

    `terms` are (coef, expr) with coef a float (or None for 1) and expr a source string
    or None (a quantity known to be zero). Terms whose coefficients have the same
    magnitude share one multiplication: c x1 - c x2 + c x3 -> c * (x1 - x2 + x3) (the
    yaw reactions +-c_m T_i, the +-arm terms of a symmetric frame). None when nothing
    is left.
    """
    groups: dict[float, list[tuple[bool, str]]] = {}
    for coef, expr in terms:
        if expr is None or coef == 0.0:
            continue
        coef = 1.0 if coef is None else float(coef)
        groups.setdefault(abs(coef), []).append((coef < 0, expr))
    out = ""
    for magnitude, members in groups.items():
        if magnitude == 1.0 or len(members) == 1:
            pieces = [(negative, expr if magnitude == 1.0 else f"{_lit(magnitude)} * {expr}")
                      for negative, expr in members]
        else:
            inner = _signed_sum(members)
            if members[0][0]:           # factor the sign of the first term out
                inner = _signed_sum([(not negative, expr) for negative, expr in members])
                pieces = [(True, f"{_lit(magnitude)} * ({inner})")]
            else:
                pieces = [(False, f"{_lit(magnitude)} * ({inner})")]
        for negative, piece in pieces:
            if not out:
                out = f"-{piece}" if negative else piece
            else:
                out += f" - {piece}" if negative else f" + {piece}"
    return out or None


def _signed_sum(members: list[tuple[bool, str]]) -> str:
    out = ""
    for negative, expr in members:
        if not out:
            out = f"-{expr}" if negative else expr
        else:
            out += f" - {expr}" if negative else f" + {expr}"
    return out


def _or_zero(expr: str | None) -> str:
    return expr if expr is not None else "0.0"


def _source(params, gains, config, setpoint_m) -> str:
    dt_s = config.dt_s
    n = params.n_rotors
    g = params.g_m_s2
    m = params.mass_kg
    J = np.asarray(params.inertia_kg_m2, dtype=float)
    dt_J_inv = dt_s * np.linalg.inv(J)
    A = params.allocation()
    up = np.exp(-dt_s / params.time_constant_up_s)
    down = np.exp(-dt_s / params.time_constant_down_s)
    pinv = gains.allocation_pinv
    thrust_max = gains.motor_constant * gains.omega_max_rad_s ** 2
    i_max = gains.max_integral_m_s
    a_h, a_v = gains.max_horizontal_accel_m_s2, gains.max_vertical_accel_m_s2
    rotors = range(n)
    om = [f"om{i}" for i in rotors]
    T = [f"T{i}" for i in rotors]
    L = _lit

    # ---- the controller at the current state (controller.control, in floats)
    ctl = [
        # dynamics.rot_from_quat with the factor 2 applied first (exact in floats)
        "x2 = qx + qx; y2 = qy + qy; z2 = qz + qz",
        "xx = qx * x2; yy = qy * y2; zz = qz * z2",
        "xy = qx * y2; xz = qx * z2; yz = qy * z2",
        "xw = qw * x2; yw = qw * y2; zw = qw * z2",
        "R00 = 1.0 - (yy + zz); R01 = xy - zw; R02 = xz + yw",
        "R10 = xy + zw; R11 = 1.0 - (xx + zz); R12 = yz - xw",
        "R20 = xz - yw; R21 = yz + xw; R22 = 1.0 - (xx + yy)",
    ]
    for axis, sp in zip("xyz", setpoint_m):
        ctl.append(f"e{axis} = p{axis}" + (f" - {L(sp)}" if sp != 0.0 else ""))
    for axis in "xyz":
        ctl.append(f"a{axis} = " + _lin([(-gains.kp_1_s2, f"e{axis}"), (-gains.kd_1_s, f"v{axis}"),
                                           (-gains.ki_1_s3, f"i{axis}")]))
    ctl += [
        # Tilt limit: max(sqrt(.), a_h) and min(max(az, -a_v), a_v) as Python's
        # builtins would evaluate them (NaN passes through), without the calls.
        "h = sqrt(ax * ax + ay * ay)",
        f"scale = {L(m * a_h)} / ({L(a_h)} if {L(a_h)} > h else h)",
        "Fx = scale * ax; Fy = scale * ay",
        f"Fz = ({L(a_v)} if az > {L(a_v)} else ({L(-a_v)} if az < {L(-a_v)} else az)) + {L(g)}",
        f"Fz = Fz * {L(m)}",
        "F_norm = sqrt(Fx * Fx + Fy * Fy + Fz * Fz)",
        "inv_F = 1.0 / F_norm",
        "b3x = Fx * inv_F; b3y = Fy * inv_F; b3z = Fz * inv_F",
        # Heading 0: b2 = (0, b3z, -b3y) / n, b1 = (n, -b3x b3y / n, -b3x b3z / n).
        "n_sq = b3y * b3y + b3z * b3z",
        "inv_n = 1.0 / sqrt(n_sq)",
        "b1x = n_sq * inv_n; u = inv_n * b3x",
        "A1 = b3y * R11 + b3z * R21; A2 = b3y * R12 + b3z * R22",
        "f = F_norm * (b3x * R02 + A2)",
        # 2 e_R = vee(Rd^T R - R^T Rd): M21 - M12, M02 - M20, M10 - M01
        "e0 = (b3x * R01 + A1) - inv_n * (b3z * R12 - b3y * R22)",
        "e1 = (b1x * R02 - u * A2) - (b3x * R00 + b3y * R10 + b3z * R20)",
        "e2 = inv_n * (b3z * R10 - b3y * R20) - (b1x * R01 - u * A1)",
    ]
    w = ("wx", "wy", "wz")
    for k in range(3):
        ctl.append(f"Jw{k} = " + _or_zero(_lin([(J[k, j], w[j]) for j in range(3)])))
    ctl += ["g0 = wy * Jw2 - wz * Jw1", "g1 = wz * Jw0 - wx * Jw2", "g2 = wx * Jw1 - wy * Jw0"]
    # tau = w x J w - J (kR e_R + kw w), with e = 2 e_R
    half_kR, kw = 0.5 * gains.kR_1_s2, gains.kw_1_s
    Jn = np.asarray(gains.inertia_kg_m2, dtype=float)
    if np.all(Jn == np.diag(np.diag(Jn))):
        for k in range(3):
            ctl.append(f"t{k} = g{k} - ({L(Jn[k, k] * half_kR)} * e{k} + "
                       f"{L(Jn[k, k] * kw)} * {w[k]})")
    else:
        for k in range(3):
            ctl.append(f"s{k} = {L(half_kR)} * e{k} + {L(kw)} * {w[k]}")
        for k in range(3):
            ctl.append(f"t{k} = g{k} - "
                       f"({_or_zero(_lin([(Jn[k, j], f's{j}') for j in range(3)]))})")
    # allocation (controller.allocate): pseudo-inverse, desaturated when out of range
    for i in rotors:
        ctl.append(f"{T[i]} = " + _or_zero(_lin([(pinv[i, 0], "f"), (pinv[i, 1], "t0"),
                                                  (pinv[i, 2], "t1"), (pinv[i, 3], "t2")])))
    out_of_range = " or ".join(f"{T[i]} < 0.0 or {T[i]} > {L(thrust_max[i])}" for i in rotors)
    ctl += [
        f"if {out_of_range}:",
        "    saturated = True",
        f"    worst = most_out_of_range(({', '.join(T)},), thrust_max)",
        f"    {', '.join(T)}, = prioritised(alloc_rows, thrust_max, f, t0, t1, t2)",
        "else:",
        "    saturated = False",
    ]

    # ---- advance one step under the command (dynamics.body_wrench, step_rigid_body and
    # the motor model): wrench at the current speeds, then the speeds respond.
    adv = []
    force = [[], [], []]      # terms of the body force and torque, about the COM
    torque = [[], [], []]
    for i in rotors:
        adv.append(f"Th{i} = {L(params.motor_constant[i])} * {om[i]} * {om[i]}")
        for k in range(3):
            force[k].append((params.rotor_axis[i, k], f"Th{i}"))
            torque[k].append((A[k + 1, i], f"Th{i}"))
    cd, cr = params.rotor_drag_coefficient, params.rolling_moment_coefficient
    if np.any(cd != 0.0) or np.any(cr != 0.0):
        dragging = [i for i in rotors if cd[i] != 0.0 or cr[i] != 0.0]
        # Every rotor with the same c_r / c_d (one rotor type): the rolling moment is that
        # ratio times the rotor drag force, summed once instead of per rotor.
        ratios = {cr[i] / cd[i] if cd[i] != 0.0 else None for i in dragging}
        rolling_ratio = ratios.pop() if len(ratios) == 1 else None
        drag_force = [[], [], []]
        P = {i: np.eye(3) - np.outer(params.rotor_axis[i], params.rotor_axis[i])
             for i in dragging}
        # u_j is needed when P has a non-zero in column j (e.g. never u_z for axes along z)
        needed = {i: [bool(np.any(P[i][:, j] != 0.0)) for j in range(3)] for i in dragging}
        R_T = ("R00 * vx + R10 * vy + R20 * vz", "R01 * vx + R11 * vy + R21 * vz",
               "R02 * vx + R12 * vy + R22 * vz")
        for j, name in enumerate("xyz"):                    # v_b = R^T v
            if any(needed[i][j] for i in dragging):
                adv.append(f"vb{name} = {R_T[j]}")
        for i in dragging:
            r = params.rotor_position_m[i]
            # velocity of the rotor u = v_b + w x r, then across its axis u_perp = P u
            u = [_lin([(None, "vbx"), (r[2], "wy"), (-r[1], "wz")]),
                 _lin([(None, "vby"), (r[0], "wz"), (-r[2], "wx")]),
                 _lin([(None, "vbz"), (r[1], "wx"), (-r[0], "wy")])]
            for j, name in enumerate("xyz"):
                if needed[i][j]:
                    adv.append(f"u{name}{i} = {u[j]}")
            perp = []
            for k, name in enumerate("xyz"):
                expr = _lin([(P[i][k, j], f"u{'xyz'[j]}{i}") for j in range(3) if needed[i][j]])
                if expr is not None and expr != f"u{name}{i}":
                    adv.append(f"u{name}_perp{i} = {expr}")
                    expr = f"u{name}_perp{i}"
                perp.append(expr)
            # rotor drag -w c_d u_perp at the rotor, rolling moment -w c_r u_perp
            drag = [None, None, None]
            if cd[i] != 0.0:
                adv.append(f"drag{i} = {om[i]} * {L(-cd[i])}")
                for k, name in enumerate("xyz"):
                    if perp[k] is not None:
                        adv.append(f"d{name}{i} = drag{i} * {perp[k]}")
                        drag[k] = f"d{name}{i}"
            for k in range(3):
                drag_force[k].append((None, drag[k]))
            torque[0] += [(r[1], drag[2]), (-r[2], drag[1])]
            torque[1] += [(r[2], drag[0]), (-r[0], drag[2])]
            torque[2] += [(r[0], drag[1]), (-r[1], drag[0])]
            if cr[i] != 0.0 and rolling_ratio is None:
                adv.append(f"roll{i} = {om[i]} * {L(-cr[i])}")
                for k in range(3):
                    if perp[k] is not None:
                        torque[k].append((None, f"roll{i} * {perp[k]}"))
        for k, name in enumerate("xyz"):
            total = _lin(drag_force[k])
            if total is not None:
                adv.append(f"Fd{name} = {total}")
                force[k].append((None, f"Fd{name}"))
                if rolling_ratio is not None:
                    # The rolling moments sum to (c_r / c_d) times the drag force.
                    torque[k].append((rolling_ratio, f"Fd{name}"))
    for k, name in enumerate("xyz"):
        adv.append(f"Fb{name} = {_or_zero(_lin(force[k]))}")
        adv.append(f"Tb{name} = {_or_zero(_lin(torque[k]))}")
    lead = gains.motor_lead_factors(dt_s)
    for i in rotors:
        # motor.speed_command, then the first-order lag (allocation keeps T <= k w_max^2)
        adv.append(f"cmd = sqrt({T[i]} * {L(1.0 / gains.motor_constant[i])}) "
                   f"if {T[i]} > 0.0 else 0.0")
        if lead is not None and (lead[0][i] != 1.0 or lead[1][i] != 1.0):
            # the controller's lead on a slow motor (ControllerGains.motor_lead_factors)
            top = gains.omega_max_rad_s[i]
            adv.append(f"cmd = {om[i]} + (cmd - {om[i]}) * ({L(lead[0][i])} if cmd > {om[i]} "
                       f"else {L(lead[1][i])})")
            adv.append(f"cmd = {L(top)} if cmd > {L(top)} else (0.0 if cmd < 0.0 else cmd)")
        adv.append(f"{om[i]} = cmd + ({om[i]} - cmd) * ({L(up[i])} if cmd > {om[i]} "
                   f"else {L(down[i])})")
    adv += [
        f"fx = Fbx * {L(dt_s / m)}; fy = Fby * {L(dt_s / m)}; fz = Fbz * {L(dt_s / m)}",
        "vx += R00 * fx + R01 * fy + R02 * fz",
        "vy += R10 * fx + R11 * fy + R12 * fz",
        f"vz += R20 * fx + R21 * fy + R22 * fz - {L(dt_s * g)}",
        "h0 = Tbx - g0; h1 = Tby - g1; h2 = Tbz - g2",      # tau - w x J w
    ]
    for k in range(3):
        adv.append(f"{w[k]} += " + _or_zero(_lin([(dt_J_inv[k, j], f"h{j}") for j in range(3)])))
    adv += [
        f"px += {L(dt_s)} * vx; py += {L(dt_s)} * vy; pz += {L(dt_s)} * vz",
        # q * (|w| / tan h, w), renormalised: dynamics.integrate_quat
        "rate = sqrt(wx * wx + wy * wy + wz * wz)",
        f"tan_h = tan({L(0.5 * dt_s)} * rate)",
        "a = rate / tan_h if tan_h != 0.0 else 1.0",
        "qw, qx, qy, qz = (qw * a - qx * wx - qy * wy - qz * wz,",
        "                  qx * a + qw * wx + qy * wz - qz * wy,",
        "                  qy * a + qw * wy + qz * wx - qx * wz,",
        "                  qz * a + qw * wz + qx * wy - qy * wx)",
        "inv_q = 1.0 / sqrt(qw * qw + qx * qx + qy * qy + qz * qz)",
        "qw *= inv_q; qx *= inv_q; qy *= inv_q; qz *= inv_q",
    ]
    for axis in "xyz":
        adv.append(f"i{axis} += {L(dt_s)} * e{axis}")
        adv.append(f"i{axis} = {L(i_max)} if i{axis} > {L(i_max)} else "
                   f"({L(-i_max)} if i{axis} < {L(-i_max)} else i{axis})")

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
        "steps = every if n_steps - step > every else n_steps - step",
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
        indent(ctl, 4),
        "    step = 0",
        "    while True:",
        indent(judge, 8),
        "        for _ in range(steps):",
        indent(adv, 12),
        indent(ctl, 12),
        "        step += steps",
        "",
    ])
