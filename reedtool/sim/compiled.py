"""The hover simulation compiled with numba: one vehicle, or a batch across the cores.

Optional (the `fast` extra, numba: `pip install numba`): without numba, `available()` is False and the
numpy engines (`run`, `batch`) are all there is; they stay the reference. The equations
are theirs, step for step: the Lee controller at heading 0 and its allocation
(`controller`), the motor model (`motor`), the semi-implicit Euler rigid body with the
exact quaternion exponential (`dynamics`) and the judge of `batch.simulate_batch`. Only
the order of a few sums differs, so results agree to rounding (tests/test_compiled.py
holds them to 1e-9 relative).

One vehicle runs on `_fly`, its state in registers. A batch runs in blocks of BLOCK
vehicles spread over the cores (`prange` over blocks); a block advances stage by stage,
each stage a loop over its vehicles in one flat working array (`_w_*`), which compiles to
SIMD instructions.

Rotor failures: every per-rotor quantity goes through the kernels as arrays indexed by
rotor, and the rotor speed is advanced in one place per kernel (`_advance_motors` for one
vehicle, `_w_motors` for a block); a per-rotor "alive" mask or failure time belongs there
(a dead rotor's command and speed set to 0), passed like `up`/`down`.
"""

from __future__ import annotations

import hashlib
import importlib.util
import inspect
import math
import os
import sys
import time

import numpy as np

from reedtool.sim import HoverConfig
from reedtool.sim.controller import (ControllerDesign, ControllerGains,
                                     most_out_of_range_one, prioritised_one)
from reedtool.sim.motor import next_speed_one

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
    return ("the compiled engine needs numba: pip install numba (reedtool's `fast` extra)")


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
              "div_rate", "duration", "hold", "sat_limit", "n_steps", "every", "lead")
BLOCK = 64              # vehicles per block of the batch kernel (its state fits in L1)
# Rows of the block kernel's working memory (see _w_control); rotor rows are sized for
# up to MAX_BLOCK_ROTORS rotors (vehicles with more fly on the per-vehicle kernel).
MAX_BLOCK_ROTORS = 16
_P, _V, _Q, _W, _I, _R, _E, _C = 0, 3, 6, 10, 13, 16, 25, 28
_F, _TQ, _XI, _AQ, _DTM, _S, _SH, _IS, _DS, _OUT, _BIG = 32, 35, 38, 41, 42, 43, 46, 49, 52, 55, 56
_OM = 57
_T = _OM + MAX_BLOCK_ROTORS
_K = _T + MAX_BLOCK_ROTORS
_NROWS = _K + MAX_BLOCK_ROTORS
REC_FIXED = 11          # t, x, y, z, R00, R10, R20, R21, R22, pos, cos_att; then omega


def _cache_with_shared_sources() -> None:
    """Stamp this module's numba cache with the sources of the functions it jits from
    other modules too.

    numba keys a cached kernel to its own file only (its documented limit: a change in a
    function called from another file is not seen), and the kernels here inline
    controller.prioritised_one, controller.most_out_of_range_one and
    motor.next_speed_one, the one source of those steps. So the locators that serve this
    file also hash those files: an edit there recompiles the kernels, never flies old
    code. Other files' functions go to numba's own locators unchanged.
    """
    from numba.core import caching

    here = os.path.abspath(__file__)
    shared = sorted({os.path.abspath(inspect.getfile(f))
                     for f in (prioritised_one, most_out_of_range_one, next_speed_one)})

    def stamped(base):
        class Locator(base):
            @classmethod
            def from_function(cls, py_func, py_file):
                if os.path.abspath(py_file) != here:
                    return None
                return super().from_function(py_func, py_file)

            def get_source_stamp(self):
                digests = []
                for path in shared:
                    with open(path, "rb") as f:
                        digests.append(hashlib.sha256(f.read()).digest())
                return (super().get_source_stamp(), *digests)

        Locator.__name__ = Locator.__qualname__ = f"Shared{base.__name__}"
        return Locator

    bases = [getattr(caching, name, None) or getattr(caching, "_" + name, None)
             for name in ("UserProvidedCacheLocator", "InTreeCacheLocator",
                          "UserWideCacheLocator")]
    impl = getattr(caching, "CacheImpl", None) or getattr(caching, "_CacheImpl", None)
    if impl is not None and all(bases):  # else numba's own: edits elsewhere need a touch here
        impl._locator_classes[:0] = [stamped(b) for b in bases]


