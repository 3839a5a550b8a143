"""The flight equations of one vehicle, written once: every engine is built from these.

Plain scalar Python in the subset numba compiles: floats, index loops over the rotors,
`math`, flat sequences indexed by position (numpy arrays in the compiled engine, tuples
of floats or traced values in the generated one), and no numpy call. The engines are:

- `compiled`: numba jits these very functions (`compiled.jitted`) for one vehicle and,
  per vehicle, across the cores for a batch;
- `scalar`: traces them once with the vehicle's numbers (`trace`: constants folded,
  rotor loops unrolled, zero terms dropped) into straight-line Python for one vehicle;
- `batch`: traces them once with per-vehicle values as arrays into numpy column
  operations for many vehicles.

Data-dependent choices are the `@select` functions: one `return a if cond else b`
line each, which the tracers emit as that very expression (numba inlines it). The
desaturation acts only when a rotor is out of range (`@guarded_by` that test): the float
engine calls `desaturate` itself under its guard, the batch traces its work into columns
for the vehicles whose guard holds, the compiled engine runs it as written.

The judge of a flight is here too, in the same style: `judge_sample` (each sample: the
record J and the events that end a flight), `verdict` (at the end: settled, saturated or
not settled) and `settle_time`; every engine judges by them, built the same ways.

Frames and units (docs/hover-test.md, "The simulation"): world z up, gravity -z; body
axes the base link's, origin at the COM; state p, v (world, m, m/s), q = (w, x, y, z)
body -> world, w body rates (rad/s), rotor speeds omega (rad/s), and the integral of the
position error (m*s).

Flat layouts (index i is a rotor, n rotors):
- CTL, the controller: kp kd ki kR kw a_h a_v m g, then the nominal inertia J row-major.
- rotor arrays `pos`, `axis`, `tmap` are 3 per rotor: [3 i + k]; `pinv` 4 per rotor.
"""

from __future__ import annotations

import math

SELECTS: set[str] = set()      # names of the one-line selects (the tracers inline them)
GUARDED: dict[str, str] = {}   # branchy step -> the select that says whether it acts


def select(f):
    """Mark `f` as a one-line `return x if cond else y`: the tracers inline its
    expression. Returns `f` itself, so numba sees a plain function."""
    SELECTS.add(f.__name__)
    return f


def guarded_by(guard: str):
    """Mark a branchy step that changes nothing unless `guard(x_i, hi_i)` holds for some
    rotor i: the tracers call it (not trace it), under that guard."""
    def mark(f):
        GUARDED[f.__name__] = guard
        return f
    return mark


# ------------------------------------------------------------------ selects

@select
def clamp(x, lo, hi):
    """x limited to [lo, hi]; NaN passes through."""
    return hi if x > hi else (lo if x < lo else x)


@select
def larger(a, b):
    """max(a, b), b when either is NaN."""
    return a if a > b else b


@select
def pick_rising(new, old, up, down):
    """`up` when `new` exceeds `old` (a rotor spinning up), else `down`."""
    return up if new > old else down


@select
def root_or_zero(x):
    """sqrt(x) for x > 0, else 0 (a thrust command below zero asks for no speed)."""
    return math.sqrt(x) if x > 0.0 else 0.0


# |w| / tan(h), h = |w| dt / 2, by its series in hh = h^2 below SERIES_HH_MAX (|w| below
# 20 rad/s at 1 kHz; the first omitted term is below 1e-19 of the sum, so it is the
# function to the last bit, and free of a call: a block of vehicles computes it in SIMD
# lanes, and a Python step in fewer operations than tan).
SERIES_HH_MAX = 1e-4


@select
def cot_series(hh, two_over_dt):
    """(2 / dt) h cot h = |w| / tan h for small h, hh = h^2 (h cot h's Taylor series)."""
    return two_over_dt * (1.0 - hh * (1.0 / 3.0 + hh * (1.0 / 45.0 + hh * (2.0 / 945.0))))


@select
def cot_exact(rate_sq, half_dt):
    """|w| / tan(|w| dt / 2) from |w|^2; 1 for no rotation (the step is then the identity)."""
    return (math.sqrt(rate_sq) / math.tan(half_dt * math.sqrt(rate_sq))
            if half_dt * math.sqrt(rate_sq) != 0.0 else 1.0)


