"""The hover simulation compiled with numba: one vehicle, or a batch across the cores.

Optional (numba): without it, `available()` is False and the numpy engines (`run`,
`batch`) are all there is. The equations are `equations`' functions themselves, jitted
(`jitted`): the same Python functions the generated engines are traced from, so the
compiled engine flies them by construction, and judges a flight by them too
(`equations.judge_sample`, `verdict`, `settle_time`). What is written here is the loop
around them: `_fly` flies one vehicle; `_fly_batch`
flies blocks of BLOCK vehicles on `_fly_block`, spread over the cores (`prange`), each
stage of a block one loop over its vehicles that calls an equation inlined (SIMD lanes).

Rotor failures: every per-rotor quantity goes through the kernels as arrays indexed by
rotor, and the rotor speed is advanced in one place (`equations.advance_plant`'s lag,
`_w_motors` for a block); a per-rotor "alive" mask or failure time belongs there.
"""

from __future__ import annotations

import hashlib
import importlib.util
import inspect
import math
import os
import sys
import time
import types

import numpy as np

from reedtool.sim import HoverConfig, equations
from reedtool.sim.controller import ControllerDesign, ControllerGains

try:        # the extra; everything below the guard needs it
    import numba
    from numba import njit, prange
except ImportError:         # pragma: no cover - exercised where the extra is absent
    numba = None


def available() -> bool:
    """True when numba imports."""
    return numba is not None


def unavailable_reason() -> str:
    return ("the compiled engine needs numba: pip install numba (reedtool's `fast` extra)")


# Layout of the float outputs per vehicle.
OUT_FIELDS = ("reason_value", "end_time_s", "settle_time_s", "max_position_error_m",
              "min_cos_attitude", "final_position_error_m", "final_cos_attitude",
              "max_throttle", "longest_saturation_s", "last_out_s", "within")
# Layout of the run's settings vector (the judge's are equations' jc).
CFG_FIELDS = ("dt", "sp_x", "sp_y", "sp_z", "duration", "n_steps", "every")
JUDGE_SIZE = equations.JUDGE_SIZE
REC_FIXED = 11          # t, x, y, z, R00, R10, R20, R21, R22, pos, cos_att; then omega
BLOCK = 64              # vehicles per block of the batch kernel (its state fits in L1)
# Rows of the block kernel's working memory W (row r of vehicle j at W[r * BLOCK + j]);
# rotor rows for up to MAX_BLOCK_ROTORS rotors (more fly on the per-vehicle kernel).
MAX_BLOCK_ROTORS = 16
# Rows 0 to 16 + n are the state in equations' layout, so W[j::BLOCK] is vehicle j's x.
_P, _V, _Q, _W, _I, _OM = 0, 3, 6, 10, 13, 16
_R = _OM + MAX_BLOCK_ROTORS
_E, _C, _F, _M, _XI, _AQ, _HH, _MASS, _S, _SH, _OUT = (
    _R + 9, _R + 12, _R + 16, _R + 19, _R + 22, _R + 25, _R + 26, _R + 27, _R + 28, _R + 31,
    _R + 34)
_T = _OUT + 1
_K = _T + MAX_BLOCK_ROTORS
_NROWS = _K + MAX_BLOCK_ROTORS


def jitted_equations(jit) -> dict:
    """Every function of `equations` compiled by `jit`, each calling the others' compiled
    forms: copies of the functions on a namespace of compiled callees (numba compiles a
    callee only when it is itself a compiled function). The code objects are equations'
    own, so numba's cache for them is keyed to equations.py."""
    namespace = {"math": math, **{name: value for name, value in vars(equations).items()
                                  if type(value) in (int, float)}}
    out = {}
    for name, f in vars(equations).items():
        if (isinstance(f, types.FunctionType) and f.__module__ == equations.__name__
                and name not in ("select", "guarded_by")):
            copy = types.FunctionType(f.__code__, namespace, name, f.__defaults__,
                                      f.__closure__)
            copy.__qualname__, copy.__module__ = f.__qualname__, f.__module__
            out[name] = jit(copy)
    namespace.update(out)
    return out