if numba is not None:
    _cache_with_shared_sources()

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
        worst = _most_out_of_range(T, thrust_max)
        _prioritised(pinv, thrust_max, f, t0, t1, t2, T)
        return True, worst

    # The desaturation and the worst rotor are controller's per-vehicle functions
    # themselves, jitted: the generated float step (run) calls the same functions unjitted.
    _prioritised = njit(cache=True, error_model="numpy")(prioritised_one)
    _most_out_of_range = njit(cache=True, error_model="numpy")(most_out_of_range_one)

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

    # One rotor's motor step is motor.next_speed_one itself, jitted and inlined.
    _next_speed = njit(cache=True, error_model="numpy", inline="always")(next_speed_one)

    @njit(cache=True, error_model="numpy")
    def _advance_motors(T, inv_k, up, down, omega, lead, lead_up, lead_down, omega_max):
        """motor.next_speed_one for every rotor. The one place a per-rotor failure (alive
        mask) would zero the command and speed."""
        for i in range(omega.shape[0]):
            omega[i] = _next_speed(T[i], inv_k[i], omega[i], up[i], down[i], lead,
                                   lead_up[i], lead_down[i], omega_max[i])

    @njit(cache=True, error_model="numpy")
    def _fly(cfg, nominal, mass, S, shift, k, state0, out_f, out_i, final, rec, pos_rec):
        """Fly one vehicle from state0 (p, v, q, w, integral, omega) as
        batch.simulate_batch judges it.

        Fills out_f (OUT_FIELDS), out_i (reason, longest-saturation rotor), final (p, v,
        q, w, omega when it ended), rec (one row per sample) and pos_rec (the position
        error per sample) when they have rows; returns the samples judged.
        """
        pos_r, axis, tmap, cd, cr, up, down, pinv, thrust_max, inv_k, omega_max, Jc, J0, \
            J0inv, lead_up, lead_down = nominal
        lead = cfg[24] > 0.0
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
            _advance_motors(T, inv_k, up, down, omega, lead, lead_up, lead_down, omega_max)
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

    # ---- the block kernel's working memory: one flat array, row r of vehicle j at
    # r * BLOCK + j. With BLOCK and the row numbers compile-time constants, every stage's
    # loop over vehicles touches one array at constant distances, which the compiler can
    # prove independent and so turn into SIMD instructions (separate arrays would need
    # run-time overlap checks, too many of them to vectorise at all).

    @njit(cache=True, error_model="numpy")
    def _w_control(W, cfg, Jc):
        """Rotation, position error and the control law for every vehicle of a block."""
        g, m_ctl = cfg[1], cfg[2]
        kp, kd, ki, kR, kw, a_h, a_v = cfg[3], cfg[4], cfg[5], cfg[6], cfg[7], cfg[8], cfg[9]
        sp0, sp1, sp2 = cfg[11], cfg[12], cfg[13]
        J00, J01, J02 = Jc[0, 0], Jc[0, 1], Jc[0, 2]
        J10, J11, J12 = Jc[1, 0], Jc[1, 1], Jc[1, 2]
        J20, J21, J22 = Jc[2, 0], Jc[2, 1], Jc[2, 2]
        m_a_h = m_ctl * a_h
        for j in range(BLOCK):
            qw, qx, qy, qz = (W[(_Q + 0) * BLOCK + j], W[(_Q + 1) * BLOCK + j],
                              W[(_Q + 2) * BLOCK + j], W[(_Q + 3) * BLOCK + j])
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
            W[(_R + 0) * BLOCK + j] = R00
            W[(_R + 1) * BLOCK + j] = R01
            W[(_R + 2) * BLOCK + j] = R02
            W[(_R + 3) * BLOCK + j] = R10
            W[(_R + 4) * BLOCK + j] = R11
            W[(_R + 5) * BLOCK + j] = R12
            W[(_R + 6) * BLOCK + j] = R20
            W[(_R + 7) * BLOCK + j] = R21
            W[(_R + 8) * BLOCK + j] = R22
            e0 = W[(_P + 0) * BLOCK + j] - sp0
            e1 = W[(_P + 1) * BLOCK + j] - sp1
            e2 = W[(_P + 2) * BLOCK + j] - sp2
            W[(_E + 0) * BLOCK + j] = e0
            W[(_E + 1) * BLOCK + j] = e1
            W[(_E + 2) * BLOCK + j] = e2
            ax = -kp * e0 - kd * W[(_V + 0) * BLOCK + j] - ki * W[(_I + 0) * BLOCK + j]
            ay = -kp * e1 - kd * W[(_V + 1) * BLOCK + j] - ki * W[(_I + 1) * BLOCK + j]
            az = -kp * e2 - kd * W[(_V + 2) * BLOCK + j] - ki * W[(_I + 2) * BLOCK + j]
            h = math.sqrt(ax * ax + ay * ay)
            scale = m_a_h / (a_h if a_h > h else h)
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
            W[(_C + 0) * BLOCK + j] = F_norm * (b3x * R02 + A2)
            er0 = (b3x * R01 + A1) - inv_n * (b3z * R12 - b3y * R22)
            er1 = (b1x * R02 - u * A2) - (b3x * R00 + b3y * R10 + b3z * R20)
            er2 = inv_n * (b3z * R10 - b3y * R20) - (b1x * R01 - u * A1)
            w0, w1, w2 = (W[(_W + 0) * BLOCK + j], W[(_W + 1) * BLOCK + j],
                          W[(_W + 2) * BLOCK + j])
            s0 = 0.5 * kR * er0 + kw * w0
            s1 = 0.5 * kR * er1 + kw * w1
            s2 = 0.5 * kR * er2 + kw * w2
            Jw0 = J00 * w0 + J01 * w1 + J02 * w2
            Jw1 = J10 * w0 + J11 * w1 + J12 * w2
            Jw2 = J20 * w0 + J21 * w1 + J22 * w2
            W[(_C + 1) * BLOCK + j] = (w1 * Jw2 - w2 * Jw1) - (J00 * s0 + J01 * s1 + J02 * s2)
            W[(_C + 2) * BLOCK + j] = (w2 * Jw0 - w0 * Jw2) - (J10 * s0 + J11 * s1 + J12 * s2)
            W[(_C + 3) * BLOCK + j] = (w0 * Jw1 - w1 * Jw0) - (J20 * s0 + J21 * s1 + J22 * s2)
            W[_OUT * BLOCK + j] = 0.0

    @njit(cache=True, error_model="numpy")
    def _w_allocate(W, n, pinv, thrust_max):
        """The pseudo-inverse thrusts; row _OUT > 0 where a rotor is out of range."""
        for i in range(n):
            c0, c1, c2, c3, hi = pinv[i, 0], pinv[i, 1], pinv[i, 2], pinv[i, 3], thrust_max[i]
            T_i = W[(_T + i) * BLOCK:(_T + i + 1) * BLOCK]     # a view (see _w_motors)
            for j in range(BLOCK):
                Ti = (c0 * W[(_C + 0) * BLOCK + j] + c1 * W[(_C + 1) * BLOCK + j]
                      + c2 * W[(_C + 2) * BLOCK + j] + c3 * W[(_C + 3) * BLOCK + j])
                T_i[j] = Ti
                W[_OUT * BLOCK + j] += 1.0 if (Ti < 0.0) | (Ti > hi) else 0.0

    @njit(cache=True, error_model="numpy")
    def _w_wrench(W, n, pos_r, axis, tmap, cd, cr):
        """Body force and torque about the nominal COM (rotor loop outside, vehicles
        inside), into rows _F and _TQ; _XI is the nominal COM's velocity, body axes."""
        for j in range(BLOCK):
            R00, R01, R02 = W[(_R + 0) * BLOCK + j], W[(_R + 1) * BLOCK + j], W[(_R + 2) * BLOCK + j]
            R10, R11, R12 = W[(_R + 3) * BLOCK + j], W[(_R + 4) * BLOCK + j], W[(_R + 5) * BLOCK + j]
            R20, R21, R22 = W[(_R + 6) * BLOCK + j], W[(_R + 7) * BLOCK + j], W[(_R + 8) * BLOCK + j]
            v0, v1, v2 = W[(_V + 0) * BLOCK + j], W[(_V + 1) * BLOCK + j], W[(_V + 2) * BLOCK + j]
            w0, w1, w2 = W[(_W + 0) * BLOCK + j], W[(_W + 1) * BLOCK + j], W[(_W + 2) * BLOCK + j]
            s0, s1, s2 = W[(_SH + 0) * BLOCK + j], W[(_SH + 1) * BLOCK + j], W[(_SH + 2) * BLOCK + j]
            W[(_XI + 0) * BLOCK + j] = (R00 * v0 + R10 * v1 + R20 * v2) - (w1 * s2 - w2 * s1)
            W[(_XI + 1) * BLOCK + j] = (R01 * v0 + R11 * v1 + R21 * v2) - (w2 * s0 - w0 * s2)
            W[(_XI + 2) * BLOCK + j] = (R02 * v0 + R12 * v1 + R22 * v2) - (w0 * s1 - w1 * s0)
            W[(_F + 0) * BLOCK + j] = 0.0
            W[(_F + 1) * BLOCK + j] = 0.0
            W[(_F + 2) * BLOCK + j] = 0.0
            W[(_TQ + 0) * BLOCK + j] = 0.0
            W[(_TQ + 1) * BLOCK + j] = 0.0
            W[(_TQ + 2) * BLOCK + j] = 0.0
        for i in range(n):
            a0, a1, a2 = axis[i, 0], axis[i, 1], axis[i, 2]
            m0, m1, m2 = tmap[0, i], tmap[1, i], tmap[2, i]
            r0, r1, r2 = pos_r[i, 0], pos_r[i, 1], pos_r[i, 2]
            cdi, cri = cd[i], cr[i]
            # the rotor's rows as views (see _w_motors)
            om_i = W[(_OM + i) * BLOCK:(_OM + i + 1) * BLOCK]
            k_i = W[(_K + i) * BLOCK:(_K + i + 1) * BLOCK]
            if cdi != 0.0 or cri != 0.0:
                for j in range(BLOCK):
                    om = om_i[j]
                    Th = k_i[j] * om * om
                    w0, w1, w2 = (W[(_W + 0) * BLOCK + j], W[(_W + 1) * BLOCK + j],
                                  W[(_W + 2) * BLOCK + j])
                    u0 = W[(_XI + 0) * BLOCK + j] + (w1 * r2 - w2 * r1)
                    u1 = W[(_XI + 1) * BLOCK + j] + (w2 * r0 - w0 * r2)
                    u2 = W[(_XI + 2) * BLOCK + j] + (w0 * r1 - w1 * r0)
                    along = a0 * u0 + a1 * u1 + a2 * u2
                    p0 = u0 - a0 * along
                    p1 = u1 - a1 * along
                    p2 = u2 - a2 * along
                    dc = -om * cdi
                    d0, d1, d2 = dc * p0, dc * p1, dc * p2
                    rc = -om * cri
                    W[(_F + 0) * BLOCK + j] += a0 * Th + d0
                    W[(_F + 1) * BLOCK + j] += a1 * Th + d1
                    W[(_F + 2) * BLOCK + j] += a2 * Th + d2
                    W[(_TQ + 0) * BLOCK + j] += m0 * Th + (r1 * d2 - r2 * d1 + rc * p0)
                    W[(_TQ + 1) * BLOCK + j] += m1 * Th + (r2 * d0 - r0 * d2 + rc * p1)
                    W[(_TQ + 2) * BLOCK + j] += m2 * Th + (r0 * d1 - r1 * d0 + rc * p2)
            else:
                for j in range(BLOCK):
                    om = om_i[j]
                    Th = k_i[j] * om * om
                    W[(_F + 0) * BLOCK + j] += a0 * Th
                    W[(_F + 1) * BLOCK + j] += a1 * Th
                    W[(_F + 2) * BLOCK + j] += a2 * Th
                    W[(_TQ + 0) * BLOCK + j] += m0 * Th
                    W[(_TQ + 1) * BLOCK + j] += m1 * Th
                    W[(_TQ + 2) * BLOCK + j] += m2 * Th

    @njit(cache=True, error_model="numpy")
    def _w_motors(W, n, inv_k, up, down, lead, lead_up, lead_down, omega_max):
        for i in range(n):
            ik, fu, fd = inv_k[i], up[i], down[i]
            lu, ld, top = lead_up[i], lead_down[i], omega_max[i]
            # The rotor's rows as two views: their distance depends on i, which the
            # compiler cannot prove apart in one array; two arrays take one run-time
            # overlap check, and the loop vectorises.
            T_i = W[(_T + i) * BLOCK:(_T + i + 1) * BLOCK]
            om_i = W[(_OM + i) * BLOCK:(_OM + i + 1) * BLOCK]
            if lead:            # two loops: each inlines a branch-free step
                for j in range(BLOCK):
                    om_i[j] = _next_speed(T_i[j], ik, om_i[j], fu, fd, True, lu, ld, top)
            else:
                for j in range(BLOCK):
                    om_i[j] = _next_speed(T_i[j], ik, om_i[j], fu, fd, False, lu, ld, top)

    @njit(cache=True, error_model="numpy")
    def _w_body(W, cfg, J0, J0inv):
        """Semi-implicit Euler for p, v, w and the integral; the quaternion step factor
        into _AQ. Returns how many vehicles need tan for it (row _BIG)."""
        dt, g, i_max = cfg[0], cfg[1], cfg[10]
        dt_g = dt * g
        half_dt = 0.5 * dt
        two_over_dt = 2.0 / dt
        K00, K01, K02 = J0[0, 0], J0[0, 1], J0[0, 2]
        K10, K11, K12 = J0[1, 0], J0[1, 1], J0[1, 2]
        K20, K21, K22 = J0[2, 0], J0[2, 1], J0[2, 2]
        L00, L01, L02 = J0inv[0, 0], J0inv[0, 1], J0inv[0, 2]
        L10, L11, L12 = J0inv[1, 0], J0inv[1, 1], J0inv[1, 2]
        L20, L21, L22 = J0inv[2, 0], J0inv[2, 1], J0inv[2, 2]
        n_big = 0
        for j in range(BLOCK):
            F0, F1, F2 = W[(_F + 0) * BLOCK + j], W[(_F + 1) * BLOCK + j], W[(_F + 2) * BLOCK + j]
            s0, s1, s2 = W[(_SH + 0) * BLOCK + j], W[(_SH + 1) * BLOCK + j], W[(_SH + 2) * BLOCK + j]
            t0 = W[(_TQ + 0) * BLOCK + j] - (s1 * F2 - s2 * F1)
            t1 = W[(_TQ + 1) * BLOCK + j] - (s2 * F0 - s0 * F2)
            t2 = W[(_TQ + 2) * BLOCK + j] - (s0 * F1 - s1 * F0)
            fm = W[_DTM * BLOCK + j]
            f0 = F0 * fm
            f1 = F1 * fm
            f2 = F2 * fm
            v0 = W[(_V + 0) * BLOCK + j] + (W[(_R + 0) * BLOCK + j] * f0
                                          + W[(_R + 1) * BLOCK + j] * f1
                                          + W[(_R + 2) * BLOCK + j] * f2)
            v1 = W[(_V + 1) * BLOCK + j] + (W[(_R + 3) * BLOCK + j] * f0
                                          + W[(_R + 4) * BLOCK + j] * f1
                                          + W[(_R + 5) * BLOCK + j] * f2)
            v2 = W[(_V + 2) * BLOCK + j] + (W[(_R + 6) * BLOCK + j] * f0
                                          + W[(_R + 7) * BLOCK + j] * f1
                                          + W[(_R + 8) * BLOCK + j] * f2)
            v2 -= dt_g
            W[(_V + 0) * BLOCK + j] = v0
            W[(_V + 1) * BLOCK + j] = v1
            W[(_V + 2) * BLOCK + j] = v2
            S0, S1, S2 = W[(_S + 0) * BLOCK + j], W[(_S + 1) * BLOCK + j], W[(_S + 2) * BLOCK + j]
            w0, w1, w2 = W[(_W + 0) * BLOCK + j], W[(_W + 1) * BLOCK + j], W[(_W + 2) * BLOCK + j]
            sw0, sw1, sw2 = S0 * w0, S1 * w1, S2 * w2
            Jw0 = S0 * (K00 * sw0 + K01 * sw1 + K02 * sw2)
            Jw1 = S1 * (K10 * sw0 + K11 * sw1 + K12 * sw2)
            Jw2 = S2 * (K20 * sw0 + K21 * sw1 + K22 * sw2)
            h0 = (t0 - (w1 * Jw2 - w2 * Jw1)) * W[(_IS + 0) * BLOCK + j]
            h1 = (t1 - (w2 * Jw0 - w0 * Jw2)) * W[(_IS + 1) * BLOCK + j]
            h2 = (t2 - (w0 * Jw1 - w1 * Jw0)) * W[(_IS + 2) * BLOCK + j]
            w0 += (L00 * h0 + L01 * h1 + L02 * h2) * W[(_DS + 0) * BLOCK + j]
            w1 += (L10 * h0 + L11 * h1 + L12 * h2) * W[(_DS + 1) * BLOCK + j]
            w2 += (L20 * h0 + L21 * h1 + L22 * h2) * W[(_DS + 2) * BLOCK + j]
            W[(_W + 0) * BLOCK + j] = w0
            W[(_W + 1) * BLOCK + j] = w1
            W[(_W + 2) * BLOCK + j] = w2
            W[(_P + 0) * BLOCK + j] += dt * v0
            W[(_P + 1) * BLOCK + j] += dt * v1
            W[(_P + 2) * BLOCK + j] += dt * v2
            # q * (|w| / tan h, w) with h = |w| dt / 2: for h < 0.1, |w| / tan h =
            # (2 / dt) h cot h by its series (to ~1e-16, and vectorisable); a larger h
            # (a tumbling vehicle) gets tan in the kernel
            hh = half_dt * half_dt * (w0 * w0 + w1 * w1 + w2 * w2)
            W[_AQ * BLOCK + j] = two_over_dt * (1.0 - hh * (1.0 / 3.0 + hh * (1.0 / 45.0 + hh * (
                2.0 / 945.0 + hh * (1.0 / 4725.0 + hh * (2.0 / 93555.0))))))
            large = hh >= 0.01
            W[_BIG * BLOCK + j] = 1.0 if large else 0.0
            n_big += 1 if large else 0
            for a3 in range(3):
                ia = W[(_I + a3) * BLOCK + j] + W[(_E + a3) * BLOCK + j] * dt
                W[(_I + a3) * BLOCK + j] = -i_max if ia < -i_max else (i_max if ia > i_max else ia)
        return n_big

    @njit(cache=True, error_model="numpy")
    def _w_quaternion(W):
        for j in range(BLOCK):
            a = W[_AQ * BLOCK + j]
            w0, w1, w2 = W[(_W + 0) * BLOCK + j], W[(_W + 1) * BLOCK + j], W[(_W + 2) * BLOCK + j]
            qw, qx, qy, qz = (W[(_Q + 0) * BLOCK + j], W[(_Q + 1) * BLOCK + j],
                              W[(_Q + 2) * BLOCK + j], W[(_Q + 3) * BLOCK + j])
            nw = qw * a - qx * w0 - qy * w1 - qz * w2
            nx = qx * a + qw * w0 + qy * w2 - qz * w1
            ny = qy * a + qw * w1 + qz * w0 - qx * w2
            nz = qz * a + qw * w2 + qx * w1 - qy * w0
            inv_q = 1.0 / math.sqrt(nw * nw + nx * nx + ny * ny + nz * nz)
            W[(_Q + 0) * BLOCK + j] = nw * inv_q
            W[(_Q + 1) * BLOCK + j] = nx * inv_q
            W[(_Q + 2) * BLOCK + j] = ny * inv_q
            W[(_Q + 3) * BLOCK + j] = nz * inv_q

    @njit(cache=True, error_model="numpy")
    def _fly_block(cfg, nominal, mass, S, shift, k, state0, out_f, out_i, final, pos_rec):
        """_fly for a block of up to BLOCK vehicles at once, stage by stage (the _w_*
        functions), each stage a loop over the vehicles that compiles to SIMD. The same
        arithmetic as _fly, vehicle for vehicle (but for the attitude step's cot by its
        series, equal to ~1e-16); vehicles that end are parked at a level hover, as the
        numpy batch parks them, and no longer judged. Lanes past the block's vehicles fly
        copies of its first vehicle and are not reported."""
        pos_r, axis, tmap, cd, cr, up, down, pinv, thrust_max, inv_k, omega_max, Jc, J0, \
            J0inv, lead_up, lead_down = nominal
        lead = cfg[24] > 0.0
        dt = cfg[0]
        n_steps, every = int(cfg[22]), int(cfg[23])
        sample_dt = every * dt
        half_dt = 0.5 * dt
        n, B = k.shape[0], mass.shape[0]
        W = np.zeros(_NROWS * BLOCK)
        for j in range(BLOCK):
            src = j if j < B else 0
            for a in range(3):
                W[(_P + a) * BLOCK + j] = state0[a]
                W[(_V + a) * BLOCK + j] = state0[3 + a]
                W[(_W + a) * BLOCK + j] = state0[10 + a]
                W[(_I + a) * BLOCK + j] = state0[13 + a]
                W[(_S + a) * BLOCK + j] = S[a, src]
                W[(_SH + a) * BLOCK + j] = shift[a, src]
                W[(_IS + a) * BLOCK + j] = 1.0 / S[a, src]
                W[(_DS + a) * BLOCK + j] = dt / S[a, src]
            for a in range(4):
                W[(_Q + a) * BLOCK + j] = state0[6 + a]
            for i in range(n):
                W[(_OM + i) * BLOCK + j] = state0[16 + i]
                W[(_K + i) * BLOCK + j] = k[i, src]
            W[_DTM * BLOCK + j] = dt / mass[src]
        running = np.zeros(BLOCK, dtype=np.bool_)
        running[:B] = True
        n_running = B
        reason = np.zeros(BLOCK, dtype=np.int64)
        value = np.zeros(BLOCK)
        end_time = np.full(BLOCK, cfg[19])
        max_pos = np.zeros(BLOCK)
        min_cos = np.ones(BLOCK)
        max_thr = np.zeros(BLOCK)
        final_pos = np.zeros(BLOCK)
        final_cos = np.ones(BLOCK)
        last_out = np.zeros(BLOCK)
        within = np.zeros(BLOCK, dtype=np.bool_)
        sat_since = np.full(BLOCK, np.nan)
        sat_rotor = np.zeros(BLOCK, dtype=np.int64)
        sat_longest = np.zeros(BLOCK)
        sat_longest_rotor = np.zeros(BLOCK, dtype=np.int64)
        worst = np.zeros(BLOCK, dtype=np.int64)
        Tcol = np.empty(n)
        n_rec = 0
        for step in range(n_steps + 1):
            t = step * dt
            last = step == n_steps
            sample = step % every == 0 or last
            _w_control(W, cfg, Jc)
            _w_allocate(W, n, pinv, thrust_max)
            # desaturate the (rare) vehicles with a rotor out of range
            for j in range(BLOCK):
                if W[_OUT * BLOCK + j] > 0.0:
                    for i in range(n):
                        Tcol[i] = W[(_T + i) * BLOCK + j]
                    worst[j] = _most_out_of_range(Tcol, thrust_max)
                    _prioritised(pinv, thrust_max, W[(_C + 0) * BLOCK + j],
                                 W[(_C + 1) * BLOCK + j], W[(_C + 2) * BLOCK + j],
                                 W[(_C + 3) * BLOCK + j], Tcol)
                    for i in range(n):
                        W[(_T + i) * BLOCK + j] = Tcol[i]
            # ---- the judge, for the vehicles still flying
            if sample:
                for j in range(B):
                    if not running[j]:
                        if n_rec < pos_rec.shape[1]:
                            pos_rec[j, n_rec] = np.nan
                        continue
                    e0, e1, e2 = (W[(_E + 0) * BLOCK + j], W[(_E + 1) * BLOCK + j],
                                  W[(_E + 2) * BLOCK + j])
                    pos = math.sqrt(e0 * e0 + e1 * e1 + e2 * e2)
                    R22 = W[(_R + 8) * BLOCK + j]
                    cos_att = min(max(0.5 * ((W[(_R + 0) * BLOCK + j] + W[(_R + 4) * BLOCK + j]
                                              + R22) - 1.0), -1.0), 1.0)
                    throttle = W[_OM * BLOCK + j] / omega_max[0]
                    for i in range(1, n):
                        ratio = W[(_OM + i) * BLOCK + j] / omega_max[i]
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
                    if W[_OUT * BLOCK + j] > 0.0:
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
                    wx, wy, wz = (W[(_W + 0) * BLOCK + j], W[(_W + 1) * BLOCK + j],
                                  W[(_W + 2) * BLOCK + j])
                    rate_xy = math.sqrt(wx * wx + wy * wy)
                    finite = True
                    for r in (_P, _P + 1, _P + 2, _Q, _Q + 1, _Q + 2, _Q + 3, _W, _W + 1, _W + 2):
                        if not math.isfinite(W[r * BLOCK + j]):
                            finite = False
                    why = 0
                    val = 0.0
                    if not finite:
                        why = _NON_FINITE
                    elif R22 < 0.0:
                        why = _FLIPPED
                        val = math.degrees(math.acos(max(R22, -1.0)))
                    elif W[(_P + 2) * BLOCK + j] < 0.0:
                        why, val = _GROUND, W[(_P + 2) * BLOCK + j]
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
                        _w_save(W, j, n, final[j])
                        for a in range(3):          # park: level hover at the setpoint
                            W[(_P + a) * BLOCK + j] = cfg[11 + a]
                            W[(_V + a) * BLOCK + j] = 0.0
                            W[(_W + a) * BLOCK + j] = 0.0
                            W[(_I + a) * BLOCK + j] = 0.0
                        for a in range(4):
                            W[(_Q + a) * BLOCK + j] = 1.0 if a == 0 else 0.0
                        for i in range(n):
                            W[(_OM + i) * BLOCK + j] = state0[16 + i]
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
            # ---- advance one step: wrench at the current speeds, then the speeds respond
            _w_wrench(W, n, pos_r, axis, tmap, cd, cr)
            _w_motors(W, n, inv_k, up, down, lead, lead_up, lead_down, omega_max)
            if _w_body(W, cfg, J0, J0inv) > 0:
                for j in range(BLOCK):
                    if W[_BIG * BLOCK + j] > 0.0:
                        w0, w1, w2 = (W[(_W + 0) * BLOCK + j], W[(_W + 1) * BLOCK + j],
                                      W[(_W + 2) * BLOCK + j])
                        rate = math.sqrt(w0 * w0 + w1 * w1 + w2 * w2)
                        tan_h = math.tan(half_dt * rate)
                        W[_AQ * BLOCK + j] = rate / tan_h if tan_h != 0.0 else 1.0
            _w_quaternion(W)
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
                _w_save(W, j, n, final[j])

    @njit(cache=True, error_model="numpy")
    def _w_save(W, j, n, out):
        """Vehicle j's state (p, v, q, w, omega) into out."""
        for a in range(3):
            out[a] = W[(_P + a) * BLOCK + j]
            out[3 + a] = W[(_V + a) * BLOCK + j]
            out[10 + a] = W[(_W + a) * BLOCK + j]
        for a in range(4):
            out[6 + a] = W[(_Q + a) * BLOCK + j]
        for i in range(n):
            out[13 + i] = W[(_OM + i) * BLOCK + j]

    @njit(cache=True, parallel=True, error_model="numpy")
    def _fly_batch(cfg, nominal, mass, S, shift, k, state0, out_f, out_i, final, pos_rec):
        N = mass.shape[0]
        if k.shape[0] > MAX_BLOCK_ROTORS:
            rec = np.empty((0, 0))
            for j in prange(N):
                _fly(cfg, nominal, mass[j], S[:, j], shift[:, j], k[:, j], state0,
                     out_f[j], out_i[j], final[j], rec, pos_rec[j])
            return
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