@select
def cot_ratio(hh, rate_sq, half_dt):
    """|w| / tan(h), the scalar part of q's step direction (hh = h^2, rate_sq = |w|^2)."""
    return cot_series(hh, 1.0 / half_dt) if hh < SERIES_HH_MAX else cot_exact(rate_sq, half_dt)


@select
def out_of_range(x, hi):
    """A rotor thrust the rotor cannot give: below 0 or above its maximum."""
    return x < 0.0 or x > hi


# ------------------------------------------------------------------ controller

def rotation(qw, qx, qy, qz):
    """R00, R01, ..., R22 of the unit quaternion's rotation (the factor 2 applied first,
    exact in floats)."""
    x2 = qx + qx
    y2 = qy + qy
    z2 = qz + qz
    xx = qx * x2
    yy = qy * y2
    zz = qz * z2
    xy = qx * y2
    xz = qx * z2
    yz = qy * z2
    xw = qw * x2
    yw = qw * y2
    zw = qw * z2
    return (1.0 - (yy + zz), xy - zw, xz + yw,
            xy + zw, 1.0 - (xx + zz), yz - xw,
            xz - yw, yz + xw, 1.0 - (xx + yy))


def attitude_control(ctl, ex, ey, ez, vx, vy, vz, ix, iy, iz,
                     R00, R01, R02, R10, R11, R12, R20, R21, R22, wx, wy, wz):
    """The Lee law towards the setpoint at heading 0: (thrust along body z, roll, pitch,
    yaw torque). controller.py derives the gains (CTL layout above).

    Position: a = -kp e - kd v - ki integral, its horizontal part capped at a_h (the tilt
    limit, direction kept), its vertical at +-a_v; F = m (a + g e3) sets b3 and the
    collective F . R e3. Attitude: tau = w x J w - J (kR e_R + kw w) with
    2 e_R = vee(Rd^T R - R^T Rd)."""
    kp, kd, ki, kR, kw, a_h, a_v, m, g = (ctl[0], ctl[1], ctl[2], ctl[3], ctl[4], ctl[5],
                                          ctl[6], ctl[7], ctl[8])
    ax = -kp * ex - kd * vx - ki * ix
    ay = -kp * ey - kd * vy - ki * iy
    az = -kp * ez - kd * vz - ki * iz
    h = math.sqrt(ax * ax + ay * ay)
    scale = (m * a_h) / larger(a_h, h)
    Fx = scale * ax
    Fy = scale * ay
    Fz = (clamp(az, -a_v, a_v) + g) * m
    F_norm = math.sqrt(Fx * Fx + Fy * Fy + Fz * Fz)
    inv_F = 1.0 / F_norm
    b3x = Fx * inv_F
    b3y = Fy * inv_F
    b3z = Fz * inv_F
    # Heading 0: b2 = (0, b3z, -b3y) / n, b1 = (n, -b3x b3y / n, -b3x b3z / n).
    n_sq = b3y * b3y + b3z * b3z
    inv_n = 1.0 / math.sqrt(n_sq)
    b1x = n_sq * inv_n
    u = inv_n * b3x
    A1 = b3y * R11 + b3z * R21
    A2 = b3y * R12 + b3z * R22
    f = F_norm * (b3x * R02 + A2)
    # 2 e_R = vee(Rd^T R - R^T Rd): M21 - M12, M02 - M20, M10 - M01 with M = Rd^T R
    e0 = (b3x * R01 + A1) - inv_n * (b3z * R12 - b3y * R22)
    e1 = (b1x * R02 - u * A2) - (b3x * R00 + b3y * R10 + b3z * R20)
    e2 = inv_n * (b3z * R10 - b3y * R20) - (b1x * R01 - u * A1)
    s0 = 0.5 * kR * e0 + kw * wx
    s1 = 0.5 * kR * e1 + kw * wy
    s2 = 0.5 * kR * e2 + kw * wz
    J00, J01, J02, J10, J11, J12, J20, J21, J22 = (ctl[9], ctl[10], ctl[11], ctl[12],
                                                   ctl[13], ctl[14], ctl[15], ctl[16],
                                                   ctl[17])
    Jw0 = J00 * wx + J01 * wy + J02 * wz
    Jw1 = J10 * wx + J11 * wy + J12 * wz
    Jw2 = J20 * wx + J21 * wy + J22 * wz
    t0 = (wy * Jw2 - wz * Jw1) - (J00 * s0 + J01 * s1 + J02 * s2)
    t1 = (wz * Jw0 - wx * Jw2) - (J10 * s0 + J11 * s1 + J12 * s2)
    t2 = (wx * Jw1 - wy * Jw0) - (J20 * s0 + J21 * s1 + J22 * s2)
    return f, t0, t1, t2


