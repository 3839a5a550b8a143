"""One vehicle, fast: the hover simulation in plain Python floats, and how it is judged.

For a single vehicle numpy's per-call overhead (about half a microsecond per operation on
tiny arrays) dominates, so the array engine in `batch` runs a 10 s flight in seconds.
`scalar` generates the step for the vehicle at hand, traced from the flight equations
(`equations`) as the array engine's is, its judge included; this module runs it (or the
compiled engine) and turns the judged flight into a HoverRun.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from reedtool.io.json_values import finite_or_none
from reedtool.sim import ExitStatus, HoverConfig
from reedtool.sim.batch import STATUS_OF_REASON, describe
from reedtool.sim.equations import REASONS
from reedtool.sim.layout import hover_speeds
from reedtool.sim.controller import ControllerDesign, ControllerGains
from reedtool.sim.dynamics import quat_from_rpy
from reedtool.sim.params import VehicleParams
from reedtool.sim.scalar import compile_vehicle


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
    engine: str = "numpy"              # which engine flew it ("numpy" or "numba")

    @property
    def passed(self) -> bool:
        return self.status is ExitStatus.PASSED

    def to_dict(self) -> dict:
        c = self.config
        return {
            "status": self.status.value,
            "engine": self.engine,
            "passed": self.passed,
            "message": self.message,
            "end_time_s": self.end_time_s,
            "settle_time_s": finite_or_none(self.settle_time_s),
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
                   record: bool = True, engine: str = "numpy",
                   gains: ControllerGains | None = None,
                   initial_omega_rad_s: np.ndarray | None = None) -> HoverRun:
    """Fly `params` from the disturbed start for config.duration_s and judge the hover.

    `engine`: "numpy" (the generated float step, no compiler needed) or "numba" (the
    compiled kernel of `compiled`: the same equations, the same Flight). `gains` and
    `initial_omega_rad_s` override the designed controller and the trim speeds at the
    start (sim.failure: the flight after a rotor fails).
    """
    config.validate()
    if gains is None:
        gains = ControllerGains.from_params(params, design)
    acos, degrees = math.acos, math.degrees
    setpoint = (0.0, 0.0, float(config.hover_altitude_m))
    if engine == "numba":
        from reedtool.sim.compiled import vehicle_flyer

        fly = vehicle_flyer(params, gains, config, setpoint)
    else:
        fly = compile_vehicle(params, gains, config, setpoint)

    # ---- the disturbed start: rotors at the trim speeds, at rest
    p0 = tuple(sp + off for sp, off in zip(setpoint, config.offset_m))
    q0 = tuple(float(x) for x in quat_from_rpy(config.roll_rad, config.pitch_rad,
                                                config.yaw_rad))
    omega0 = (hover_speeds(params, gains) if initial_omega_rad_s is None
              else np.asarray(initial_omega_rad_s, dtype=float))
    rec: list[tuple] = []
    flight = fly((*p0, 0.0, 0.0, 0.0, *q0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0,
                  tuple(float(w) for w in omega0)), rec.append if record else None)

    # the judge's ending (equations.judge_sample, verdict, settle_time), as the engine ran it
    reason = REASONS[flight.reason]
    status = STATUS_OF_REASON[reason]
    end_time, value, settle = flight.end_time_s, flight.value, flight.settle_time_s
    sat_longest = flight.longest_saturation_s
    pos, cos_att = flight.position_error_m, flight.cos_attitude
    max_pos, min_cos, max_throttle = (flight.max_position_error_m, flight.min_cos_attitude,
                                      flight.max_throttle)
    omega = flight.omega_rad_s
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
        series=sample_series(rec, params.rotor_names) if record else {}, engine=engine)


def sample_series(rec: list[tuple], rotor_names: tuple[str, ...]) -> dict[str, np.ndarray]:
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
