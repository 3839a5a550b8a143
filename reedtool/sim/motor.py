"""The RotorS motor model (rotors_gazebo_plugins/gazebo_motor_model.cpp), without Gazebo:
its per-step factors and the trim's speed command. The model itself, per step, is
equations.rotor_wrench, speed_command and lag; what it is:

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

import numpy as np


def speed_filter_factors(dt_s: float, time_constant_up_s: np.ndarray,
                         time_constant_down_s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """exp(-dt/tau) for spinning up and down: omega' = cmd + (omega - cmd) * factor."""
    up = np.exp(-dt_s / np.asarray(time_constant_up_s, dtype=float))
    down = np.exp(-dt_s / np.asarray(time_constant_down_s, dtype=float))
    return up, down


def speed_command(thrust_cmd_N: np.ndarray, motor_constant: np.ndarray,
                  omega_max_rad_s: np.ndarray) -> np.ndarray:
    """Rotor speeds that give the commanded thrusts, clamped to [0, omega_max].

    Arrays are (n,) or (n, N) with the rotor first; constants broadcast as (n,) or (n, 1).
    """
    omega_sq = np.clip(thrust_cmd_N / motor_constant, 0.0, omega_max_rad_s ** 2)
    return np.sqrt(omega_sq)