def rotor_thrust(c0, c1, c2, c3, f, t0, t1, t2):
    """A rotor's thrust in the pseudo-inverse allocation of the wrench (c: its row)."""
    return c0 * f + c1 * t0 + c2 * t1 + c3 * t2


def pinv_thrusts(pinv, f, t0, t1, t2, T):
    """The pseudo-inverse allocation of the wrench into T (one thrust per rotor)."""
    for i in range(len(T)):
        T[i] = rotor_thrust(pinv[4 * i], pinv[4 * i + 1], pinv[4 * i + 2], pinv[4 * i + 3],
                            f, t0, t1, t2)


@select
def excess(b, hi):
    """How far a thrust is outside [0, hi], relative to hi: max(-b, b - hi) / hi, as
    Python's max evaluates it (negative inside the range)."""
    return (b - hi if b - hi > -b else -b) / hi


@select
def index_if_above(x, best, i, index):
    """`i` when x exceeds the best so far, else the index of the best (the first wins a
    tie)."""
    return i if x > best else index


@select
def tighter_fit(b, hi, fit):
    """The scale that brings a thrust b above its maximum hi back to it, when tighter
    than `fit` (the collective's scale over the rotors so far)."""
    return hi / b if b > hi and hi / b < fit else fit


@select
def room(d, b, hi, scale):
    """The smaller of `scale` and the fraction of a change d that keeps the thrust b
    within [0, hi]."""
    return (((hi - b) / d if (hi - b) / d < scale else scale) if d > 0.0
            else ((-b / d if -b / d < scale else scale) if d < 0.0 else scale))


def most_out_of_range(T, thrust_max):
    """The rotor whose thrust is furthest out of its range, relative to its maximum (the
    first on a tie): what a saturation streak reports."""
    worst = 0
    best = -math.inf
    for i in range(len(T)):
        x = excess(T[i], thrust_max[i])
        worst = index_if_above(x, best, i, worst)
        best = larger(x, best)
    return worst


def prioritised(pinv, thrust_max, f, t0, t1, t2, T) -> None:
    """The desaturation, into T: as PX4's mixer does, the collective thrust part first
    (scaled into range if it alone saturates), then as much of the roll/pitch part as
    fits, then of the yaw part; the torques keep their direction (clipping each rotor on
    its own would couple roll into pitch and yaw and can limit-cycle). Its choices are
    selects, so a batch computes it in columns too."""
    n = len(T)
    fit = 1.0
    for i in range(n):
        T[i] = pinv[4 * i] * f
        fit = tighter_fit(T[i], thrust_max[i], fit)
    for i in range(n):
        T[i] = clamp(T[i] * fit, 0.0, thrust_max[i])
    for stage in range(2):
        scale = math.inf
        for i in range(n):
            d = pinv[4 * i + 1] * t0 + pinv[4 * i + 2] * t1 if stage == 0 \
                else pinv[4 * i + 3] * t2
            scale = room(d, T[i], thrust_max[i], scale)
        scale = clamp(scale, 0.0, 1.0)
        for i in range(n):
            d = pinv[4 * i + 1] * t0 + pinv[4 * i + 2] * t1 if stage == 0 \
                else pinv[4 * i + 3] * t2
            T[i] = T[i] + scale * d
    for i in range(n):
        T[i] = clamp(T[i], 0.0, thrust_max[i])


@guarded_by("out_of_range")
def desaturate(pinv, thrust_max, f, t0, t1, t2, T):
    """(saturated, most-out-of-range rotor): T as the pseudo-inverse gave it when every
    rotor can deliver it, else prioritised."""
    for i in range(len(T)):
        if out_of_range(T[i], thrust_max[i]):
            worst = most_out_of_range(T, thrust_max)
            prioritised(pinv, thrust_max, f, t0, t1, t2, T)
            return True, worst
    return False, 0


