"""The hover simulation compiled with numba: one vehicle, or a batch across the cores.

Optional (`pip install 'reedtool[fast]'`): without numba, `available()` is False and the
numpy engines (`run`, `batch`) are all there is; they stay the reference. The equations
are theirs, step for step: the Lee controller at heading 0 and its allocation
(`controller`), the motor model (`motor`), the semi-implicit Euler rigid body with the
exact quaternion exponential (`dynamics`) and the judge of `batch.simulate_batch`. Only
the order of a few sums differs, so results agree to rounding (tests/test_compiled.py
holds them to 1e-9 relative).

The batch runs vehicle by vehicle (`prange` over vehicles, the time loop inside): each
vehicle's state stays in registers and cache, and vehicles that end early stop costing.

Rotor failures: every per-rotor quantity goes through `_fly` as arrays indexed by rotor,
and the rotor speed is advanced in one place (`_advance_motors`); a per-rotor "alive"
mask or failure time belongs there (a dead rotor's command and speed set to 0).
"""

from __future__ import annotations

import math
import time

import numpy as np

from reedtool.sim import HoverConfig
from reedtool.sim.controller import ControllerDesign, ControllerGains

try:        # the extra; everything below the guard needs it
    import numba
    from numba import njit, prange
except ImportError:         # pragma: no cover - exercised where the extra is absent
    numba = None

ENGINE_NUMPY = "numpy"
ENGINE_COMPILED = "numba"


def available() -> bool:
    """True when numba imports (the `fast` extra is installed)."""
    return numba is not None


def unavailable_reason() -> str:
    return ("the compiled engine needs numba: pip install 'reedtool[fast]'")


# Reason codes: batch.REASONS indices (kept literal here: numba needs constants).
_SETTLED, _NOT_SETTLED, _NON_FINITE, _DRIFTED, _RATE, _GROUND, _FLIPPED, _SATURATED, \
    _YAW_SPIN = 1, 2, 3, 4, 5, 6, 7, 8, 9

# Layout of the float outputs per vehicle.
OUT_FIELDS = ("reason_value", "end_time_s", "settle_time_s", "max_position_error_m",
              "min_cos_attitude", "final_position_error_m", "final_cos_attitude",
              "max_throttle", "longest_saturation_s", "last_out_s", "within")
# Layout of the scalar settings vector.
CFG_FIELDS = ("dt", "g", "m_ctl", "kp", "kd", "ki", "kR", "kw", "a_h", "a_v", "i_max",
              "sp_x", "sp_y", "sp_z", "pos_tol", "cos_tol", "yaw_spin", "div_dist",
              "div_rate", "duration", "hold", "sat_limit", "n_steps", "every")
BLOCK = 64              # vehicles per block of the batch kernel (its state fits in L1)
REC_FIXED = 11          # t, x, y, z, R00, R10, R20, R21, R22, pos, cos_att; then omega


