"""The numbers `equations` flies, from a vehicle, its controller and the run: one place
that lays them out (equations' flat layouts), for every engine.

The controller is the nominal one (`ControllerGains`); the plant may differ per vehicle
in mass, inertia scale S (J = S J0 S), COM shift and motor constants (`dynamics.Plant`,
the robustness batch's perturbations).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from reedtool.sim import HoverConfig
from reedtool.sim.controller import ControllerGains
from reedtool.sim.motor import speed_filter_factors


# Names of the traced step's values (scalar, columns): the state in equations' layout,
# the rotation and the position error control_state computes.
STATE = ("px", "py", "pz", "vx", "vy", "vz", "qw", "qx", "qy", "qz", "wx", "wy", "wz",
         "ix", "iy", "iz")
ROTATION = ("R00", "R01", "R02", "R10", "R11", "R12", "R20", "R21", "R22")
ERROR = ("ex", "ey", "ez")


def state_names(n_rotors: int) -> list[str]:
    return [*STATE, *(f"om{i}" for i in range(n_rotors))]


def as_constants(x):
    """The equations' numbers as Python floats and tuples of them (what a tracer folds)."""
    if isinstance(x, bool):
        return x
    if isinstance(x, tuple):
        return tuple(as_constants(v) for v in x)
    if hasattr(x, "shape") and x.shape != ():
        return tuple(float(v) for v in x)
    return float(x)


@dataclass(frozen=True)
class Inputs:
    ctl: np.ndarray           # (18,) equations' CTL
    pinv: np.ndarray          # (4 n,) the allocation's pseudo-inverse, row per rotor
    thrust_max: np.ndarray    # (n,)
    setpoint: np.ndarray      # (3,)
    nominal: tuple            # dt g lead i_max pos axis tmap cd cr J0 dt_J0inv inv_k up down
                              # lead_up lead_down omega_max (shared by every vehicle)
    mass: np.ndarray          # (N,)
    S: np.ndarray             # (N, 3)
    shift: np.ndarray         # (N, 3)
    k: np.ndarray             # (N, n)

    def vehicle(self, j: int = 0) -> tuple:
        """equations' `veh` for vehicle j."""
        dt, g, lead, i_max, pos, axis, tmap, cd, cr, J0, dt_J0inv, inv_k, up, down, lead_up, \
            lead_down, omega_max = self.nominal
        return (dt, g, float(self.mass[j]), lead, i_max, pos, axis, tmap, cd, cr, self.k[j],
                self.shift[j], self.S[j], J0, dt_J0inv, inv_k, up, down, lead_up, lead_down,
                omega_max)


def hover_speeds(params, gains: ControllerGains) -> np.ndarray:
    """The controller's allocation of [m*g, 0, 0, 0]: the minimum-norm trim speeds every
    engine starts from."""
    from reedtool.sim.motor import speed_command

    thrust = gains.allocation_pinv @ np.array([params.weight_N, 0.0, 0.0, 0.0])
    return speed_command(thrust, gains.motor_constant, gains.omega_max_rad_s)


def _c(x) -> np.ndarray:
    # fresh writable C arrays: numba types read-only or strided arrays apart (a recompile)
    return np.array(x, dtype=float, order="C", copy=True)


def inputs(params, gains: ControllerGains, config: HoverConfig, plant=None,
           setpoint_m=None) -> Inputs:
    """The equations' numbers for `params` flown by `gains` as `config` says; the plant's
    from `plant` (default: the nominal vehicle), its thrust and torque maps included
    (tests swap them to model a rotor spinning the wrong way)."""
    from reedtool.sim.dynamics import Plant

    plant = plant if plant is not None else Plant.from_params(params, 1)
    dt = config.dt_s
    up, down = speed_filter_factors(dt, params.time_constant_up_s, params.time_constant_down_s)
    n = params.n_rotors
    lead = gains.motor_lead_factors(dt)
    J0 = np.asarray(plant.inertia_kg_m2, dtype=float)
    ctl = [gains.kp_1_s2, gains.kd_1_s, gains.ki_1_s3, gains.kR_1_s2, gains.kw_1_s,
           gains.max_horizontal_accel_m_s2, gains.max_vertical_accel_m_s2, gains.mass_kg,
           gains.g_m_s2, *np.asarray(gains.inertia_kg_m2, dtype=float).ravel()]
    nominal = (float(dt), float(plant.g_m_s2), lead is not None,
               float(gains.max_integral_m_s), _c(np.ravel(plant.rotor_position_m)),
               _c(np.asarray(plant.force_map).T.ravel()),
               _c(np.asarray(plant.torque_map).T.ravel()),
               _c(plant.rotor_drag_coefficient), _c(plant.rolling_moment_coefficient),
               _c(J0.ravel()), _c(dt * np.linalg.inv(J0).ravel()), _c(1.0 / gains.motor_constant),
               _c(up), _c(down),
               *(_c(f) for f in (lead or (np.ones(n), np.ones(n)))),
               _c(gains.omega_max_rad_s))
    sp = (0.0, 0.0, config.hover_altitude_m) if setpoint_m is None else setpoint_m
    return Inputs(ctl=_c(ctl), pinv=_c(np.asarray(gains.allocation_pinv).ravel()),
                  thrust_max=_c(gains.motor_constant * gains.omega_max_rad_s ** 2),
                  setpoint=_c(sp), nominal=nominal, mass=_c(plant.mass_kg),
                  S=_c(np.asarray(plant.inertia_scale_sqrt).T),
                  shift=_c(np.asarray(plant.com_shift_m).T),
                  k=_c(np.asarray(plant.motor_constant).T))


# Names of the judge's record J in the traced code (equations' J layout).
JUDGE = ("max_pos", "min_cos", "max_throttle", "pos", "cos_att", "last_out", "within",
         "sat_since", "sat_rotor", "sat_longest", "sat_rotor_longest")


def judge_settings(config: HoverConfig) -> np.ndarray:
    """equations' jc for `config`: what the judge holds a flight to."""
    return _c([config.position_tol_m, config.cos_attitude_tol, config.yaw_spin_rad_s,
               config.divergence_distance_m, config.diverged_rate_rad_s, config.duration_s,
               config.hold_s, config.saturation_limit_s,
               config.sample_every * config.dt_s])