def control(ctl, pinv, thrust_max, ex, ey, ez, vx, vy, vz, ix, iy, iz,
            R00, R01, R02, R10, R11, R12, R20, R21, R22, wx, wy, wz, T):
    """The controller at the current state: rotor thrusts into T; returns (saturated,
    most-out-of-range rotor)."""
    f, t0, t1, t2 = attitude_control(ctl, ex, ey, ez, vx, vy, vz, ix, iy, iz,
                                     R00, R01, R02, R10, R11, R12, R20, R21, R22, wx, wy, wz)
    pinv_thrusts(pinv, f, t0, t1, t2, T)
    return desaturate(pinv, thrust_max, f, t0, t1, t2, T)


# ------------------------------------------------------------------ motors

def speed_command(thrust_N, inv_k, omega, lead, lead_up, lead_down, omega_max):
    """A rotor's speed command for `thrust_N` (the allocation keeps it within
    [0, k omega_max^2]), with the controller's lead on it when `lead`
    (ControllerGains.motor_lead_factors, clamped to [0, omega_max])."""
    cmd = root_or_zero(thrust_N * inv_k)
    if lead:
        cmd = clamp(omega + (cmd - omega) * pick_rising(cmd, omega, lead_up, lead_down),
                    0.0, omega_max)
    return cmd


def lag(cmd, omega, up, down):
    """RotorS' first-order speed response over one step, exact for a command held over
    it: exp(-dt / tau) per step, `up` spinning up and `down` spinning down."""
    return cmd + (omega - cmd) * pick_rising(cmd, omega, up, down)


def next_speed(thrust_N, inv_k, omega, up, down, lead, lead_up, lead_down, omega_max):
    """One rotor's speed after a step under the thrust `thrust_N`."""
    return lag(speed_command(thrust_N, inv_k, omega, lead, lead_up, lead_down, omega_max),
               omega, up, down)


# ------------------------------------------------------------------ rotor wrench

def com_velocity(R00, R01, R02, R10, R11, R12, R20, R21, R22, vx, vy, vz, wx, wy, wz,
                 s0, s1, s2):
    """Velocity of the nominal COM, body axes: R^T v - w x shift (shift = the true COM
    minus the nominal one, about which the rotor positions are given)."""
    return ((R00 * vx + R10 * vy + R20 * vz) - (wy * s2 - wz * s1),
            (R01 * vx + R11 * vy + R21 * vz) - (wz * s0 - wx * s2),
            (R02 * vx + R12 * vy + R22 * vz) - (wx * s1 - wy * s0))


def rotor_wrench(r0, r1, r2, a0, a1, a2, m0, m1, m2, cd, cr, k, om, xi0, xi1, xi2, wx, wy,
                 wz):
    """A rotor's force and torque about the nominal COM, body axes, at speed om (RotorS'
    motor model): thrust k om^2 along its axis a and the yaw drag reaction (m, torque
    per newton), rotor drag -om c_d u_perp at the rotor (at r) and the rolling moment
    -om c_r u_perp (u_perp the rotor's airspeed across its axis; xi the COM's)."""
    Th = k * om * om
    F0, F1, F2 = a0 * Th, a1 * Th, a2 * Th
    M0, M1, M2 = m0 * Th, m1 * Th, m2 * Th
    if cd != 0.0 or cr != 0.0:
        u0 = xi0 + (wy * r2 - wz * r1)
        u1 = xi1 + (wz * r0 - wx * r2)
        u2 = xi2 + (wx * r1 - wy * r0)
        along = a0 * u0 + a1 * u1 + a2 * u2
        p0 = u0 - a0 * along
        p1 = u1 - a1 * along
        p2 = u2 - a2 * along
        dc = -om * cd
        d0 = dc * p0
        d1 = dc * p1
        d2 = dc * p2
        rc = -om * cr
        F0, F1, F2 = F0 + d0, F1 + d1, F2 + d2
        M0 = M0 + (r1 * d2 - r2 * d1 + rc * p0)
        M1 = M1 + (r2 * d0 - r0 * d2 + rc * p1)
        M2 = M2 + (r0 * d1 - r1 * d0 + rc * p2)
    return F0, F1, F2, M0, M1, M2