if numba is not None:

    @njit(cache=True, error_model="numpy")
    def _rotation(q, R):
        qw, qx, qy, qz = q[0], q[1], q[2], q[3]
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
        R[0, 0] = 1.0 - (yy + zz)
        R[0, 1] = xy - zw
        R[0, 2] = xz + yw
        R[1, 0] = xy + zw
        R[1, 1] = 1.0 - (xx + zz)
        R[1, 2] = yz - xw
        R[2, 0] = xz - yw
        R[2, 1] = yz + xw
        R[2, 2] = 1.0 - (xx + yy)

    @njit(cache=True, error_model="numpy")
    def _control(cfg, Jc, pinv, thrust_max, e, v, integ, R, w, T):
        """controller.control_kernel + allocation_kernel for one vehicle: thrusts into T.

        Returns (saturated, most-out-of-range rotor)."""
        kp, kd, ki = cfg[3], cfg[4], cfg[5]
        kR, kw, a_h, a_v = cfg[6], cfg[7], cfg[8], cfg[9]
        m, g = cfg[2], cfg[1]
        ax = -kp * e[0] - kd * v[0] - ki * integ[0]
        ay = -kp * e[1] - kd * v[1] - ki * integ[1]
        az = -kp * e[2] - kd * v[2] - ki * integ[2]
        h = math.sqrt(ax * ax + ay * ay)
        scale = (m * a_h) / (a_h if a_h > h else h)
        Fx = scale * ax
        Fy = scale * ay
        Fz = (a_v if az > a_v else (-a_v if az < -a_v else az)) + g
        Fz = Fz * m
        F_norm = math.sqrt(Fx * Fx + Fy * Fy + Fz * Fz)
        inv_F = 1.0 / F_norm
        b3x = Fx * inv_F
        b3y = Fy * inv_F
        b3z = Fz * inv_F
        n_sq = b3y * b3y + b3z * b3z
        inv_n = 1.0 / math.sqrt(n_sq)
        b1x = n_sq * inv_n
        u = inv_n * b3x
        A1 = b3y * R[1, 1] + b3z * R[2, 1]
        A2 = b3y * R[1, 2] + b3z * R[2, 2]
        f = F_norm * (b3x * R[0, 2] + A2)
        # 2 e_R = vee(Rd^T R - R^T Rd)
        e0 = (b3x * R[0, 1] + A1) - inv_n * (b3z * R[1, 2] - b3y * R[2, 2])
        e1 = (b1x * R[0, 2] - u * A2) - (b3x * R[0, 0] + b3y * R[1, 0] + b3z * R[2, 0])
        e2 = inv_n * (b3z * R[1, 0] - b3y * R[2, 0]) - (b1x * R[0, 1] - u * A1)
        # tau = w x J w - J (kR e_R + kw w)
        s0 = 0.5 * kR * e0 + kw * w[0]
        s1 = 0.5 * kR * e1 + kw * w[1]
        s2 = 0.5 * kR * e2 + kw * w[2]
        Jw0 = Jc[0, 0] * w[0] + Jc[0, 1] * w[1] + Jc[0, 2] * w[2]
        Jw1 = Jc[1, 0] * w[0] + Jc[1, 1] * w[1] + Jc[1, 2] * w[2]
        Jw2 = Jc[2, 0] * w[0] + Jc[2, 1] * w[1] + Jc[2, 2] * w[2]
        t0 = (w[1] * Jw2 - w[2] * Jw1) - (Jc[0, 0] * s0 + Jc[0, 1] * s1 + Jc[0, 2] * s2)
        t1 = (w[2] * Jw0 - w[0] * Jw2) - (Jc[1, 0] * s0 + Jc[1, 1] * s1 + Jc[1, 2] * s2)
        t2 = (w[0] * Jw1 - w[1] * Jw0) - (Jc[2, 0] * s0 + Jc[2, 1] * s1 + Jc[2, 2] * s2)
        n = T.shape[0]
        out = False
        for i in range(n):
            T[i] = pinv[i, 0] * f + pinv[i, 1] * t0 + pinv[i, 2] * t1 + pinv[i, 3] * t2
            if T[i] < 0.0 or T[i] > thrust_max[i]:
                out = True
        if not out:
            return False, 0
        worst = 0
        worst_excess = -np.inf
        for i in range(n):
            hi = thrust_max[i]
            excess = max(-T[i], T[i] - hi) / hi
            if excess > worst_excess:
                worst_excess = excess
                worst = i
        _prioritised(pinv, thrust_max, f, t0, t1, t2, T)
        return True, worst

    @njit(cache=True, error_model="numpy")
    def _prioritised(pinv, thrust_max, f, t0, t1, t2, T):
        """controller._prioritised for one vehicle: thrust, then roll/pitch, then yaw."""
        n = T.shape[0]
        fit = 1.0
        any_over = False
        for i in range(n):
            T[i] = pinv[i, 0] * f
            if T[i] > thrust_max[i]:
                ratio = thrust_max[i] / T[i]
                if not any_over or ratio < fit:
                    fit = ratio
                any_over = True
        for i in range(n):
            b = T[i] * fit if any_over else T[i]
            T[i] = min(max(b, 0.0), thrust_max[i])
        for stage in range(2):
            scale = np.inf
            for i in range(n):
                d = pinv[i, 1] * t0 + pinv[i, 2] * t1 if stage == 0 else pinv[i, 3] * t2
                if d > 0.0:
                    room = (thrust_max[i] - T[i]) / d
                    if room < scale:
                        scale = room
                elif d < 0.0:
                    room = -T[i] / d
                    if room < scale:
                        scale = room
            scale = min(max(scale, 0.0), 1.0)
            for i in range(n):
                d = pinv[i, 1] * t0 + pinv[i, 2] * t1 if stage == 0 else pinv[i, 3] * t2
                T[i] = T[i] + scale * d
        for i in range(n):
            T[i] = min(max(T[i], 0.0), thrust_max[i])

    @njit(cache=True, error_model="numpy")
    def _body_wrench(pos, axis, tmap, cd, cr, k, shift, omega, R, v, w, Fb, Tb):
        """dynamics.body_wrench_kernel for one vehicle: force and torque about the true
        COM, body axes (thrust, yaw drag, rotor drag, rolling moment)."""
        for a in range(3):
            Fb[a] = 0.0
            Tb[a] = 0.0
        # velocity of the nominal COM, body axes: R^T v - w x shift
        xi0 = R[0, 0] * v[0] + R[1, 0] * v[1] + R[2, 0] * v[2]
        xi1 = R[0, 1] * v[0] + R[1, 1] * v[1] + R[2, 1] * v[2]
        xi2 = R[0, 2] * v[0] + R[1, 2] * v[1] + R[2, 2] * v[2]
        xi0 -= w[1] * shift[2] - w[2] * shift[1]
        xi1 -= w[2] * shift[0] - w[0] * shift[2]
        xi2 -= w[0] * shift[1] - w[1] * shift[0]
        for i in range(omega.shape[0]):
            om = omega[i]
            Th = k[i] * om * om
            a0, a1, a2 = axis[i, 0], axis[i, 1], axis[i, 2]
            Fb[0] += a0 * Th
            Fb[1] += a1 * Th
            Fb[2] += a2 * Th
            Tb[0] += tmap[0, i] * Th
            Tb[1] += tmap[1, i] * Th
            Tb[2] += tmap[2, i] * Th
            if cd[i] != 0.0 or cr[i] != 0.0:
                r0, r1, r2 = pos[i, 0], pos[i, 1], pos[i, 2]
                u0 = xi0 + (w[1] * r2 - w[2] * r1)
                u1 = xi1 + (w[2] * r0 - w[0] * r2)
                u2 = xi2 + (w[0] * r1 - w[1] * r0)
                along = a0 * u0 + a1 * u1 + a2 * u2
                p0 = u0 - a0 * along
                p1 = u1 - a1 * along
                p2 = u2 - a2 * along
                dc = -om * cd[i]
                d0, d1, d2 = dc * p0, dc * p1, dc * p2
                Fb[0] += d0
                Fb[1] += d1
                Fb[2] += d2
                rc = -om * cr[i]
                Tb[0] += r1 * d2 - r2 * d1 + rc * p0
                Tb[1] += r2 * d0 - r0 * d2 + rc * p1
                Tb[2] += r0 * d1 - r1 * d0 + rc * p2
        # moments about the true COM: tau - shift x F
        c0 = shift[1] * Fb[2] - shift[2] * Fb[1]
        c1 = shift[2] * Fb[0] - shift[0] * Fb[2]
        c2 = shift[0] * Fb[1] - shift[1] * Fb[0]
        Tb[0] -= c0
        Tb[1] -= c1
        Tb[2] -= c2

    @njit(cache=True, error_model="numpy")
    def _rigid_body(dt, g, mass, J0, J0inv, S, R, Fb, Tb, p, v, q, w):
        """dynamics.rigid_body_kernel for one vehicle: semi-implicit Euler, in place."""
        f0 = Fb[0] * (dt / mass)
        f1 = Fb[1] * (dt / mass)
        f2 = Fb[2] * (dt / mass)
        v[0] += R[0, 0] * f0 + R[0, 1] * f1 + R[0, 2] * f2
        v[1] += R[1, 0] * f0 + R[1, 1] * f1 + R[1, 2] * f2
        v[2] += R[2, 0] * f0 + R[2, 1] * f1 + R[2, 2] * f2
        v[2] -= dt * g
        # Euler's equations with J = S J0 S: J w' = tau - w x J w
        sw0, sw1, sw2 = S[0] * w[0], S[1] * w[1], S[2] * w[2]
        Jw0 = S[0] * (J0[0, 0] * sw0 + J0[0, 1] * sw1 + J0[0, 2] * sw2)
        Jw1 = S[1] * (J0[1, 0] * sw0 + J0[1, 1] * sw1 + J0[1, 2] * sw2)
        Jw2 = S[2] * (J0[2, 0] * sw0 + J0[2, 1] * sw1 + J0[2, 2] * sw2)
        h0 = (Tb[0] - (w[1] * Jw2 - w[2] * Jw1)) / S[0]
        h1 = (Tb[1] - (w[2] * Jw0 - w[0] * Jw2)) / S[1]
        h2 = (Tb[2] - (w[0] * Jw1 - w[1] * Jw0)) / S[2]
        w[0] += (J0inv[0, 0] * h0 + J0inv[0, 1] * h1 + J0inv[0, 2] * h2) * (dt / S[0])
        w[1] += (J0inv[1, 0] * h0 + J0inv[1, 1] * h1 + J0inv[1, 2] * h2) * (dt / S[1])
        w[2] += (J0inv[2, 0] * h0 + J0inv[2, 1] * h1 + J0inv[2, 2] * h2) * (dt / S[2])
        p[0] += dt * v[0]
        p[1] += dt * v[1]
        p[2] += dt * v[2]
        # q * exp(w dt / 2) as q * (|w| / tan h, w), renormalised
        wx, wy, wz = w[0], w[1], w[2]
        rate = math.sqrt(wx * wx + wy * wy + wz * wz)
        tan_h = math.tan(0.5 * dt * rate)
        a = rate / tan_h if tan_h != 0.0 else 1.0
        qw, qx, qy, qz = q[0], q[1], q[2], q[3]
        nw = qw * a - qx * wx - qy * wy - qz * wz
        nx = qx * a + qw * wx + qy * wz - qz * wy
        ny = qy * a + qw * wy + qz * wx - qx * wz
        nz = qz * a + qw * wz + qx * wy - qy * wx
        inv_q = 1.0 / math.sqrt(nw * nw + nx * nx + ny * ny + nz * nz)
        q[0] = nw * inv_q
        q[1] = nx * inv_q
        q[2] = ny * inv_q
        q[3] = nz * inv_q

    @njit(cache=True, error_model="numpy")
    def _advance_motors(T, inv_k, up, down, omega):
        """motor.speed_command (the allocation keeps T in range) and the first-order lag.
        The one place a per-rotor failure (alive mask) would zero the command and speed."""
        for i in range(omega.shape[0]):
            cmd = math.sqrt(T[i] * inv_k[i]) if T[i] > 0.0 else 0.0
            omega[i] = cmd + (omega[i] - cmd) * (up[i] if cmd > omega[i] else down[i])

    @njit(cache=True, error_model="numpy")
    def _fly(cfg, nominal, mass, S, shift, k, state0, out_f, out_i, final, rec, pos_rec):
        """Fly one vehicle from state0 (p, v, q, w, integral, omega) as batch.simulate_batch judges it.

        Fills out_f (OUT_FIELDS), out_i (reason, longest-saturation rotor), final
        (p, v, q, w, omega when it ended), and rec (one row per sample) when it has rows; returns the samples written.
        """
        pos_r, axis, tmap, cd, cr, up, down, pinv, thrust_max, inv_k, omega_max, Jc, J0, \
            J0inv = nominal
        dt, g = cfg[0], cfg[1]
        ki_dt, i_max = dt, cfg[10]
        n_steps, every = int(cfg[22]), int(cfg[23])
        n = k.shape[0]
        p = state0[0:3].copy()
        v = state0[3:6].copy()
        q = state0[6:10].copy()
        w = state0[10:13].copy()
        integ = state0[13:16].copy()
        omega = state0[16:16 + n].copy()
        e = np.zeros(3)
        R = np.empty((3, 3))
        T = np.empty(n)
        Fb = np.empty(3)
        Tb = np.empty(3)
        sp0, sp1, sp2 = cfg[11], cfg[12], cfg[13]
        sample_dt = every * dt
        reason = 0
        value = 0.0
        end_time = cfg[19]
        max_pos = 0.0
        min_cos = 1.0
        max_throttle = 0.0
        final_pos = 0.0
        final_cos = 1.0
        last_out = 0.0
        within = False
        sat_since = np.nan
        sat_rotor = 0
        sat_longest = 0.0
        sat_longest_rotor = 0
        n_rec = 0
        for step in range(n_steps + 1):
            t = step * dt
            _rotation(q, R)
            e[0] = p[0] - sp0
            e[1] = p[1] - sp1
            e[2] = p[2] - sp2
            last = step == n_steps
            saturated, worst = _control(cfg, Jc, pinv, thrust_max, e, v, integ, R, w, T)
            if step % every == 0 or last:
                pos = math.sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2])
                cos_att = min(max(0.5 * ((R[0, 0] + R[1, 1] + R[2, 2]) - 1.0), -1.0), 1.0)
                throttle = omega[0] / omega_max[0]
                for i in range(1, n):
                    ratio = omega[i] / omega_max[i]
                    if ratio > throttle:
                        throttle = ratio
                if pos > max_pos:
                    max_pos = pos
                if cos_att < min_cos:
                    min_cos = cos_att
                if throttle > max_throttle:
                    max_throttle = throttle
                final_pos = pos
                final_cos = cos_att
                within = pos <= cfg[14] and cos_att >= cfg[15]
                if not within:
                    last_out = t
                if saturated:
                    if math.isnan(sat_since):
                        sat_since = t
                        sat_rotor = worst
                    if t - sat_since > sat_longest:
                        sat_longest = t - sat_since
                        sat_longest_rotor = sat_rotor
                else:
                    sat_since = np.nan
                if n_rec < pos_rec.shape[0]:
                    pos_rec[n_rec] = pos
                if n_rec < rec.shape[0]:
                    rec[n_rec, 0] = t
                    rec[n_rec, 1] = p[0]
                    rec[n_rec, 2] = p[1]
                    rec[n_rec, 3] = p[2]
                    rec[n_rec, 4] = R[0, 0]
                    rec[n_rec, 5] = R[1, 0]
                    rec[n_rec, 6] = R[2, 0]
                    rec[n_rec, 7] = R[2, 1]
                    rec[n_rec, 8] = R[2, 2]
                    rec[n_rec, 9] = pos
                    rec[n_rec, 10] = cos_att
                    for i in range(n):
                        rec[n_rec, REC_FIXED + i] = omega[i]
                n_rec += 1
                rate_xy = math.sqrt(w[0] * w[0] + w[1] * w[1])
                finite = True
                for x in (p[0], p[1], p[2], q[0], q[1], q[2], q[3], w[0], w[1], w[2]):
                    if not math.isfinite(x):
                        finite = False
                if not finite:
                    reason, value = _NON_FINITE, 0.0
                elif R[2, 2] < 0.0:
                    reason = _FLIPPED
                    value = math.degrees(math.acos(max(R[2, 2], -1.0)))
                elif p[2] < 0.0:
                    reason, value = _GROUND, p[2]
                elif abs(w[2]) > cfg[16]:
                    reason, value = _YAW_SPIN, abs(w[2])
                elif pos > cfg[17]:
                    reason, value = _DRIFTED, pos
                elif rate_xy > cfg[18]:
                    reason, value = _RATE, rate_xy
                if reason != 0:
                    end_time = t
                    break
                if last:
                    if within and last_out + sample_dt <= cfg[19] - cfg[20] + 1e-9:
                        reason = _SETTLED
                    elif sat_longest >= cfg[21] - 1e-9:
                        reason = _SATURATED
                        value = float(sat_longest_rotor)
                    else:
                        reason = _NOT_SETTLED
                    break
            # ---- advance one step: wrench at the current speeds, then the speeds respond
            _body_wrench(pos_r, axis, tmap, cd, cr, k, shift, omega, R, v, w, Fb, Tb)
            _advance_motors(T, inv_k, up, down, omega)
            _rigid_body(dt, g, mass, J0, J0inv, S, R, Fb, Tb, p, v, q, w)
            for a in range(3):
                integ[a] += e[a] * ki_dt
                integ[a] = min(max(integ[a], -i_max), i_max)
        out_i[0] = reason
        out_i[1] = sat_longest_rotor
        out_f[0] = value
        out_f[1] = end_time
        reached_end = reason == _SETTLED or reason == _NOT_SETTLED or reason == _SATURATED
        out_f[2] = last_out + sample_dt if reached_end and within else np.nan
        out_f[3] = max_pos
        out_f[4] = min_cos
        out_f[5] = final_pos
        out_f[6] = final_cos
        out_f[7] = max_throttle
        out_f[8] = sat_longest
        out_f[9] = last_out
        out_f[10] = 1.0 if within else 0.0
        final[0:3] = p
        final[3:6] = v
        final[6:10] = q
        final[10:13] = w
        final[13:13 + n] = omega
        return n_rec

    @njit(cache=True, error_model="numpy")
    def _stage_control(cfg, Jc, p, v, q, w, integ, R, e, ctl, out):
        """Rotation, position error and the control law for every vehicle of a block."""
        g, m_ctl = cfg[1], cfg[2]
        kp, kd, ki, kR, kw, a_h, a_v = cfg[3], cfg[4], cfg[5], cfg[6], cfg[7], cfg[8], cfg[9]
        sp0, sp1, sp2 = cfg[11], cfg[12], cfg[13]
        for j in range(p.shape[1]):
            qw, qx, qy, qz = q[0, j], q[1, j], q[2, j], q[3, j]
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
            R00 = 1.0 - (yy + zz)
            R01 = xy - zw
            R02 = xz + yw
            R10 = xy + zw
            R11 = 1.0 - (xx + zz)
            R12 = yz - xw
            R20 = xz - yw
            R21 = yz + xw
            R22 = 1.0 - (xx + yy)
            R[0, j] = R00
            R[1, j] = R01
            R[2, j] = R02
            R[3, j] = R10
            R[4, j] = R11
            R[5, j] = R12
            R[6, j] = R20
            R[7, j] = R21
            R[8, j] = R22
            e0 = p[0, j] - sp0
            e1 = p[1, j] - sp1
            e2 = p[2, j] - sp2
            e[0, j] = e0
            e[1, j] = e1
            e[2, j] = e2
            ax = -kp * e0 - kd * v[0, j] - ki * integ[0, j]
            ay = -kp * e1 - kd * v[1, j] - ki * integ[1, j]
            az = -kp * e2 - kd * v[2, j] - ki * integ[2, j]
            h = math.sqrt(ax * ax + ay * ay)
            scale = (m_ctl * a_h) / (a_h if a_h > h else h)
            Fx = scale * ax
            Fy = scale * ay
            Fz = (a_v if az > a_v else (-a_v if az < -a_v else az)) + g
            Fz = Fz * m_ctl
            F_norm = math.sqrt(Fx * Fx + Fy * Fy + Fz * Fz)
            inv_F = 1.0 / F_norm
            b3x = Fx * inv_F
            b3y = Fy * inv_F
            b3z = Fz * inv_F
            n_sq = b3y * b3y + b3z * b3z
            inv_n = 1.0 / math.sqrt(n_sq)
            b1x = n_sq * inv_n
            u = inv_n * b3x
            A1 = b3y * R11 + b3z * R21
            A2 = b3y * R12 + b3z * R22
            ctl[0, j] = F_norm * (b3x * R02 + A2)
            er0 = (b3x * R01 + A1) - inv_n * (b3z * R12 - b3y * R22)
            er1 = (b1x * R02 - u * A2) - (b3x * R00 + b3y * R10 + b3z * R20)
            er2 = inv_n * (b3z * R10 - b3y * R20) - (b1x * R01 - u * A1)
            w0, w1, w2 = w[0, j], w[1, j], w[2, j]
            s0 = 0.5 * kR * er0 + kw * w0
            s1 = 0.5 * kR * er1 + kw * w1
            s2 = 0.5 * kR * er2 + kw * w2
            Jw0 = Jc[0, 0] * w0 + Jc[0, 1] * w1 + Jc[0, 2] * w2
            Jw1 = Jc[1, 0] * w0 + Jc[1, 1] * w1 + Jc[1, 2] * w2
            Jw2 = Jc[2, 0] * w0 + Jc[2, 1] * w1 + Jc[2, 2] * w2
            ctl[1, j] = (w1 * Jw2 - w2 * Jw1) - (Jc[0, 0] * s0 + Jc[0, 1] * s1 + Jc[0, 2] * s2)
            ctl[2, j] = (w2 * Jw0 - w0 * Jw2) - (Jc[1, 0] * s0 + Jc[1, 1] * s1 + Jc[1, 2] * s2)
            ctl[3, j] = (w0 * Jw1 - w1 * Jw0) - (Jc[2, 0] * s0 + Jc[2, 1] * s1 + Jc[2, 2] * s2)
            out[j] = False

    @njit(cache=True, error_model="numpy")
    def _stage_allocate(pinv, thrust_max, ctl, T, out):
        """The pseudo-inverse thrusts; `out` marks the vehicles with a rotor out of range."""
        for i in range(T.shape[0]):
            c0, c1, c2, c3, hi = pinv[i, 0], pinv[i, 1], pinv[i, 2], pinv[i, 3], thrust_max[i]
            for j in range(T.shape[1]):
                Ti = c0 * ctl[0, j] + c1 * ctl[1, j] + c2 * ctl[2, j] + c3 * ctl[3, j]
                T[i, j] = Ti
                out[j] = out[j] | (Ti < 0.0) | (Ti > hi)

    @njit(cache=True, error_model="numpy")
    def _stage_wrench(pos_r, axis, tmap, cd, cr, k, shift, omega, R, v, w, xi, Fb, Tb):
        """Body force and torque about the nominal COM (rotor loop outside, vehicles inside)."""
        for j in range(v.shape[1]):
            R00, R01, R02 = R[0, j], R[1, j], R[2, j]
            R10, R11, R12 = R[3, j], R[4, j], R[5, j]
            R20, R21, R22 = R[6, j], R[7, j], R[8, j]
            v0, v1, v2 = v[0, j], v[1, j], v[2, j]
            w0, w1, w2 = w[0, j], w[1, j], w[2, j]
            s0, s1, s2 = shift[0, j], shift[1, j], shift[2, j]
            xi[0, j] = (R00 * v0 + R10 * v1 + R20 * v2) - (w1 * s2 - w2 * s1)
            xi[1, j] = (R01 * v0 + R11 * v1 + R21 * v2) - (w2 * s0 - w0 * s2)
            xi[2, j] = (R02 * v0 + R12 * v1 + R22 * v2) - (w0 * s1 - w1 * s0)
            for a in range(3):
                Fb[a, j] = 0.0
                Tb[a, j] = 0.0
        for i in range(omega.shape[0]):
            a0, a1, a2 = axis[i, 0], axis[i, 1], axis[i, 2]
            m0, m1, m2 = tmap[0, i], tmap[1, i], tmap[2, i]
            drag = cd[i] != 0.0 or cr[i] != 0.0
            r0, r1, r2 = pos_r[i, 0], pos_r[i, 1], pos_r[i, 2]
            cdi, cri = cd[i], cr[i]
            for j in range(v.shape[1]):
                om = omega[i, j]
                Th = k[i, j] * om * om
                f0 = a0 * Th
                f1 = a1 * Th
                f2 = a2 * Th
                q0 = m0 * Th
                q1 = m1 * Th
                q2 = m2 * Th
                if drag:
                    w0, w1, w2 = w[0, j], w[1, j], w[2, j]
                    u0 = xi[0, j] + (w1 * r2 - w2 * r1)
                    u1 = xi[1, j] + (w2 * r0 - w0 * r2)
                    u2 = xi[2, j] + (w0 * r1 - w1 * r0)
                    along = a0 * u0 + a1 * u1 + a2 * u2
                    p0 = u0 - a0 * along
                    p1 = u1 - a1 * along
                    p2 = u2 - a2 * along
                    dc = -om * cdi
                    d0, d1, d2 = dc * p0, dc * p1, dc * p2
                    f0 += d0
                    f1 += d1
                    f2 += d2
                    rc = -om * cri
                    q0 += r1 * d2 - r2 * d1 + rc * p0
                    q1 += r2 * d0 - r0 * d2 + rc * p1
                    q2 += r0 * d1 - r1 * d0 + rc * p2
                Fb[0, j] += f0
                Fb[1, j] += f1
                Fb[2, j] += f2
                Tb[0, j] += q0
                Tb[1, j] += q1
                Tb[2, j] += q2

    @njit(cache=True, error_model="numpy")
    def _stage_motors(T, inv_k, up, down, omega):
        for i in range(T.shape[0]):
            ik, fu, fd = inv_k[i], up[i], down[i]
            for j in range(T.shape[1]):
                Ti = T[i, j]
                cmd = math.sqrt(Ti * ik) if Ti > 0.0 else 0.0
                om = omega[i, j]
                omega[i, j] = cmd + (om - cmd) * (fu if cmd > om else fd)

    @njit(cache=True, error_model="numpy")
    def _stage_body(cfg, J0, J0inv, S, shift, dt_m, Fb, Tb, R, p, v, w, e, integ, aq, big):
        """Semi-implicit Euler for p, v, w and the integral; the quaternion step factor
        into aq. Returns how many vehicles need tan for it (big)."""
        dt, g, i_max = cfg[0], cfg[1], cfg[10]
        half_dt = 0.5 * dt
        two_over_dt = 2.0 / dt
        n_big = 0
        for j in range(v.shape[1]):
            F0, F1, F2 = Fb[0, j], Fb[1, j], Fb[2, j]
            s0, s1, s2 = shift[0, j], shift[1, j], shift[2, j]
            t0 = Tb[0, j] - (s1 * F2 - s2 * F1)
            t1 = Tb[1, j] - (s2 * F0 - s0 * F2)
            t2 = Tb[2, j] - (s0 * F1 - s1 * F0)
            fm = dt_m[j]
            f0 = F0 * fm
            f1 = F1 * fm
            f2 = F2 * fm
            v0 = v[0, j] + (R[0, j] * f0 + R[1, j] * f1 + R[2, j] * f2)
            v1 = v[1, j] + (R[3, j] * f0 + R[4, j] * f1 + R[5, j] * f2)
            v2 = v[2, j] + (R[6, j] * f0 + R[7, j] * f1 + R[8, j] * f2)
            v2 -= dt * g
            v[0, j] = v0
            v[1, j] = v1
            v[2, j] = v2
            S0, S1, S2 = S[0, j], S[1, j], S[2, j]
            w0, w1, w2 = w[0, j], w[1, j], w[2, j]
            sw0, sw1, sw2 = S0 * w0, S1 * w1, S2 * w2
            Jw0 = S0 * (J0[0, 0] * sw0 + J0[0, 1] * sw1 + J0[0, 2] * sw2)
            Jw1 = S1 * (J0[1, 0] * sw0 + J0[1, 1] * sw1 + J0[1, 2] * sw2)
            Jw2 = S2 * (J0[2, 0] * sw0 + J0[2, 1] * sw1 + J0[2, 2] * sw2)
            h0 = (t0 - (w1 * Jw2 - w2 * Jw1)) / S0
            h1 = (t1 - (w2 * Jw0 - w0 * Jw2)) / S1
            h2 = (t2 - (w0 * Jw1 - w1 * Jw0)) / S2
            w0 += (J0inv[0, 0] * h0 + J0inv[0, 1] * h1 + J0inv[0, 2] * h2) * (dt / S0)
            w1 += (J0inv[1, 0] * h0 + J0inv[1, 1] * h1 + J0inv[1, 2] * h2) * (dt / S1)
            w2 += (J0inv[2, 0] * h0 + J0inv[2, 1] * h1 + J0inv[2, 2] * h2) * (dt / S2)
            w[0, j] = w0
            w[1, j] = w1
            w[2, j] = w2
            p[0, j] += dt * v0
            p[1, j] += dt * v1
            p[2, j] += dt * v2
            # q * (|w| / tan h, w) with h = |w| dt / 2: for h < 0.1, |w| / tan h =
            # (2 / dt) h cot h by its series (to ~1e-16, and vectorisable); a larger h
            # (a tumbling vehicle) gets tan in the pass below
            hh = half_dt * half_dt * (w0 * w0 + w1 * w1 + w2 * w2)
            aq[j] = two_over_dt * (1.0 - hh * (1.0 / 3.0 + hh * (1.0 / 45.0 + hh * (
                2.0 / 945.0 + hh * (1.0 / 4725.0 + hh * (2.0 / 93555.0))))))
            large = hh >= 0.01
            big[j] = large
            n_big += 1 if large else 0
            for a3 in range(3):
                ia = integ[a3, j] + e[a3, j] * dt
                integ[a3, j] = -i_max if ia < -i_max else (i_max if ia > i_max else ia)
        return n_big

    @njit(cache=True, error_model="numpy")
    def _stage_quaternion(q, w, aq):
        for j in range(q.shape[1]):
            a = aq[j]
            w0, w1, w2 = w[0, j], w[1, j], w[2, j]
            qw, qx, qy, qz = q[0, j], q[1, j], q[2, j], q[3, j]
            nw = qw * a - qx * w0 - qy * w1 - qz * w2
            nx = qx * a + qw * w0 + qy * w2 - qz * w1
            ny = qy * a + qw * w1 + qz * w0 - qx * w2
            nz = qz * a + qw * w2 + qx * w1 - qy * w0
            inv_q = 1.0 / math.sqrt(nw * nw + nx * nx + ny * ny + nz * nz)
            q[0, j] = nw * inv_q
            q[1, j] = nx * inv_q
            q[2, j] = ny * inv_q
            q[3, j] = nz * inv_q

    @njit(cache=True, error_model="numpy")
    def _fly_block(cfg, nominal, mass, S, shift, k, state0, out_f, out_i, final, pos_rec):
        """_fly for a block of B vehicles at once (columns), so that each stage is a loop
        over vehicles that the compiler turns into SIMD instructions. The same arithmetic
        as _fly, vehicle for vehicle; vehicles that end are parked at a level hover (as
        the numpy batch parks them) and no longer judged."""
        pos_r, axis, tmap, cd, cr, up, down, pinv, thrust_max, inv_k, omega_max, Jc, J0, \
            J0inv = nominal
        dt, g, m_ctl = cfg[0], cfg[1], cfg[2]
        kp, kd, ki, kR, kw, a_h, a_v, i_max = (cfg[3], cfg[4], cfg[5], cfg[6], cfg[7],
                                               cfg[8], cfg[9], cfg[10])
        sp0, sp1, sp2 = cfg[11], cfg[12], cfg[13]
        n_steps, every = int(cfg[22]), int(cfg[23])
        sample_dt = every * dt
        n, B = k.shape[0], mass.shape[0]
        p = np.empty((3, B))
        v = np.empty((3, B))
        q = np.empty((4, B))
        w = np.empty((3, B))
        integ = np.empty((3, B))
        omega = np.empty((n, B))
        for j in range(B):
            for a in range(3):
                p[a, j] = state0[a]
                v[a, j] = state0[3 + a]
                w[a, j] = state0[10 + a]
                integ[a, j] = state0[13 + a]
            for a in range(4):
                q[a, j] = state0[6 + a]
            for i in range(n):
                omega[i, j] = state0[16 + i]
        R = np.empty((9, B))
        e = np.empty((3, B))
        ctl = np.empty((4, B))
        T = np.empty((n, B))
        Fb = np.empty((3, B))
        Tb = np.empty((3, B))
        xi = np.empty((3, B))
        out = np.zeros(B, dtype=np.bool_)
        big = np.zeros(B, dtype=np.bool_)
        aq = np.empty(B)
        dt_m = np.empty(B)
        for j in range(B):
            dt_m[j] = dt / mass[j]
        running = np.ones(B, dtype=np.bool_)
        n_running = B
        reason = np.zeros(B, dtype=np.int64)
        value = np.zeros(B)
        end_time = np.full(B, cfg[19])
        max_pos = np.zeros(B)
        min_cos = np.ones(B)
        max_thr = np.zeros(B)
        final_pos = np.zeros(B)
        final_cos = np.ones(B)
        last_out = np.zeros(B)
        within = np.zeros(B, dtype=np.bool_)
        sat_since = np.full(B, np.nan)
        sat_rotor = np.zeros(B, dtype=np.int64)
        sat_longest = np.zeros(B)
        sat_longest_rotor = np.zeros(B, dtype=np.int64)
        worst = np.zeros(B, dtype=np.int64)
        Tcol = np.empty(n)
        n_rec = 0
        half_dt = 0.5 * dt
        two_over_dt = 2.0 / dt
        for step in range(n_steps + 1):
            t = step * dt
            last = step == n_steps
            sample = step % every == 0 or last
            # ---- rotation, error, control law (one vectorised pass)
            _stage_control(cfg, Jc, p, v, q, w, integ, R, e, ctl, out)
            # ---- allocation: pseudo-inverse, then desaturate the (rare) columns out of range
            _stage_allocate(pinv, thrust_max, ctl, T, out)
            for j in range(B):
                if out[j]:
                    best = -np.inf
                    for i in range(n):
                        hi = thrust_max[i]
                        excess = max(-T[i, j], T[i, j] - hi) / hi
                        if excess > best:
                            best = excess
                            worst[j] = i
                    _prioritised(pinv, thrust_max, ctl[0, j], ctl[1, j], ctl[2, j], ctl[3, j],
                                 Tcol)
                    for i in range(n):
                        T[i, j] = Tcol[i]
            # ---- the judge, for the vehicles still flying
            if sample:
                for j in range(B):
                    if not running[j]:
                        if n_rec < pos_rec.shape[1]:
                            pos_rec[j, n_rec] = np.nan
                        continue
                    e0, e1, e2 = e[0, j], e[1, j], e[2, j]
                    pos = math.sqrt(e0 * e0 + e1 * e1 + e2 * e2)
                    cos_att = min(max(0.5 * ((R[0, j] + R[4, j] + R[8, j]) - 1.0), -1.0), 1.0)
                    throttle = omega[0, j] / omega_max[0]
                    for i in range(1, n):
                        ratio = omega[i, j] / omega_max[i]
                        if ratio > throttle:
                            throttle = ratio
                    if pos > max_pos[j]:
                        max_pos[j] = pos
                    if cos_att < min_cos[j]:
                        min_cos[j] = cos_att
                    if throttle > max_thr[j]:
                        max_thr[j] = throttle
                    final_pos[j] = pos
                    final_cos[j] = cos_att
                    within[j] = pos <= cfg[14] and cos_att >= cfg[15]
                    if not within[j]:
                        last_out[j] = t
                    if out[j]:
                        if math.isnan(sat_since[j]):
                            sat_since[j] = t
                            sat_rotor[j] = worst[j]
                        if t - sat_since[j] > sat_longest[j]:
                            sat_longest[j] = t - sat_since[j]
                            sat_longest_rotor[j] = sat_rotor[j]
                    else:
                        sat_since[j] = np.nan
                    if n_rec < pos_rec.shape[1]:
                        pos_rec[j, n_rec] = pos
                    wx, wy, wz = w[0, j], w[1, j], w[2, j]
                    rate_xy = math.sqrt(wx * wx + wy * wy)
                    finite = (math.isfinite(p[0, j]) and math.isfinite(p[1, j])
                              and math.isfinite(p[2, j]) and math.isfinite(q[0, j])
                              and math.isfinite(q[1, j]) and math.isfinite(q[2, j])
                              and math.isfinite(q[3, j]) and math.isfinite(wx)
                              and math.isfinite(wy) and math.isfinite(wz))
                    why = 0
                    val = 0.0
                    if not finite:
                        why = _NON_FINITE
                    elif R[8, j] < 0.0:
                        why = _FLIPPED
                        val = math.degrees(math.acos(max(R[8, j], -1.0)))
                    elif p[2, j] < 0.0:
                        why, val = _GROUND, p[2, j]
                    elif abs(wz) > cfg[16]:
                        why, val = _YAW_SPIN, abs(wz)
                    elif pos > cfg[17]:
                        why, val = _DRIFTED, pos
                    elif rate_xy > cfg[18]:
                        why, val = _RATE, rate_xy
                    if why != 0:
                        reason[j] = why
                        value[j] = val
                        end_time[j] = t
                        running[j] = False
                        n_running -= 1
                        for a in range(3):          # park: level hover at the setpoint
                            final[j, a] = p[a, j]
                            final[j, 3 + a] = v[a, j]
                            final[j, 10 + a] = w[a, j]
                            p[a, j] = cfg[11 + a]
                            v[a, j] = 0.0
                            w[a, j] = 0.0
                            integ[a, j] = 0.0
                        for a in range(4):
                            final[j, 6 + a] = q[a, j]
                            q[a, j] = 1.0 if a == 0 else 0.0
                        for i in range(n):
                            final[j, 13 + i] = omega[i, j]
                            omega[i, j] = state0[16 + i]
                    elif last:
                        if within[j] and last_out[j] + sample_dt <= cfg[19] - cfg[20] + 1e-9:
                            reason[j] = _SETTLED
                        elif sat_longest[j] >= cfg[21] - 1e-9:
                            reason[j] = _SATURATED
                            value[j] = float(sat_longest_rotor[j])
                        else:
                            reason[j] = _NOT_SETTLED
                n_rec += 1
                if last or n_running == 0:
                    break
            # ---- body wrench at the current speeds (rotor loop outside, vehicles inside)
            _stage_wrench(pos_r, axis, tmap, cd, cr, k, shift, omega, R, v, w, xi, Fb, Tb)
            # ---- the speeds respond
            _stage_motors(T, inv_k, up, down, omega)
            # ---- rigid body, semi-implicit Euler
            any_big = _stage_body(cfg, J0, J0inv, S, shift, dt_m, Fb, Tb, R, p, v, w, e,
                                  integ, aq, big) > 0
            if any_big:
                for j in range(B):
                    if big[j]:
                        rate = math.sqrt(w[0, j] * w[0, j] + w[1, j] * w[1, j]
                                         + w[2, j] * w[2, j])
                        tan_h = math.tan(half_dt * rate)
                        aq[j] = rate / tan_h if tan_h != 0.0 else 1.0
            _stage_quaternion(q, w, aq)
        for j in range(B):
            out_i[j, 0] = reason[j]
            out_i[j, 1] = sat_longest_rotor[j]
            reached = running[j]
            out_f[j, 0] = value[j]
            out_f[j, 1] = end_time[j]
            out_f[j, 2] = last_out[j] + sample_dt if reached and within[j] else np.nan
            out_f[j, 3] = max_pos[j]
            out_f[j, 4] = min_cos[j]
            out_f[j, 5] = final_pos[j]
            out_f[j, 6] = final_cos[j]
            out_f[j, 7] = max_thr[j]
            out_f[j, 8] = sat_longest[j]
            out_f[j, 9] = last_out[j]
            out_f[j, 10] = 1.0 if within[j] else 0.0
            if reached:
                for a in range(3):
                    final[j, a] = p[a, j]
                    final[j, 3 + a] = v[a, j]
                    final[j, 10 + a] = w[a, j]
                for a in range(4):
                    final[j, 6 + a] = q[a, j]
                for i in range(n):
                    final[j, 13 + i] = omega[i, j]

    @njit(cache=True, parallel=True, error_model="numpy")
    def _fly_batch(cfg, nominal, mass, S, shift, k, state0, out_f, out_i, final, pos_rec):
        N = mass.shape[0]
        n_blocks = (N + BLOCK - 1) // BLOCK
        for b in prange(n_blocks):
            lo = b * BLOCK
            hi = min(lo + BLOCK, N)
            _fly_block(cfg, nominal, mass[lo:hi], S[:, lo:hi], shift[:, lo:hi], k[:, lo:hi],
                       state0, out_f[lo:hi], out_i[lo:hi], final[lo:hi], pos_rec[lo:hi])

    @njit(cache=True, error_model="numpy")
    def _fly_one(cfg, nominal, mass, S, shift, k, state0, out_f, out_i, final, rec, pos_rec):
        return _fly(cfg, nominal, mass, S, shift, k, state0, out_f, out_i, final, rec, pos_rec)


