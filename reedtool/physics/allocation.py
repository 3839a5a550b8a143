"""The control-allocation matrix, derived from rotor geometry rather than written per frame."""

from __future__ import annotations

from typing import Sequence

import numpy as np

from reedtool.physics.rotors import Rotor


def allocation_matrix(rotors: Sequence[Rotor], com_m: np.ndarray) -> np.ndarray:
    """(4, n) matrix B with [thrust_z, tau_x, tau_y, tau_z] = B @ thrust_N.

    Row 0 is the collective thrust along body z; rows 1-3 the torque about `com_m` in the
    base axes: the lever arm of each rotor's force plus its drag reaction torque, which
    RotorS applies as -turning_sign * moment_constant * thrust along the rotor axis.
    """
    com_m = np.asarray(com_m, dtype=float)
    B = np.zeros((4, len(rotors)))
    for i, rotor in enumerate(rotors):
        axis = rotor.axis / np.linalg.norm(rotor.axis)
        lever = rotor.position_m - com_m
        torque = np.cross(lever, axis) - rotor.turning_sign * rotor.moment_constant * axis
        B[0, i] = axis[2]
        B[1:, i] = torque
    return B