def _load_numba_typing() -> None:
    """Import numba's typing of numpy without importing scipy.

    numba's first compile or cache load in a process imports numba.np.arraymath, whose
    module-level BLAS probe imports scipy.linalg (numba itself imports only scipy's top): about a third of the CPU time of a
    cached single-vehicle run (cProfile; the kernels call no BLAS). scipy is hidden for
    that import only; the probe's answer (read by numba's np.convolve and np.correlate
    alone; np.dot probes again when compiled) is then set to what it would have been, so
    nothing else in the process sees a difference.
    """
    if "numba.np.arraymath" in sys.modules or "scipy.linalg" in sys.modules:
        return
    sys.modules["scipy.linalg"] = None   # import scipy.linalg -> ImportError, here only
    try:
        import numba.np.arraymath as arraymath
    finally:
        if sys.modules.get("scipy.linalg", 0) is None:
            del sys.modules["scipy.linalg"]
    arraymath._HAVE_BLAS = importlib.util.find_spec("scipy.linalg") is not None



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
        "every": config.sample_every,
        "lead": 1.0 if gains.has_motor_lead else 0.0}
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
            c(gains.inertia_kg_m2, dtype=float), J0, np.linalg.inv(J0),
            *(c(f) for f in (gains.motor_lead_factors(config.dt_s)
                             or (np.ones(params.n_rotors), np.ones(params.n_rotors)))))


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
    _load_numba_typing()
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
    _load_numba_typing()
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