# ------------------------------------------------------------------ Python side

def _settings(params, gains: ControllerGains, config: HoverConfig, setpoint) -> np.ndarray:
    values = {
        "dt": config.dt_s, "g": params.g_m_s2, "m_ctl": gains.mass_kg, "kp": gains.kp_1_s2,
        "kd": gains.kd_1_s, "ki": gains.ki_1_s3, "kR": gains.kR_1_s2, "kw": gains.kw_1_s,
        "a_h": gains.max_horizontal_accel_m_s2, "a_v": gains.max_vertical_accel_m_s2,
        "i_max": gains.max_integral_m_s, "sp_x": setpoint[0], "sp_y": setpoint[1],
        "sp_z": setpoint[2], "pos_tol": config.position_tol_m,
        "cos_tol": config.cos_attitude_tol, "yaw_spin": config.yaw_spin_rad_s,
        "div_dist": config.divergence_distance_m, "div_rate": config.diverged_rate_rad_s,
        "duration": config.duration_s, "hold": config.hold_s,
        "sat_limit": config.saturation_limit_s, "n_steps": config.n_steps,
        "every": config.sample_every}
    return np.array([float(values[name]) for name in CFG_FIELDS])


def _nominal(params, gains: ControllerGains, config: HoverConfig, plant) -> tuple:
    """The per-rotor arrays shared by every vehicle; thrust and torque maps from `plant`
    (tests swap them to model a rotor spinning the wrong way)."""
    from reedtool.sim.motor import speed_filter_factors

    up, down = speed_filter_factors(config.dt_s, params.time_constant_up_s,
                                    params.time_constant_down_s)
    J0 = np.array(params.inertia_kg_m2, dtype=float)

    def c(x, dtype=float):
        # fresh writable C arrays: numba types read-only arrays apart (a second compile)
        return np.array(x, dtype=dtype, order="C", copy=True)

    return (c(params.rotor_position_m, dtype=float), c(plant.force_map.T, dtype=float),
            c(plant.torque_map, dtype=float),
            c(params.rotor_drag_coefficient, dtype=float),
            c(params.rolling_moment_coefficient, dtype=float), c(up), c(down),
            c(gains.allocation_pinv, dtype=float),
            c(gains.motor_constant * gains.omega_max_rad_s ** 2, dtype=float),
            c(1.0 / gains.motor_constant, dtype=float), c(gains.omega_max_rad_s, dtype=float),
            c(gains.inertia_kg_m2, dtype=float), J0, np.linalg.inv(J0))