def about_true_com(F0, F1, F2, M0, M1, M2, s0, s1, s2):
    """The torque about the true COM: tau - shift x F."""
    return M0 - (s1 * F2 - s2 * F1), M1 - (s2 * F0 - s0 * F2), M2 - (s0 * F1 - s1 * F0)


def body_wrench(pos, axis, tmap, cd, cr, k, shift, omega, R00, R01, R02, R10, R11, R12,
                R20, R21, R22, vx, vy, vz, wx, wy, wz):
    """Force and torque about the true COM, body axes: every rotor's rotor_wrench."""
    s0, s1, s2 = shift[0], shift[1], shift[2]
    xi0, xi1, xi2 = com_velocity(R00, R01, R02, R10, R11, R12, R20, R21, R22, vx, vy, vz,
                                 wx, wy, wz, s0, s1, s2)
    F0 = F1 = F2 = M0 = M1 = M2 = 0.0
    for i in range(len(k)):
        f0, f1, f2, m0, m1, m2 = rotor_wrench(
            pos[3 * i], pos[3 * i + 1], pos[3 * i + 2], axis[3 * i], axis[3 * i + 1],
            axis[3 * i + 2], tmap[3 * i], tmap[3 * i + 1], tmap[3 * i + 2], cd[i], cr[i], k[i],
            omega[i], xi0, xi1, xi2, wx, wy, wz)
        F0 += f0
        F1 += f1
        F2 += f2
        M0 += m0
        M1 += m1
        M2 += m2
    M0, M1, M2 = about_true_com(F0, F1, F2, M0, M1, M2, s0, s1, s2)
    return F0, F1, F2, M0, M1, M2


# ------------------------------------------------------------------ rigid body

def translation_and_rates(dt, g, mass, J0, dt_J0inv, S0, S1, S2, R, F0, F1, F2, M0, M1, M2,
                          px, py, pz, vx, vy, vz, wx, wy, wz):
    """Semi-implicit Euler for p, v and w: v from the force at the start of the step, p
    from the new v; J w' = tau - w x J w with J = S J0 S (S = diag(S0, S1, S2), a
    perturbed vehicle's; dt_J0inv = dt J0^-1). R: the 9 entries of the attitude. Returns
    p, v, w."""
    R00, R01, R02, R10, R11, R12, R20, R21, R22 = (R[0], R[1], R[2], R[3], R[4], R[5], R[6],
                                                   R[7], R[8])
    fm = dt / mass
    f0 = F0 * fm
    f1 = F1 * fm
    f2 = F2 * fm
    vx = vx + (R00 * f0 + R01 * f1 + R02 * f2)
    vy = vy + (R10 * f0 + R11 * f1 + R12 * f2)
    vz = vz + (R20 * f0 + R21 * f1 + R22 * f2) - dt * g
    sw0 = S0 * wx
    sw1 = S1 * wy
    sw2 = S2 * wz
    Jw0 = S0 * (J0[0] * sw0 + J0[1] * sw1 + J0[2] * sw2)
    Jw1 = S1 * (J0[3] * sw0 + J0[4] * sw1 + J0[5] * sw2)
    Jw2 = S2 * (J0[6] * sw0 + J0[7] * sw1 + J0[8] * sw2)
    h0 = (M0 - (wy * Jw2 - wz * Jw1)) / S0
    h1 = (M1 - (wz * Jw0 - wx * Jw2)) / S1
    h2 = (M2 - (wx * Jw1 - wy * Jw0)) / S2
    wx = wx + (dt_J0inv[0] * h0 + dt_J0inv[1] * h1 + dt_J0inv[2] * h2) / S0
    wy = wy + (dt_J0inv[3] * h0 + dt_J0inv[4] * h1 + dt_J0inv[5] * h2) / S1
    wz = wz + (dt_J0inv[6] * h0 + dt_J0inv[7] * h1 + dt_J0inv[8] * h2) / S2
    return px + dt * vx, py + dt * vy, pz + dt * vz, vx, vy, vz, wx, wy, wz


