"""The RotorS motor model (rotors_gazebo_plugins/gazebo_motor_model.cpp), without Gazebo.

Per rotor i spinning at omega_i (physical speed, rad/s, >= 0):
- thrust k_i * omega_i^2 along the rotor axis a_i, applied at the rotor;
- yaw drag reaction torque -turning_sign_i * c_m,i * thrust_i along a_i (a ccw rotor
  pushes the body cw);
- rotor drag -omega_i * c_drag,i * u_perp at the rotor, u_perp the rotor's velocity
  relative to the air with its component along a_i removed;
- rolling moment -omega_i * c_roll,i * u_perp on the body;
- speed: the commanded speed, clamped to [0, omega_max], goes through a first-order lag
  with time constant tau_up when spinning up and tau_down when spinning down (RotorS's
  FirstOrderFilter; its exponential update is exact for a command held over the step).
"""

from __future__ import annotations

import math

import numpy as np


def speed_filter_factors(dt_s: float, time_constant_up_s: np.ndarray,
                         time_constant_down_s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """exp(-dt/tau) for spinning up and down: omega' = cmd + (omega - cmd) * factor."""
    up = np.exp(-dt_s / np.asarray(time_constant_up_s, dtype=float))
    down = np.exp(-dt_s / np.asarray(time_constant_down_s, dtype=float))
    return up, down


def next_speed_one(thrust_N, inv_k, omega, up, down, lead, lead_up, lead_down, omega_max):
    """One rotor's speed after a step: the speed command for `thrust_N` (the allocation
    keeps it within [0, k omega_max^2]), the controller's lead on it when `lead`
    (ControllerGains.motor_lead_factors, clamped to [0, omega_max]), then the lag.

    The single source of the compiled engine's motor step, one vehicle and a block alike
    (compiled jits this function and inlines it); written in the subset numba compiles,
    comparisons instead of min/max. The generated float step and the numpy batch write the
    same operations in their own form, held to it by the engine agreement tests.
    """
    cmd = math.sqrt(thrust_N * inv_k) if thrust_N > 0.0 else 0.0
    if lead:
        cmd = omega + (cmd - omega) * (lead_up if cmd > omega else lead_down)
        cmd = omega_max if cmd > omega_max else (0.0 if cmd < 0.0 else cmd)
    return cmd + (omega - cmd) * (up if cmd > omega else down)


def speed_command(thrust_cmd_N: np.ndarray, motor_constant: np.ndarray,
                  omega_max_rad_s: np.ndarray) -> np.ndarray:
    """Rotor speeds that give the commanded thrusts, clamped to [0, omega_max].

    Arrays are (n,) or (n, N) with the rotor first; constants broadcast as (n,) or (n, 1).
    """
    omega_sq = np.clip(thrust_cmd_N / motor_constant, 0.0, omega_max_rad_s ** 2)
    return np.sqrt(omega_sq)


def drag_matrices(position_m: np.ndarray, axis: np.ndarray, drag_coefficient: np.ndarray,
                  rolling_moment_coefficient: np.ndarray) -> np.ndarray:
    """(9, 6, n): rotor i's drag wrench per rad/s of its speed, linear in the body twist.

    With twist xi = [v_o; w] (velocity of the body origin and angular velocity, body axes),
    rotor i moves at u_i = v_o + w x r_i = [I, -[r_i]x] xi, so its drag force is
    -omega_i c_d P_i [I, -[r_i]x] xi with P_i = I - a_i a_i^T. Rows 0-2 are that force,
    rows 3-5 its torque about the origin (r_i x force), rows 6-8 the rolling moment.
    Summing omega_i * K_i over the rotors turns the per-rotor drag into one matrix product.
    """
    position_m = np.asarray(position_m, dtype=float)
    n = len(position_m)
    K = np.zeros((9, 6, n))
    for i in range(n):
        a = axis[i]
        P = np.eye(3) - np.outer(a, a)
        velocity_map = np.hstack([np.eye(3), -_skew(position_m[i])])   # xi -> u_i
        u_perp_map = P @ velocity_map
        K[0:3, :, i] = -drag_coefficient[i] * u_perp_map
        K[3:6, :, i] = _skew(position_m[i]) @ K[0:3, :, i]
        K[6:9, :, i] = -rolling_moment_coefficient[i] * u_perp_map
    return K


def _skew(v: np.ndarray) -> np.ndarray:
    return np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])