def _start(params, gains, config: HoverConfig) -> tuple[np.ndarray, tuple, np.ndarray]:
    """(state0, setpoint, parked state) as batch.initial_state makes them: the disturbed
    start at rest with the rotors at the controller's trim speeds."""
    from reedtool.sim.dynamics import quat_from_rpy
    from reedtool.sim.motor import speed_command

    setpoint = np.array([0.0, 0.0, config.hover_altitude_m])
    p0 = setpoint + np.asarray(config.offset_m, dtype=float)
    q0 = quat_from_rpy(config.roll_rad, config.pitch_rad, config.yaw_rad)
    omega0 = speed_command(gains.allocation_pinv @ np.array([params.weight_N, 0.0, 0.0, 0.0]),
                           gains.motor_constant, gains.omega_max_rad_s)
    state0 = np.concatenate([p0, np.zeros(3), q0, np.zeros(3), np.zeros(3), omega0])
    park = np.concatenate([setpoint, np.zeros(3), [1.0, 0.0, 0.0, 0.0], np.zeros(3), omega0])
    return state0, tuple(float(x) for x in setpoint), park


def warm_up() -> float:
    """Compile (or load from numba's cache) both kernels on a tiny vehicle; seconds spent."""
    from reedtool.sim.dynamics import Plant
    from reedtool.sim.params import symmetric_multirotor

    start = time.perf_counter()
    params = symmetric_multirotor(4)
    config = HoverConfig(duration_s=0.02, hold_s=0.01)
    for n_vehicles in (1, 2):
        fly_batch(params, config, Plant.from_params(params, n_vehicles))
    return time.perf_counter() - start


