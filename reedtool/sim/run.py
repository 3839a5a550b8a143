"""One vehicle, fast: the hover simulation transcribed into plain Python floats.

For a single vehicle numpy's per-call overhead (about half a microsecond per operation on
tiny arrays) dominates, so the array engine in `batch` runs a 10 s flight in seconds.
This engine steps the same equations (motor model from `motor`, rigid body from
`dynamics`, control law from `controller`) with scalar arithmetic and loops over the
rotors. tests/test_sim_engines.py holds the two engines to the same trajectory, so this
transcription cannot drift from the reference.

Everything that does not change during a run (gains, rotor geometry) is unpacked into
locals before the loop: the loop body is where the time goes.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from . import ExitStatus, HoverConfig
from .batch import describe, hover_speeds
from .controller import ControllerDesign, ControllerGains
from .dynamics import quat_from_rpy
from .motor import speed_filter_factors
from .params import VehicleParams


@dataclass
class HoverRun:
    status: ExitStatus
    reason: str
    message: str
    end_time_s: float
    settle_time_s: float               # NaN when it never settled
    max_position_error_m: float
    max_attitude_error_deg: float
    final_position_error_m: float
    final_attitude_error_deg: float
    max_throttle: float
    longest_saturation_s: float        # longest run with the demand out of the rotors' range
    final_omega_rad_s: np.ndarray      # (n,)
    initial_omega_rad_s: np.ndarray    # (n,) the trim speeds the run started from
    gains: ControllerGains
    config: HoverConfig
    rotor_names: tuple[str, ...]
    series: dict[str, np.ndarray] = field(default_factory=dict)  # sampled time series

    @property
    def passed(self) -> bool:
        return self.status is ExitStatus.PASSED

    def to_dict(self) -> dict:
        c = self.config
        return {
            "status": self.status.value,
            "passed": self.passed,
            "message": self.message,
            "end_time_s": self.end_time_s,
            "settle_time_s": _finite_or_none(self.settle_time_s),
            "max_position_error_m": self.max_position_error_m,
            "max_attitude_error_deg": self.max_attitude_error_deg,
            "final_position_error_m": self.final_position_error_m,
            "final_attitude_error_deg": self.final_attitude_error_deg,
            "max_throttle": self.max_throttle,
            "longest_saturation_s": self.longest_saturation_s,
            "final_omega_rad_s": dict(zip(self.rotor_names,
                                          (float(w) for w in self.final_omega_rad_s))),
            "config": {"duration_s": c.duration_s, "rate_hz": c.rate_hz,
                       "offset_m": list(c.offset_m), "roll_rad": c.roll_rad,
                       "pitch_rad": c.pitch_rad, "yaw_rad": c.yaw_rad,
                       "position_tol_m": c.position_tol_m,
                       "attitude_tol_deg": c.attitude_tol_deg, "hold_s": c.hold_s,
                       "integrator": "semi-implicit Euler"},
            "gains": self.gains.to_dict(),
        }


def simulate_hover(params: VehicleParams, config: HoverConfig = HoverConfig(),
                   design: ControllerDesign = ControllerDesign(),
                   record: bool = True) -> HoverRun:
    """Fly `params` from the disturbed start for config.duration_s and judge the hover."""
    config.validate()
    gains = ControllerGains.from_params(params, design)
    n = params.n_rotors
    dt = config.dt_s
    n_steps = config.n_steps
    every = config.sample_every
    sample_dt = every * dt
    sqrt, acos, degrees = math.sqrt, math.acos, math.degrees

    # ---- constants of the run, as plain floats
    g = params.g_m_s2
    m = params.mass_kg
    J = [[float(x) for x in row] for row in params.inertia_kg_m2]
    Ji = [[float(x) for x in row] for row in np.linalg.inv(params.inertia_kg_m2)]
    J00, J01, J02, J10, J11, J12, J20, J21, J22 = J[0] + J[1] + J[2]
    kp, kd, ki = gains.kp_1_s2, gains.kd_1_s, gains.ki_1_s3
    kR, kw = gains.kR_1_s2, gains.kw_1_s
    a_h_max, a_v = gains.max_horizontal_accel_m_s2, gains.max_vertical_accel_m_s2
    i_max = gains.max_integral_m_s
    yaw_cos, yaw_sin = 1.0, 0.0
    A = params.allocation()
    up, down = speed_filter_factors(dt, params.time_constant_up_s, params.time_constant_down_s)
    omega_max = [float(w) for w in params.omega_max_rad_s]
    # Per rotor: thrust constant, thrust-to-wrench column, geometry, drag coefficients,
    # then the controller side: allocation row, thrust limit, 1/k_hat, lag factors.
    rotors = [(float(params.motor_constant[i]),
               float(params.rotor_axis[i, 0]), float(params.rotor_axis[i, 1]),
               float(params.rotor_axis[i, 2]),
               float(A[1, i]), float(A[2, i]), float(A[3, i]),
               float(params.rotor_position_m[i, 0]), float(params.rotor_position_m[i, 1]),
               float(params.rotor_position_m[i, 2]),
               float(params.rotor_drag_coefficient[i]),
               float(params.rolling_moment_coefficient[i]),
               *(float(x) for x in gains.allocation_pinv[i]),
               float(gains.motor_constant[i] * gains.omega_max_rad_s[i] ** 2),
               1.0 / float(gains.motor_constant[i]), float(up[i]), float(down[i]))
              for i in range(n)]
    alloc_rows = [r[12:16] for r in rotors]
    thrust_max = [r[16] for r in rotors]
    has_drag = any(r[10] != 0.0 or r[11] != 0.0 for r in rotors)
    dt_inv_m = dt / m
    Ji = [[dt * x for x in row] for row in Ji]   # dt J^-1: one multiply less per step
    I00, I01, I02, I10, I11, I12, I20, I21, I22 = Ji[0] + Ji[1] + Ji[2]

    # ---- initial state
    spx, spy, spz = 0.0, 0.0, float(config.hover_altitude_m)
    px, py, pz = (spx + config.offset_m[0], spy + config.offset_m[1], spz + config.offset_m[2])
    vx = vy = vz = 0.0
    qw, qx, qy, qz = (float(x) for x in quat_from_rpy(config.roll_rad, config.pitch_rad,
                                                      config.yaw_rad))
    wx = wy = wz = 0.0
    omega0 = hover_speeds(params, gains)
    omega = [float(w) for w in omega0]
    ix = iy = iz = 0.0

    # ---- judging
    pos_tol, cos_tol = config.position_tol_m, config.cos_attitude_tol
    status, reason, value, end_time = None, "", 0.0, config.duration_s
    last_out, within, worst = 0.0, False, 0
    sat_since, sat_rotor = None, 0          # current saturated streak
    sat_longest, sat_longest_rotor = 0.0, 0
    max_pos, min_cos, max_throttle = 0.0, 1.0, 0.0
    pos = cos_att = 0.0
    rec: list[tuple] = []

    for step in range(n_steps + 1):
        t = step * dt
        # rotation body -> world
        xx, yy, zz = qx * qx, qy * qy, qz * qz
        xy, xz, yz = qx * qy, qx * qz, qy * qz
        xw, yw, zw = qw * qx, qw * qy, qw * qz
        R00, R01, R02 = 1.0 - 2.0 * (yy + zz), 2.0 * (xy - zw), 2.0 * (xz + yw)
        R10, R11, R12 = 2.0 * (xy + zw), 1.0 - 2.0 * (xx + zz), 2.0 * (yz - xw)
        R20, R21, R22 = 2.0 * (xz - yw), 2.0 * (yz + xw), 1.0 - 2.0 * (xx + yy)

        # ---- controller (controller.control, in floats)
        ex, ey, ez = px - spx, py - spy, pz - spz
        ax = -kp * ex - kd * vx - ki * ix
        ay = -kp * ey - kd * vy - ki * iy
        az = -kp * ez - kd * vz - ki * iz
        scale = m * a_h_max / max(sqrt(ax * ax + ay * ay), a_h_max)
        Fx, Fy = scale * ax, scale * ay
        Fz = m * (min(max(az, -a_v), a_v) + g)
        inv_F = 1.0 / sqrt(Fx * Fx + Fy * Fy + Fz * Fz)
        b3x, b3y, b3z = Fx * inv_F, Fy * inv_F, Fz * inv_F
        b2x, b2y, b2z = -b3z * yaw_sin, b3z * yaw_cos, b3x * yaw_sin - b3y * yaw_cos
        inv_n2 = 1.0 / sqrt(b2x * b2x + b2y * b2y + b2z * b2z)
        b2x, b2y, b2z = b2x * inv_n2, b2y * inv_n2, b2z * inv_n2
        b1x, b1y, b1z = b2y * b3z - b2z * b3y, b2z * b3x - b2x * b3z, b2x * b3y - b2y * b3x
        f = Fx * R02 + Fy * R12 + Fz * R22
        M21 = b3x * R01 + b3y * R11 + b3z * R21
        M12 = b2x * R02 + b2y * R12 + b2z * R22
        M02 = b1x * R02 + b1y * R12 + b1z * R22
        M20 = b3x * R00 + b3y * R10 + b3z * R20
        M10 = b2x * R00 + b2y * R10 + b2z * R20
        M01 = b1x * R01 + b1y * R11 + b1z * R21
        s0 = kR * 0.5 * (M21 - M12) + kw * wx
        s1 = kR * 0.5 * (M02 - M20) + kw * wy
        s2 = kR * 0.5 * (M10 - M01) + kw * wz
        Jw0 = J00 * wx + J01 * wy + J02 * wz
        Jw1 = J10 * wx + J11 * wy + J12 * wz
        Jw2 = J20 * wx + J21 * wy + J22 * wz
        t0 = -(J00 * s0 + J01 * s1 + J02 * s2) + (wy * Jw2 - wz * Jw1)
        t1 = -(J10 * s0 + J11 * s1 + J12 * s2) + (wz * Jw0 - wx * Jw2)
        t2 = -(J20 * s0 + J21 * s1 + J22 * s2) + (wx * Jw1 - wy * Jw0)

        # ---- allocation (controller.allocate): pseudo-inverse, desaturated when needed
        thrust_cmd = [c0 * f + c1 * t0 + c2 * t1 + c3 * t2 for c0, c1, c2, c3 in alloc_rows]
        saturated = False
        for T, hi in zip(thrust_cmd, thrust_max):
            if T < 0.0 or T > hi:
                saturated = True
                break
        if saturated:
            worst = _most_out_of_range(thrust_cmd, thrust_max)
            thrust_cmd = _prioritised(alloc_rows, thrust_max, f, t0, t1, t2)

        last = step == n_steps
        if step % every == 0 or last:
            # ---- judge the state at time t (same rules as batch.simulate_batch)
            pos = sqrt(ex * ex + ey * ey + ez * ez)
            # Attitude error: angle from the level hover attitude at the setpoint heading.
            cos_att = min(max(0.5 * (R00 + R11 + R22 - 1.0), -1.0), 1.0)
            throttle = max(w / wm for w, wm in zip(omega, omega_max))
            max_pos = max(max_pos, pos) if pos == pos else max_pos
            min_cos = min(min_cos, cos_att) if cos_att == cos_att else min_cos
            max_throttle = max(max_throttle, throttle)
            within = pos <= pos_tol and cos_att >= cos_tol
            if not within:
                last_out = t
            if saturated:
                if sat_since is None:
                    sat_since, sat_rotor = t, worst
                if t - sat_since > sat_longest:
                    sat_longest, sat_longest_rotor = t - sat_since, sat_rotor
            else:
                sat_since = None
            rate_xy = sqrt(wx * wx + wy * wy)
            if record:
                rec.append((t, px, py, pz, R00, R10, R20, R21, R22, pos, cos_att, *omega))
            if not all(math.isfinite(x) for x in (px, py, pz, qw, qx, qy, qz, wx, wy, wz)):
                status, reason, value = ExitStatus.DIVERGED, "non-finite", 0.0
            elif R22 < 0.0:
                status, reason, value = (ExitStatus.CRASHED, "flipped",
                                         degrees(acos(max(R22, -1.0))))
            elif pz < 0.0:
                status, reason, value = ExitStatus.CRASHED, "ground", pz
            elif abs(wz) > config.yaw_spin_rad_s:
                status, reason, value = ExitStatus.YAW_SPIN, "yaw-spin", abs(wz)
            elif pos > config.divergence_distance_m:
                status, reason, value = ExitStatus.DIVERGED, "drifted", pos
            elif rate_xy > config.diverged_rate_rad_s:
                status, reason, value = ExitStatus.DIVERGED, "rate", rate_xy
            if status is not None:
                end_time = t
                break
            if last:
                if within and last_out + sample_dt <= config.duration_s - config.hold_s + 1e-9:
                    status, reason = ExitStatus.PASSED, "settled"
                elif sat_longest >= config.saturation_limit_s - 1e-9:
                    status, reason, value = (ExitStatus.SATURATED, "saturated",
                                             float(sat_longest_rotor))
                else:
                    status, reason = ExitStatus.NOT_SETTLED, "not-settled"
                break

        # ---- plant: thrust, yaw drag and rotor drag (dynamics.body_wrench) at the current
        # speeds; in the same pass, the motors' response to this step's command
        # (motor.speed_command + first-order lag)
        Fbx = Fby = Fbz = Tbx = Tby = Tbz = 0.0
        if has_drag:
            vbx = R00 * vx + R10 * vy + R20 * vz
            vby = R01 * vx + R11 * vy + R21 * vz
            vbz = R02 * vx + R12 * vy + R22 * vz
        next_omega = []
        for (k, a0, a1, a2, g0, g1, g2, r0, r1, r2, cd, cr, _c0, _c1, _c2, _c3, hi, inv_k,
             f_up, f_down), w, T_cmd in zip(rotors, omega, thrust_cmd):
            T = k * w * w
            Fbx += a0 * T
            Fby += a1 * T
            Fbz += a2 * T
            Tbx += g0 * T
            Tby += g1 * T
            Tbz += g2 * T
            if has_drag:
                ux = vbx + wy * r2 - wz * r1
                uy = vby + wz * r0 - wx * r2
                uz = vbz + wx * r1 - wy * r0
                ua = ux * a0 + uy * a1 + uz * a2
                ux, uy, uz = ux - ua * a0, uy - ua * a1, uz - ua * a2
                c = -w * cd
                dx, dy, dz = c * ux, c * uy, c * uz
                c = -w * cr
                Fbx += dx
                Fby += dy
                Fbz += dz
                Tbx += r1 * dz - r2 * dy + c * ux
                Tby += r2 * dx - r0 * dz + c * uy
                Tbz += r0 * dy - r1 * dx + c * uz
            cmd = sqrt(T_cmd * inv_k) if T_cmd > 0.0 else 0.0
            next_omega.append(cmd + (w - cmd) * (f_up if cmd > w else f_down))
        omega = next_omega

        # ---- semi-implicit Euler (dynamics.step_rigid_body, in floats)
        fx, fy, fz = Fbx * dt_inv_m, Fby * dt_inv_m, Fbz * dt_inv_m
        vx += R00 * fx + R01 * fy + R02 * fz
        vy += R10 * fx + R11 * fy + R12 * fz
        vz += R20 * fx + R21 * fy + R22 * fz - dt * g
        Jw0 = J00 * wx + J01 * wy + J02 * wz
        Jw1 = J10 * wx + J11 * wy + J12 * wz
        Jw2 = J20 * wx + J21 * wy + J22 * wz
        h0 = Tbx - (wy * Jw2 - wz * Jw1)
        h1 = Tby - (wz * Jw0 - wx * Jw2)
        h2 = Tbz - (wx * Jw1 - wy * Jw0)
        wx += I00 * h0 + I01 * h1 + I02 * h2
        wy += I10 * h0 + I11 * h1 + I12 * h2
        wz += I20 * h0 + I21 * h1 + I22 * h2
        px += dt * vx
        py += dt * vy
        pz += dt * vz
        rate = sqrt(wx * wx + wy * wy + wz * wz)
        half_angle = 0.5 * dt * rate
        c = math.cos(half_angle)
        s = math.sin(half_angle) / rate if rate > 0.0 else 0.0
        dx, dy, dz = s * wx, s * wy, s * wz
        qw, qx, qy, qz = (qw * c - qx * dx - qy * dy - qz * dz,
                          qw * dx + qx * c + qy * dz - qz * dy,
                          qw * dy - qx * dz + qy * c + qz * dx,
                          qw * dz + qx * dy - qy * dx + qz * c)
        inv_q = 1.0 / sqrt(qw * qw + qx * qx + qy * qy + qz * qz)
        qw, qx, qy, qz = qw * inv_q, qx * inv_q, qy * inv_q, qz * inv_q

        ix = min(max(ix + dt * ex, -i_max), i_max)
        iy = min(max(iy + dt * ey, -i_max), i_max)
        iz = min(max(iz + dt * ez, -i_max), i_max)

    # Time it entered the band for good; NaN when it ended early or outside the band.
    reached_end = status in (ExitStatus.PASSED, ExitStatus.NOT_SETTLED, ExitStatus.SATURATED)
    settle = last_out + sample_dt if reached_end and within else math.nan
    final_att_deg = degrees(acos(cos_att)) if cos_att == cos_att else math.nan
    message = describe(status, reason, value, end_time, settle, pos, final_att_deg, config,
                       params.rotor_names, sat_longest)
    return HoverRun(
        status=status, reason=reason, message=message, end_time_s=end_time,
        settle_time_s=settle, max_position_error_m=max_pos,
        max_attitude_error_deg=degrees(acos(min_cos)), final_position_error_m=pos,
        final_attitude_error_deg=final_att_deg, max_throttle=max_throttle,
        longest_saturation_s=sat_longest,
        final_omega_rad_s=np.array(omega), initial_omega_rad_s=omega0, gains=gains,
        config=config, rotor_names=params.rotor_names,
        series=_series(rec, params.rotor_names) if record else {})


def _most_out_of_range(thrust: list[float], thrust_max: list[float]) -> int:
    excess = [max(-T, T - hi) / hi for T, hi in zip(thrust, thrust_max)]
    return excess.index(max(excess))


def _prioritised(rows: list[tuple], thrust_max: list[float], f: float, t0: float, t1: float,
                 t2: float) -> list[float]:
    """controller._prioritised for one vehicle: thrust, then roll/pitch, then yaw."""
    base = [r[0] * f for r in rows]
    over = [hi / b for b, hi in zip(base, thrust_max) if b > hi]
    if over:
        fit = min(over)
        base = [b * fit for b in base]
    base = [min(max(b, 0.0), hi) for b, hi in zip(base, thrust_max)]
    for part in ([r[1] * t0 + r[2] * t1 for r in rows], [r[3] * t2 for r in rows]):
        scale = math.inf
        for b, d, hi in zip(base, part, thrust_max):
            if d > 0.0:
                scale = min(scale, (hi - b) / d)
            elif d < 0.0:
                scale = min(scale, -b / d)
        scale = min(max(scale, 0.0), 1.0)
        base = [b + scale * d for b, d in zip(base, part)]
    return [min(max(b, 0.0), hi) for b, hi in zip(base, thrust_max)]


def _series(rec: list[tuple], rotor_names: tuple[str, ...]) -> dict[str, np.ndarray]:
    """Sampled time series; attitude as roll/pitch/yaw (URDF rpy convention)."""
    if not rec:
        return {}
    data = np.array(rec, dtype=float)
    R00, R10, R20, R21, R22 = data[:, 4:9].T
    out = {"t_s": data[:, 0], "x_m": data[:, 1], "y_m": data[:, 2], "z_m": data[:, 3],
           "roll_rad": np.arctan2(R21, R22),
           "pitch_rad": np.arcsin(np.clip(-R20, -1.0, 1.0)),
           "yaw_rad": np.arctan2(R10, R00),
           "position_error_m": data[:, 9],
           "attitude_error_deg": np.degrees(np.arccos(np.clip(data[:, 10], -1.0, 1.0)))}
    for i, name in enumerate(rotor_names):
        out[f"omega_{name}_rad_s"] = data[:, 11 + i]
    return out


def _finite_or_none(value: float) -> float | None:
    return value if math.isfinite(value) else None