def attitude_step(qw, qx, qy, qz, wx, wy, wz, a):
    """q * exp(w dt / 2) as q * (a, w), renormalised (a positive multiple of the exact
    step, a = cot_ratio): the quaternion stays a rotation."""
    nw = qw * a - qx * wx - qy * wy - qz * wz
    nx = qx * a + qw * wx + qy * wz - qz * wy
    ny = qy * a + qw * wy + qz * wx - qx * wz
    nz = qz * a + qw * wz + qx * wy - qy * wx
    inv_q = 1.0 / math.sqrt(nw * nw + nx * nx + ny * ny + nz * nz)
    return nw * inv_q, nx * inv_q, ny * inv_q, nz * inv_q


def rigid_body(dt, g, mass, J0, dt_J0inv, S, R, F0, F1, F2, M0, M1, M2, px, py, pz, vx, vy,
               vz, qw, qx, qy, qz, wx, wy, wz):
    """One semi-implicit Euler step under the body wrench: p, v, w (translation_and_rates),
    then q through the exact exponential map of the new w. Returns p, v, q, w.

    Why this integrator (dynamics.py): the command is held over the step, it costs one
    force evaluation, and its fixed point is the continuous equilibrium (hover = trim)."""
    px, py, pz, vx, vy, vz, wx, wy, wz = translation_and_rates(
        dt, g, mass, J0, dt_J0inv, S[0], S[1], S[2], R, F0, F1, F2, M0, M1, M2, px, py, pz, vx,
        vy, vz, wx, wy, wz)
    half_dt = 0.5 * dt
    rate_sq = wx * wx + wy * wy + wz * wz
    a = cot_ratio(half_dt * half_dt * rate_sq, rate_sq, half_dt)
    qw, qx, qy, qz = attitude_step(qw, qx, qy, qz, wx, wy, wz, a)
    return px, py, pz, vx, vy, vz, qw, qx, qy, qz, wx, wy, wz


def integral(i_max, dt, ix, iy, iz, ex, ey, ez):
    """The position error's integral, one step, each axis within +-i_max (anti-windup)."""
    return (clamp(ix + ex * dt, -i_max, i_max), clamp(iy + ey * dt, -i_max, i_max),
            clamp(iz + ez * dt, -i_max, i_max))


# ------------------------------------------------------------------ the step

# The state x: p 0:3, v 3:6, q 6:10, w 10:13, integral 13:16, rotor speeds 16:16+n.
# The vehicle `veh` (per vehicle where a batch perturbs it: mass, S, shift, k):
#   dt g mass lead i_max pos axis tmap cd cr k shift S J0 dt_J0inv inv_k up down lead_up
#   lead_down omega_max   (J0 and dt J0^-1 row-major; inv_k and omega_max the controller's).
STATE_SIZE = 16


def control_state(ctl, pinv, thrust_max, sp, x, R, e, T):
    """The controller at state x towards setpoint sp: the rotation into R (9), the
    position error into e (3), the thrusts into T; returns (saturated, worst rotor)."""
    R00, R01, R02, R10, R11, R12, R20, R21, R22 = rotation(x[6], x[7], x[8], x[9])
    R[0], R[1], R[2], R[3], R[4], R[5], R[6], R[7], R[8] = (R00, R01, R02, R10, R11, R12,
                                                            R20, R21, R22)
    ex = x[0] - sp[0]
    ey = x[1] - sp[1]
    ez = x[2] - sp[2]
    e[0], e[1], e[2] = ex, ey, ez
    return control(ctl, pinv, thrust_max, ex, ey, ez, x[3], x[4], x[5], x[13], x[14], x[15],
                   R00, R01, R02, R10, R11, R12, R20, R21, R22, x[10], x[11], x[12], T)


def advance_plant(veh, x, cmd, R):
    """x's vehicle one step on under the rotor speed commands cmd: the wrench at the
    current rotor speeds, the speeds' lag towards cmd, the rigid body under that wrench.
    R is x's rotation."""
    dt, g, mass, lead, i_max, pos, axis, tmap, cd, cr, k, shift, S, J0, dt_J0inv, inv_k, \
        up, down, lead_up, lead_down, omega_max = veh
    n = len(k)
    F0, F1, F2, M0, M1, M2 = body_wrench(pos, axis, tmap, cd, cr, k, shift, x[16:16 + n],
                                         R[0], R[1], R[2], R[3], R[4], R[5], R[6], R[7],
                                         R[8], x[3], x[4], x[5], x[10], x[11], x[12])
    for i in range(n):
        x[16 + i] = lag(cmd[i], x[16 + i], up[i], down[i])
    (x[0], x[1], x[2], x[3], x[4], x[5], x[6], x[7], x[8], x[9], x[10], x[11],
     x[12]) = rigid_body(dt, g, mass, J0, dt_J0inv, S, R, F0, F1, F2, M0, M1, M2, x[0], x[1],
                         x[2], x[3], x[4], x[5], x[6], x[7], x[8], x[9], x[10], x[11], x[12])