def fly_batch(params, config: HoverConfig, plant,
              design: ControllerDesign = ControllerDesign(),
              record: bool = False) -> dict[str, np.ndarray]:
    """Every vehicle of `plant` flown on the nominal controller, judged as
    batch.simulate_batch judges: per-vehicle arrays "reason" (batch.REASONS index),
    "saturation_rotor", the OUT_FIELDS and "final" (N, 13 + n: p, v, q, w, omega; the
    parked level hover for vehicles that ended early, as the numpy batch parks them).
    With `record`, also "position_error_m" (samples, N), NaN after a vehicle ended.
    batch.simulate_batch(engine="numba") turns them into its Outcome.

    One vehicle runs on the serial kernel, more on the parallel one.
    """
    if numba is None:
        raise RuntimeError(unavailable_reason())
    config.validate()
    gains = ControllerGains.from_params(params, design)
    state0, setpoint, park = _start(params, gains, config)
    cfg = _settings(params, gains, config, setpoint)
    nominal = _nominal(params, gains, config, plant)
    N, n = plant.n_vehicles, params.n_rotors
    mass = np.array(plant.mass_kg, dtype=float)
    S = np.array(plant.inertia_scale_sqrt, dtype=float, order="C")
    shift = np.array(plant.com_shift_m, dtype=float, order="C")
    k = np.array(plant.motor_constant, dtype=float, order="C")
    out_f = np.zeros((N, len(OUT_FIELDS)))
    out_i = np.zeros((N, 2), dtype=np.int64)
    final = np.zeros((N, 13 + n))
    rows = config.n_steps // config.sample_every + (config.n_steps % config.sample_every != 0) + 1
    pos_rec = np.full((N, rows if record else 0), np.nan)
    if N == 1:
        _fly_one(cfg, nominal, mass[0], S[:, 0].copy(), shift[:, 0].copy(),
                 k[:, 0].copy(), state0, out_f[0], out_i[0], final[0], np.empty((0, 0)),
                 pos_rec[0])
    else:
        _fly_batch(cfg, nominal, mass, S, shift, k, state0, out_f, out_i, final, pos_rec)
    reason = out_i[:, 0].copy()
    ended = ~np.isin(reason, [_SETTLED, _NOT_SETTLED, _SATURATED])
    final[ended] = park
    result = {name: out_f[:, i].copy() for i, name in enumerate(OUT_FIELDS)}
    result.update(reason=reason, saturation_rotor=out_i[:, 1].copy(), final=final)
    if record:
        result["position_error_m"] = pos_rec.T.copy()
    return result


