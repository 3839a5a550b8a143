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
    return allocation_from_geometry([r.position_m for r in rotors], [r.axis for r in rotors],
                                    [r.turning_sign for r in rotors],
                                    [r.moment_constant for r in rotors], com_m)


def allocation_from_geometry(positions_m, axes, turning_signs, moment_constants,
                             com_m) -> np.ndarray:
    """allocation_matrix from the rotors' numbers alone (a model not yet written)."""
    com_m = np.asarray(com_m, dtype=float)
    B = np.zeros((4, len(positions_m)))
    for i, (position, axis, sign, k_m) in enumerate(zip(positions_m, axes, turning_signs,
                                                        moment_constants)):
        axis = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
        lever = np.asarray(position, dtype=float) - com_m
        B[0, i] = axis[2]
        B[1:, i] = np.cross(lever, axis) - sign * k_m * axis
    return B


def wrench_matrix(rotors: Sequence[Rotor], com_m: np.ndarray) -> np.ndarray:
    """(6, n) matrix W with [F_x, F_y, F_z, tau_x, tau_y, tau_z] = W @ thrust_N.

    The full force-and-torque allocation an omnidirectional frame is flown with: each
    rotor pushes along its axis (a reversible one with either sign of thrust).
    """
    com_m = np.asarray(com_m, dtype=float)
    W = np.zeros((6, len(rotors)))
    for i, rotor in enumerate(rotors):
        axis = rotor.axis / np.linalg.norm(rotor.axis)
        lever = rotor.position_m - com_m
        W[:3, i] = axis
        W[3:, i] = np.cross(lever, axis) - rotor.turning_sign * rotor.moment_constant * axis
    return W


def tilt_balance(rotors: Sequence[Rotor], com_m: np.ndarray) -> tuple[float, float, float, float]:
    """How the rotors' tilts cancel at equal thrust (unit thrust per rotor).

    Returns (|sum of horizontal axis components|, sum of their magnitudes, |net yaw torque
    of the tilts about the COM|, sum of the individual tilt yaw torques' magnitudes). A
    deliberate pattern (AscTec Neo: every rotor tilted the same angle, alternating) has
    both sums near zero against the magnitudes; a single tilted rotor has neither.
    """
    com_m = np.asarray(com_m, dtype=float)
    horizontal = np.zeros(2)
    horizontal_abs = yaw = yaw_abs = 0.0
    for rotor in rotors:
        axis = rotor.axis / np.linalg.norm(rotor.axis)
        horizontal += axis[:2]
        horizontal_abs += float(np.linalg.norm(axis[:2]))
        lever = rotor.position_m - com_m
        tau_z = float(lever[0] * axis[1] - lever[1] * axis[0])
        yaw += tau_z
        yaw_abs += abs(tau_z)
    return float(np.linalg.norm(horizontal)), horizontal_abs, abs(yaw), yaw_abs