def advance_state(veh, x, T, R, e):
    """x one step on under the controller's thrusts T (overwritten by the rotors' speed
    commands): advance_plant, and the integral of the error e. R is x's rotation
    (control_state's)."""
    dt, g, mass, lead, i_max, pos, axis, tmap, cd, cr, k, shift, S, J0, dt_J0inv, inv_k, \
        up, down, lead_up, lead_down, omega_max = veh
    for i in range(len(k)):
        T[i] = speed_command(T[i], inv_k[i], x[16 + i], lead, lead_up[i], lead_down[i],
                             omega_max[i])
    advance_plant(veh, x, T, R)
    x[13], x[14], x[15] = integral(i_max, dt, x[13], x[14], x[15], e[0], e[1], e[2])


# ------------------------------------------------------------------ the judge

# Why a flight ended: batch.REASONS[code]; 0 while it flies on.
SETTLED, NOT_SETTLED, NON_FINITE, DRIFTED, RATE, GROUND, FLIPPED, SATURATED, YAW_SPIN = (
    1, 2, 3, 4, 5, 6, 7, 8, 9)
REASONS = ("", "settled", "not-settled", "non-finite", "drifted", "rate", "ground", "flipped",
           "saturated", "yaw-spin")

# The judge's settings jc (layout.judge_settings): pos_tol cos_tol yaw_spin div_dist div_rate
#   duration hold sat_limit sample_dt (m, cos, rad/s, m, rad/s, s, s, s, s).
# What it tracks over the samples, J (floats; judge_start sets them):
#   0 max position error, 1 min cos(attitude error), 2 max throttle, 3 position error and
#   4 cos(attitude error) at the last sample, 5 last sample time outside the band,
#   6 inside the band at the last sample (1.0 / 0.0), 7 start of the current saturated
#   streak (NaN: none), 8 its rotor furthest out at its start, 9 longest streak [s],
#   10 that streak's rotor.
JUDGE_SIZE = 11


@select
def smaller(a, b):
    """min(a, b), b when either is NaN."""
    return a if a < b else b


@select
def either(cond, a, b):
    """`a` where cond holds, else `b`."""
    return a if cond else b


@select
def flag(cond):
    """1.0 for True, 0.0 for False (J holds floats)."""
    return 1.0 if cond else 0.0


@select
def over(x, limit):
    """x above limit (False for NaN)."""
    return x > limit


@select
def under(x, limit):
    """x below limit (False for NaN)."""
    return x < limit


@select
def at_least(x, limit):
    """x at or above limit (False for NaN)."""
    return x >= limit


@select
def inside_band(pos, pos_tol, cos_att, cos_tol):
    """Position and attitude errors both within the tolerance band."""
    return pos <= pos_tol and cos_att >= cos_tol


@select
def streak_begins(saturated, since):
    """A saturated sample with no streak running: one begins."""
    return saturated and since != since


@select
def streak_start(saturated, since, t):
    """When the current saturated streak began: t if it begins now, NaN when the demand
    is back in range."""
    return (t if since != since else since) if saturated else math.nan


@select
def all_finite(px, py, pz, qw, qx, qy, qz, wx, wy, wz):
    """Position, attitude and rates all finite."""
    return (math.isfinite(px) and math.isfinite(py) and math.isfinite(pz)
            and math.isfinite(qw) and math.isfinite(qx) and math.isfinite(qy)
            and math.isfinite(qz) and math.isfinite(wx) and math.isfinite(wy)
            and math.isfinite(wz))


@select
def tilt_deg(R22):
    """How far a flipped vehicle's body z is from up [deg] (0 when it is not flipped).
    acos reads 0 for a vehicle that is not flipped (a batch computes both sides)."""
    return math.degrees(math.acos(clamp(R22, -1.0, 0.0))) if R22 < 0.0 else 0.0