def vehicle_flyer(params, gains: ControllerGains, config: HoverConfig, setpoint_m):
    """`fly(state, rec)` with scalar.compile_vehicle's contract, on the compiled kernel:
    run.simulate_hover flies it unchanged."""
    from reedtool.sim.dynamics import Plant
    from reedtool.sim.scalar import Flight

    if numba is None:
        raise RuntimeError(unavailable_reason())
    cfg = _settings(params, gains, config, setpoint_m)
    nominal = _nominal(params, gains, config, Plant.from_params(params, 1))
    n = params.n_rotors
    mass = float(params.mass_kg)
    S, shift = np.ones(3), np.zeros(3)
    k = np.array(params.motor_constant, dtype=float)
    reasons = {_NON_FINITE: "non-finite", _FLIPPED: "flipped", _GROUND: "ground",
               _YAW_SPIN: "yaw-spin", _DRIFTED: "drifted", _RATE: "rate"}

    def fly(state, rec):
        *head, omega = state
        state0 = np.array([*head, *omega], dtype=float)
        out_f = np.zeros(len(OUT_FIELDS))
        out_i = np.zeros(2, dtype=np.int64)
        final = np.zeros(13 + n)
        rows = config.n_steps // config.sample_every + 2 if rec is not None else 0
        buffer = np.empty((rows, REC_FIXED + n))
        n_rec = _fly_one(cfg, nominal, mass, S, shift, k, state0, out_f, out_i, final, buffer,
                         np.empty(0))
        n_rec = min(n_rec, rows)
        if rec is not None:
            for row in buffer[:n_rec]:
                rec(tuple(float(x) for x in row))
        col = dict(zip(OUT_FIELDS, (float(x) for x in out_f)))
        reason = int(out_i[0])
        # The judge's verdict at the end is run.simulate_hover's to make (as for the
        # generated engine): hand back only the early endings.
        early = reasons.get(reason)
        omega_end = tuple(float(x) for x in final[13:])
        return Flight(early, col["reason_value"] if early else 0.0, col["end_time_s"],
                      col["max_position_error_m"], col["min_cos_attitude"],
                      col["max_throttle"], col["last_out_s"], bool(col["within"]),
                      col["longest_saturation_s"], int(out_i[1]),
                      col["final_position_error_m"], col["final_cos_attitude"], omega_end)

    return fly