def _cache_with_shared_sources() -> None:
    """Stamp this module's numba cache with equations.py's source too.

    numba keys a cached kernel to its own file only (its documented limit: a change in a
    function called from another file is not seen), and the kernels here call the
    equations of equations.py. So the locators that serve this file also hash that file:
    an edit there recompiles the kernels, never flies old code. Other files' functions go
    to numba's own locators unchanged.
    """
    from numba.core import caching

    here = os.path.abspath(__file__)
    shared = [os.path.abspath(inspect.getfile(equations))]

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
    jitted = jitted_equations(njit(cache=True, error_model="numpy", inline="always"))
    _rotation, _attitude_control, _rotor_thrust = (
        jitted["rotation"], jitted["attitude_control"], jitted["rotor_thrust"])
    _out_of_range, _desaturate = jitted["out_of_range"], jitted["desaturate"]
    _com_velocity, _rotor_wrench, _about_true_com = (
        jitted["com_velocity"], jitted["rotor_wrench"], jitted["about_true_com"])
    _next_speed, _translation_and_rates = jitted["next_speed"], jitted["translation_and_rates"]
    _cot_series, _cot_ratio, _attitude_step, _integral = (
        jitted["cot_series"], jitted["cot_ratio"], jitted["attitude_step"], jitted["integral"])
    _control_state = jitted["control_state"]
    _advance_state = jitted["advance_state"]
    _judge_start, _judge_sample, _verdict, _settle_time = (
        jitted["judge_start"], jitted["judge_sample"], jitted["verdict"],
        jitted["settle_time"])

    @njit(cache=True, error_model="numpy")
    def _fly(cfg, jc, ctl, pinv, thrust_max, veh, state0, out_f, out_i, final, rec,
             pos_rec):
        """Fly one vehicle from state0 (equations' state layout), judged by equations'
        judge (jc its settings).

        Fills out_f (OUT_FIELDS), out_i (reason, longest-saturation rotor), final (p, v,
        q, w, omega when it ended), rec (one row per sample) and pos_rec (the position
        error per sample) when they have rows; returns the samples judged.
        """
        dt = cfg[0]
        n_steps, every = int(cfg[5]), int(cfg[6])
        omega_max = veh[20]
        n = len(thrust_max)
        x = state0.copy()
        sp = cfg[1:4]
        e = np.zeros(3)
        R = np.empty(9)
        T = np.empty(n)
        J = np.empty(JUDGE_SIZE)
        _judge_start(J)
        reason = 0
        value = 0.0
        end_time = cfg[4]
        n_rec = 0
        for step in range(n_steps + 1):
            t = step * dt
            last = step == n_steps
            saturated, worst = _control_state(ctl, pinv, thrust_max, sp, x, R, e, T)
            if step % every == 0 or last:
                reason, value = _judge_sample(jc, omega_max, t, x, R, e, saturated, worst, J)
                if n_rec < pos_rec.shape[0]:
                    pos_rec[n_rec] = J[3]
                if n_rec < rec.shape[0]:
                    rec[n_rec, 0] = t
                    rec[n_rec, 1] = x[0]
                    rec[n_rec, 2] = x[1]
                    rec[n_rec, 3] = x[2]
                    rec[n_rec, 4] = R[0]
                    rec[n_rec, 5] = R[3]
                    rec[n_rec, 6] = R[6]
                    rec[n_rec, 7] = R[7]
                    rec[n_rec, 8] = R[8]
                    rec[n_rec, 9] = J[3]
                    rec[n_rec, 10] = J[4]
                    for i in range(n):
                        rec[n_rec, REC_FIXED + i] = x[16 + i]
                n_rec += 1
                if reason != 0:
                    end_time = t
                    break
                if last:
                    reason, value = _verdict(jc, J)
                    break
            _advance_state(veh, x, T, R, e)
        _report(jc, reason, value, end_time, J, out_f, out_i)
        for a in range(13):
            final[a] = x[a]
        for i in range(n):
            final[13 + i] = x[16 + i]
        return n_rec

    @njit(cache=True, error_model="numpy")
    def _report(jc, reason, value, end_time, J, out_f, out_i):
        """A judged flight into out_f (OUT_FIELDS) and out_i (reason, saturation rotor)."""
        out_i[0] = reason
        out_i[1] = int(J[10])
        out_f[0] = value
        out_f[1] = end_time
        out_f[2] = _settle_time(jc, reason, J)
        out_f[3] = J[0]
        out_f[4] = J[1]
        out_f[5] = J[3]
        out_f[6] = J[4]
        out_f[7] = J[2]
        out_f[8] = J[9]
        out_f[9] = J[5]
        out_f[10] = J[6]

    # ---- the batch: blocks of BLOCK vehicles, each stage one loop over the block's
    # vehicles that calls an equation (inlined) on rows of one flat working array W, at
    # compile-time constant distances, so the compiler proves the lanes independent and
    # emits SIMD instructions. Per-rotor stages take the rotor's rows as views (their
    # distance depends on the rotor, which one array would hide from the vectoriser).

    @njit(cache=True, error_model="numpy")
    def _nine(a):
        """The block's constants as tuples: its loops keep them in registers (an array
        might alias the working memory, and would be read again at every vehicle)."""
        return (a[0], a[1], a[2], a[3], a[4], a[5], a[6], a[7], a[8])

    @njit(cache=True, error_model="numpy")
    def _w_control(W, ctl, sp):
        """Rotation, position error and the control law's wrench (rows _R, _E, _C)."""
        sp0, sp1, sp2 = sp[0], sp[1], sp[2]
        for j in range(BLOCK):
            R00, R01, R02, R10, R11, R12, R20, R21, R22 = _rotation(
                W[(_Q + 0) * BLOCK + j], W[(_Q + 1) * BLOCK + j], W[(_Q + 2) * BLOCK + j],
                W[(_Q + 3) * BLOCK + j])
            ex = W[(_P + 0) * BLOCK + j] - sp0
            ey = W[(_P + 1) * BLOCK + j] - sp1
            ez = W[(_P + 2) * BLOCK + j] - sp2
            f, t0, t1, t2 = _attitude_control(
                ctl, ex, ey, ez, W[(_V + 0) * BLOCK + j], W[(_V + 1) * BLOCK + j],
                W[(_V + 2) * BLOCK + j], W[(_I + 0) * BLOCK + j], W[(_I + 1) * BLOCK + j],
                W[(_I + 2) * BLOCK + j], R00, R01, R02, R10, R11, R12, R20, R21, R22,
                W[(_W + 0) * BLOCK + j], W[(_W + 1) * BLOCK + j], W[(_W + 2) * BLOCK + j])
            W[(_R + 0) * BLOCK + j] = R00
            W[(_R + 1) * BLOCK + j] = R01
            W[(_R + 2) * BLOCK + j] = R02
            W[(_R + 3) * BLOCK + j] = R10
            W[(_R + 4) * BLOCK + j] = R11
            W[(_R + 5) * BLOCK + j] = R12
            W[(_R + 6) * BLOCK + j] = R20
            W[(_R + 7) * BLOCK + j] = R21
            W[(_R + 8) * BLOCK + j] = R22
            W[(_E + 0) * BLOCK + j] = ex
            W[(_E + 1) * BLOCK + j] = ey
            W[(_E + 2) * BLOCK + j] = ez
            W[(_C + 0) * BLOCK + j] = f
            W[(_C + 1) * BLOCK + j] = t0
            W[(_C + 2) * BLOCK + j] = t1
            W[(_C + 3) * BLOCK + j] = t2
            W[_OUT * BLOCK + j] = 0.0

    @njit(cache=True, error_model="numpy")
    def _w_allocate(W, n, pinv, thrust_max):
        """The pseudo-inverse thrusts (rows _T); row _OUT > 0 where a rotor is out of range."""
        for i in range(n):
            hi = thrust_max[i]
            c0, c1, c2, c3 = pinv[4 * i], pinv[4 * i + 1], pinv[4 * i + 2], pinv[4 * i + 3]
            T_i = W[(_T + i) * BLOCK:(_T + i + 1) * BLOCK]
            for j in range(BLOCK):
                Ti = _rotor_thrust(c0, c1, c2, c3, W[(_C + 0) * BLOCK + j],
                                   W[(_C + 1) * BLOCK + j], W[(_C + 2) * BLOCK + j],
                                   W[(_C + 3) * BLOCK + j])
                T_i[j] = Ti
                W[_OUT * BLOCK + j] += 1.0 if _out_of_range(Ti, hi) else 0.0

    @njit(cache=True, error_model="numpy")
    def _w_wrench(W, n, pos, axis, tmap, cd, cr):
        """Body force and torque about the nominal COM (rows _F, _M): the rotors' sum,
        rotor loop outside, vehicles inside; _XI is the nominal COM's velocity."""
        for j in range(BLOCK):
            xi0, xi1, xi2 = _com_velocity(
                W[(_R + 0) * BLOCK + j], W[(_R + 1) * BLOCK + j], W[(_R + 2) * BLOCK + j],
                W[(_R + 3) * BLOCK + j], W[(_R + 4) * BLOCK + j], W[(_R + 5) * BLOCK + j],
                W[(_R + 6) * BLOCK + j], W[(_R + 7) * BLOCK + j], W[(_R + 8) * BLOCK + j],
                W[(_V + 0) * BLOCK + j], W[(_V + 1) * BLOCK + j], W[(_V + 2) * BLOCK + j],
                W[(_W + 0) * BLOCK + j], W[(_W + 1) * BLOCK + j], W[(_W + 2) * BLOCK + j],
                W[(_SH + 0) * BLOCK + j], W[(_SH + 1) * BLOCK + j], W[(_SH + 2) * BLOCK + j])
            W[(_XI + 0) * BLOCK + j] = xi0
            W[(_XI + 1) * BLOCK + j] = xi1
            W[(_XI + 2) * BLOCK + j] = xi2
            for a in range(3):
                W[(_F + a) * BLOCK + j] = 0.0
                W[(_M + a) * BLOCK + j] = 0.0
        for i in range(n):
            om_i = W[(_OM + i) * BLOCK:(_OM + i + 1) * BLOCK]
            k_i = W[(_K + i) * BLOCK:(_K + i + 1) * BLOCK]
            r0, r1, r2 = pos[3 * i], pos[3 * i + 1], pos[3 * i + 2]
            a0, a1, a2 = axis[3 * i], axis[3 * i + 1], axis[3 * i + 2]
            m0, m1, m2 = tmap[3 * i], tmap[3 * i + 1], tmap[3 * i + 2]
            cdi, cri = cd[i], cr[i]
            for j in range(BLOCK):
                f0, f1, f2, n0, n1, n2 = _rotor_wrench(
                    r0, r1, r2, a0, a1, a2, m0, m1, m2, cdi, cri, k_i[j], om_i[j],
                    W[(_XI + 0) * BLOCK + j],
                    W[(_XI + 1) * BLOCK + j], W[(_XI + 2) * BLOCK + j],
                    W[(_W + 0) * BLOCK + j], W[(_W + 1) * BLOCK + j], W[(_W + 2) * BLOCK + j])
                W[(_F + 0) * BLOCK + j] += f0
                W[(_F + 1) * BLOCK + j] += f1
                W[(_F + 2) * BLOCK + j] += f2
                W[(_M + 0) * BLOCK + j] += n0
                W[(_M + 1) * BLOCK + j] += n1
                W[(_M + 2) * BLOCK + j] += n2

    @njit(cache=True, error_model="numpy")
    def _w_motors(W, n, inv_k, up, down, lead, lead_up, lead_down, omega_max):
        """Every rotor's next_speed under its thrust command."""
        for i in range(n):
            ik, fu, fd = inv_k[i], up[i], down[i]
            lu, ld, top = lead_up[i], lead_down[i], omega_max[i]
            T_i = W[(_T + i) * BLOCK:(_T + i + 1) * BLOCK]
            om_i = W[(_OM + i) * BLOCK:(_OM + i + 1) * BLOCK]
            if lead:            # two loops: each inlines a branch-free step
                for j in range(BLOCK):
                    om_i[j] = _next_speed(T_i[j], ik, om_i[j], fu, fd, True, lu, ld, top)
            else:
                for j in range(BLOCK):
                    om_i[j] = _next_speed(T_i[j], ik, om_i[j], fu, fd, False, lu, ld, top)

    @njit(cache=True, error_model="numpy")
    def _w_body(W, dt, g, i_max, J0, dt_J0inv):
        """translation_and_rates, the integral and cot_ratio's series (row _AQ; row _HH
        its argument); returns how many vehicles need cot_ratio's other branch."""
        half_dt = 0.5 * dt
        two_over_dt = 1.0 / half_dt
        n_big = 0
        for j in range(BLOCK):
            F0, F1, F2 = W[(_F + 0) * BLOCK + j], W[(_F + 1) * BLOCK + j], W[(_F + 2) * BLOCK + j]
            s0, s1, s2 = W[(_SH + 0) * BLOCK + j], W[(_SH + 1) * BLOCK + j], W[(_SH + 2) * BLOCK + j]
            M0, M1, M2 = _about_true_com(F0, F1, F2, W[(_M + 0) * BLOCK + j],
                                         W[(_M + 1) * BLOCK + j], W[(_M + 2) * BLOCK + j],
                                         s0, s1, s2)
            px, py, pz, vx, vy, vz, wx, wy, wz = _translation_and_rates(
                dt, g, W[_MASS * BLOCK + j], J0, dt_J0inv, W[(_S + 0) * BLOCK + j],
                W[(_S + 1) * BLOCK + j], W[(_S + 2) * BLOCK + j],
                (W[(_R + 0) * BLOCK + j], W[(_R + 1) * BLOCK + j], W[(_R + 2) * BLOCK + j],
                 W[(_R + 3) * BLOCK + j], W[(_R + 4) * BLOCK + j], W[(_R + 5) * BLOCK + j],
                 W[(_R + 6) * BLOCK + j], W[(_R + 7) * BLOCK + j], W[(_R + 8) * BLOCK + j]),
                F0, F1, F2, M0, M1, M2,
                W[(_P + 0) * BLOCK + j], W[(_P + 1) * BLOCK + j], W[(_P + 2) * BLOCK + j],
                W[(_V + 0) * BLOCK + j], W[(_V + 1) * BLOCK + j], W[(_V + 2) * BLOCK + j],
                W[(_W + 0) * BLOCK + j], W[(_W + 1) * BLOCK + j], W[(_W + 2) * BLOCK + j])
            W[(_P + 0) * BLOCK + j] = px
            W[(_P + 1) * BLOCK + j] = py
            W[(_P + 2) * BLOCK + j] = pz
            W[(_V + 0) * BLOCK + j] = vx
            W[(_V + 1) * BLOCK + j] = vy
            W[(_V + 2) * BLOCK + j] = vz
            W[(_W + 0) * BLOCK + j] = wx
            W[(_W + 1) * BLOCK + j] = wy
            W[(_W + 2) * BLOCK + j] = wz
            ix, iy, iz = _integral(i_max, dt, W[(_I + 0) * BLOCK + j], W[(_I + 1) * BLOCK + j],
                                   W[(_I + 2) * BLOCK + j], W[(_E + 0) * BLOCK + j],
                                   W[(_E + 1) * BLOCK + j], W[(_E + 2) * BLOCK + j])
            W[(_I + 0) * BLOCK + j] = ix
            W[(_I + 1) * BLOCK + j] = iy
            W[(_I + 2) * BLOCK + j] = iz
            # rigid_body's cot_ratio in two passes: its series here, in SIMD lanes; the
            # rare vehicle beyond the series' range (a tumbling one) after the loop
            hh = half_dt * half_dt * (wx * wx + wy * wy + wz * wz)
            W[_HH * BLOCK + j] = hh
            W[_AQ * BLOCK + j] = _cot_series(hh, two_over_dt)
            n_big += 0 if hh < equations.SERIES_HH_MAX else 1
        return n_big

    @njit(cache=True, error_model="numpy")
    def _w_attitude(W):
        for j in range(BLOCK):
            qw, qx, qy, qz = _attitude_step(
                W[(_Q + 0) * BLOCK + j], W[(_Q + 1) * BLOCK + j], W[(_Q + 2) * BLOCK + j],
                W[(_Q + 3) * BLOCK + j], W[(_W + 0) * BLOCK + j], W[(_W + 1) * BLOCK + j],
                W[(_W + 2) * BLOCK + j], W[_AQ * BLOCK + j])
            W[(_Q + 0) * BLOCK + j] = qw
            W[(_Q + 1) * BLOCK + j] = qx
            W[(_Q + 2) * BLOCK + j] = qy
            W[(_Q + 3) * BLOCK + j] = qz

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

    @njit(cache=True, error_model="numpy")
    def _fly_block(cfg, jc, ctl, pinv, thrust_max, nominal, mass, S, shift, k, state0, out_f,
                   out_i, final, pos_rec):
        """_fly for a block of up to BLOCK vehicles at once, stage by stage (the _w_*
        functions), each stage the equations inlined in a loop over the vehicles. The
        same arithmetic as _fly, vehicle for vehicle; vehicles that end are parked at a
        level hover, as the numpy batch parks them, and no longer judged. Lanes past the
        block's vehicles fly copies of its first vehicle and are not reported."""
        dt, g, lead, i_max, pos, axis, tmap, cd, cr, J0a, dt_J0inva, inv_k, up, down, lead_up, \
            lead_down, omega_max = nominal
        J0, dt_J0inv = _nine(J0a), _nine(dt_J0inva)
        ctl = (*_nine(ctl[0:9]), *_nine(ctl[9:18]))
        n_steps, every = int(cfg[5]), int(cfg[6])
        half_dt = 0.5 * dt
        sp = cfg[1:4]
        n, B = k.shape[1], mass.shape[0]
        W = np.zeros(_NROWS * BLOCK)
        for j in range(BLOCK):
            src = j if j < B else 0
            for a in range(3):
                W[(_P + a) * BLOCK + j] = state0[a]
                W[(_V + a) * BLOCK + j] = state0[3 + a]
                W[(_W + a) * BLOCK + j] = state0[10 + a]
                W[(_I + a) * BLOCK + j] = state0[13 + a]
                W[(_S + a) * BLOCK + j] = S[src, a]
                W[(_SH + a) * BLOCK + j] = shift[src, a]
            for a in range(4):
                W[(_Q + a) * BLOCK + j] = state0[6 + a]
            for i in range(n):
                W[(_OM + i) * BLOCK + j] = state0[16 + i]
                W[(_K + i) * BLOCK + j] = k[src, i]
            W[_MASS * BLOCK + j] = mass[src]
        running = np.zeros(BLOCK, dtype=np.bool_)
        running[:B] = True
        n_running = B
        reason = np.zeros(BLOCK, dtype=np.int64)
        value = np.zeros(BLOCK)
        end_time = np.full(BLOCK, cfg[4])
        J = np.empty((BLOCK, JUDGE_SIZE))
        for j in range(BLOCK):
            _judge_start(J[j])
        worst = np.zeros(BLOCK, dtype=np.int64)
        Tcol = np.empty(n)
        n_rec = 0
        for step in range(n_steps + 1):
            t = step * dt
            last = step == n_steps
            sample = step % every == 0 or last
            _w_control(W, ctl, sp)
            _w_allocate(W, n, pinv, thrust_max)
            # desaturate the (rare) vehicles with a rotor out of range
            for j in range(BLOCK):
                if W[_OUT * BLOCK + j] > 0.0:
                    for i in range(n):
                        Tcol[i] = W[(_T + i) * BLOCK + j]
                    _, worst[j] = _desaturate(pinv, thrust_max, W[(_C + 0) * BLOCK + j],
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
                    # vehicle j's state, rotation and error: strided views of W
                    why, val = _judge_sample(jc, omega_max, t, W[j::BLOCK],
                                             W[_R * BLOCK + j::BLOCK],
                                             W[_E * BLOCK + j::BLOCK],
                                             W[_OUT * BLOCK + j] > 0.0, worst[j], J[j])
                    if n_rec < pos_rec.shape[1]:
                        pos_rec[j, n_rec] = J[j, 3]
                    if why != 0:
                        reason[j] = why
                        value[j] = val
                        end_time[j] = t
                        running[j] = False
                        n_running -= 1
                        _w_save(W, j, n, final[j])
                        for a in range(3):          # park: level hover at the setpoint
                            W[(_P + a) * BLOCK + j] = sp[a]
                            W[(_V + a) * BLOCK + j] = 0.0
                            W[(_W + a) * BLOCK + j] = 0.0
                            W[(_I + a) * BLOCK + j] = 0.0
                        for a in range(4):
                            W[(_Q + a) * BLOCK + j] = 1.0 if a == 0 else 0.0
                        for i in range(n):
                            W[(_OM + i) * BLOCK + j] = state0[16 + i]
                    elif last:
                        reason[j], value[j] = _verdict(jc, J[j])
                n_rec += 1
                if last or n_running == 0:
                    break
            # ---- advance one step: wrench at the current speeds, then the speeds respond
            _w_wrench(W, n, pos, axis, tmap, cd, cr)
            _w_motors(W, n, inv_k, up, down, lead, lead_up, lead_down, omega_max)
            if _w_body(W, dt, g, i_max, J0, dt_J0inv) > 0:
                for j in range(BLOCK):
                    hh = W[_HH * BLOCK + j]
                    if not hh < equations.SERIES_HH_MAX:
                        w0, w1, w2 = (W[(_W + 0) * BLOCK + j], W[(_W + 1) * BLOCK + j],
                                      W[(_W + 2) * BLOCK + j])
                        W[_AQ * BLOCK + j] = _cot_ratio(hh, w0 * w0 + w1 * w1 + w2 * w2,
                                                        half_dt)
            _w_attitude(W)
        for j in range(B):
            _report(jc, reason[j], value[j], end_time[j], J[j], out_f[j], out_i[j])
            reached = running[j]
            if reached:
                _w_save(W, j, n, final[j])

    @njit(cache=True, parallel=True, error_model="numpy")
    def _fly_batch(cfg, jc, ctl, pinv, thrust_max, nominal, mass, S, shift, k, state0,
                   out_f, out_i, final, pos_rec):
        """Blocks of BLOCK vehicles on _fly_block, spread over the cores; vehicles with
        more than MAX_BLOCK_ROTORS rotors one by one on _fly."""
        N = mass.shape[0]
        if k.shape[1] > MAX_BLOCK_ROTORS:
            dt, g, lead, i_max, pos, axis, tmap, cd, cr, J0, dt_J0inv, inv_k, up, down, \
                lead_up, lead_down, omega_max = nominal
            rec = np.empty((0, 0))
            for j in prange(N):
                veh = (dt, g, mass[j], lead, i_max, pos, axis, tmap, cd, cr, k[j], shift[j],
                       S[j], J0, dt_J0inv, inv_k, up, down, lead_up, lead_down, omega_max)
                _fly(cfg, jc, ctl, pinv, thrust_max, veh, state0, out_f[j], out_i[j],
                     final[j], rec, pos_rec[j])
            return
        for b in prange((N + BLOCK - 1) // BLOCK):
            lo = b * BLOCK
            hi = min(lo + BLOCK, N)
            _fly_block(cfg, jc, ctl, pinv, thrust_max, nominal, mass[lo:hi], S[lo:hi],
                       shift[lo:hi], k[lo:hi], state0, out_f[lo:hi], out_i[lo:hi],
                       final[lo:hi], pos_rec[lo:hi])


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


def _settings(config: HoverConfig, setpoint) -> np.ndarray:
    values = {
        "dt": config.dt_s, "sp_x": setpoint[0], "sp_y": setpoint[1], "sp_z": setpoint[2],
        "duration": config.duration_s, "n_steps": config.n_steps,
        "every": config.sample_every}
    return np.array([float(values[name]) for name in CFG_FIELDS])


def _start(params, gains, config: HoverConfig) -> tuple[np.ndarray, np.ndarray]:
    """(state0, parked state) as batch.initial_state makes them: the disturbed start at
    rest with the rotors at the controller's trim speeds."""
    from reedtool.sim.dynamics import quat_from_rpy
    from reedtool.sim.layout import hover_speeds

    setpoint = np.array([0.0, 0.0, config.hover_altitude_m])
    p0 = setpoint + np.asarray(config.offset_m, dtype=float)
    q0 = quat_from_rpy(config.roll_rad, config.pitch_rad, config.yaw_rad)
    omega0 = hover_speeds(params, gains)
    state0 = np.concatenate([p0, np.zeros(3), q0, np.zeros(3), np.zeros(3), omega0])
    park = np.concatenate([setpoint, np.zeros(3), [1.0, 0.0, 0.0, 0.0], np.zeros(3), omega0])
    return state0, park


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
    from reedtool.sim.layout import inputs, judge_settings

    gains = ControllerGains.from_params(params, design)
    state0, park = _start(params, gains, config)
    the = inputs(params, gains, config, plant)
    cfg = _settings(config, the.setpoint)
    N, n = plant.n_vehicles, params.n_rotors
    out_f = np.zeros((N, len(OUT_FIELDS)))
    out_i = np.zeros((N, 2), dtype=np.int64)
    final = np.zeros((N, 13 + n))
    rows = config.n_steps // config.sample_every + (config.n_steps % config.sample_every != 0) + 1
    pos_rec = np.full((N, rows if record else 0), np.nan)
    _load_numba_typing()
    jc = judge_settings(config)
    if N == 1:
        _fly(cfg, jc, the.ctl, the.pinv, the.thrust_max, the.vehicle(0), state0, out_f[0],
             out_i[0], final[0], np.empty((0, 0)), pos_rec[0])
    else:
        _fly_batch(cfg, jc, the.ctl, the.pinv, the.thrust_max, the.nominal, the.mass, the.S,
                   the.shift, the.k, state0, out_f, out_i, final, pos_rec)
    reason = out_i[:, 0].copy()
    ended = ~np.isin(reason, [equations.SETTLED, equations.NOT_SETTLED, equations.SATURATED])
    final[ended] = park
    result = {name: out_f[:, i].copy() for i, name in enumerate(OUT_FIELDS)}
    result.update(reason=reason, saturation_rotor=out_i[:, 1].copy(), final=final)
    if record:
        result["position_error_m"] = pos_rec.T.copy()
    return result


def vehicle_flyer(params, gains: ControllerGains, config: HoverConfig, setpoint_m):
    """`fly(state, rec)` with scalar.compile_vehicle's contract, on the compiled kernel:
    run.simulate_hover flies it unchanged."""
    from reedtool.sim.layout import inputs, judge_settings
    from reedtool.sim.scalar import Flight

    if numba is None:
        raise RuntimeError(unavailable_reason())
    _load_numba_typing()
    the = inputs(params, gains, config, setpoint_m=setpoint_m)
    cfg = _settings(config, the.setpoint)
    veh = the.vehicle(0)
    n = params.n_rotors
    jc = judge_settings(config)

    def fly(state, rec):
        *head, omega = state
        state0 = np.array([*head, *omega], dtype=float)
        out_f = np.zeros(len(OUT_FIELDS))
        out_i = np.zeros(2, dtype=np.int64)
        final = np.zeros(13 + n)
        rows = config.n_steps // config.sample_every + 2 if rec is not None else 0
        buffer = np.empty((rows, REC_FIXED + n))
        n_rec = _fly(cfg, jc, the.ctl, the.pinv, the.thrust_max, veh, state0, out_f, out_i,
                     final, buffer, np.empty(0))
        n_rec = min(n_rec, rows)
        if rec is not None:
            for row in buffer[:n_rec]:
                rec(tuple(float(x) for x in row))
        col = dict(zip(OUT_FIELDS, (float(x) for x in out_f)))
        return Flight(int(out_i[0]), col["reason_value"], col["end_time_s"],
                      col["settle_time_s"], col["max_position_error_m"],
                      col["min_cos_attitude"], col["max_throttle"],
                      col["longest_saturation_s"], col["final_position_error_m"],
                      col["final_cos_attitude"], tuple(float(x) for x in final[13:]),
                      tuple(float(x) for x in final))

    return fly