@select
def settles(within, last_out, sample_dt, duration, hold):
    """Inside the band at the end, and for the hold time before it."""
    return within != 0.0 and last_out + sample_dt <= duration - hold + 1e-9


@select
def ran_to_end(reason):
    """An ending at the end of the run, not an event on the way."""
    return reason == SETTLED or reason == NOT_SETTLED or reason == SATURATED


@select
def settled_at(reached_end, within, last_out, sample_dt):
    """The time the vehicle entered the band for good; NaN when it ended early or
    outside the band."""
    return last_out + sample_dt if reached_end and within != 0.0 else math.nan


def judge_start(J):
    """J before the first sample."""
    J[0], J[1], J[2], J[3], J[4], J[5] = 0.0, 1.0, 0.0, 0.0, 1.0, 0.0
    J[6], J[7], J[8], J[9], J[10] = 0.0, math.nan, 0.0, 0.0, 0.0


def judge_sample(jc, omega_max, t, x, R, e, saturated, worst, J):
    """One sample of the flight at time t: state x, its rotation R and position error e,
    and whether the controller's demand there is out of the rotors' range (`saturated`,
    `worst` the rotor furthest out). Updates J; returns (reason, value): the event that
    ends the flight here (the first in this order: non-finite, flipped, ground, yaw spin,
    drifted, roll/pitch rate) and the number that ended it, or (0, 0.0)."""
    pos = math.sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2])
    # the attitude error: the rotation angle of R from the level hover at heading 0
    cos_att = clamp(0.5 * ((R[0] + R[4] + R[8]) - 1.0), -1.0, 1.0)
    throttle = x[16] / omega_max[0]
    for i in range(1, len(omega_max)):
        throttle = larger(x[16 + i] / omega_max[i], throttle)
    J[0] = larger(pos, J[0])
    J[1] = smaller(cos_att, J[1])
    J[2] = larger(throttle, J[2])
    J[3] = pos
    J[4] = cos_att
    within = inside_band(pos, jc[0], cos_att, jc[1])
    J[5] = either(within, J[5], t)
    J[6] = flag(within)
    # saturated streaks: start, rotor furthest out at the start, longest so far
    since = J[7]
    rotor = either(streak_begins(saturated, since), worst, J[8])
    since = streak_start(saturated, since, t)
    longer = over(t - since, J[9])
    J[9] = either(longer, t - since, J[9])
    J[10] = either(longer, rotor, J[10])
    J[7] = since
    J[8] = rotor
    # events, the last in the order first so that the first one that holds wins
    rate_xy = math.sqrt(x[10] * x[10] + x[11] * x[11])
    hit = over(rate_xy, jc[4])
    reason = either(hit, RATE, 0)
    value = either(hit, rate_xy, 0.0)
    hit = over(pos, jc[3])
    reason = either(hit, DRIFTED, reason)
    value = either(hit, pos, value)
    yaw_rate = math.fabs(x[12])
    hit = over(yaw_rate, jc[2])
    reason = either(hit, YAW_SPIN, reason)
    value = either(hit, yaw_rate, value)
    hit = under(x[2], 0.0)
    reason = either(hit, GROUND, reason)
    value = either(hit, x[2], value)
    hit = under(R[8], 0.0)
    reason = either(hit, FLIPPED, reason)
    value = either(hit, tilt_deg(R[8]), value)
    finite = all_finite(x[0], x[1], x[2], x[6], x[7], x[8], x[9], x[10], x[11], x[12])
    reason = either(finite, reason, NON_FINITE)
    value = either(finite, value, 0.0)
    return reason, value


def verdict(jc, J):
    """(reason, value) of a flight that flew to the end: settled (in the band for the
    hold time), else saturated when the rotors were at their limits for sat_limit in a
    row (value: the rotor furthest out), else not settled."""
    settled = settles(J[6], J[5], jc[8], jc[5], jc[6])
    starved = at_least(J[9], jc[7] - 1e-9)
    reason = either(settled, SETTLED, either(starved, SATURATED, NOT_SETTLED))
    value = either(settled, 0.0, either(starved, J[10], 0.0))
    return reason, value


def settle_time(jc, reason, J):
    """When the flight entered the band for good (NaN: never, or it ended early)."""
    return settled_at(ran_to_end(reason), J[6], J[5], jc[8])
