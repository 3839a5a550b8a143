"""Rotations, T_a_b helpers and the named axis conventions meshes arrive in.

URDF `rpy` is roll-pitch-yaw about FIXED axes X, then Y, then Z, i.e.
R = Rz(yaw) @ Ry(pitch) @ Rx(roll). Poses are 4x4 transforms T_a_b ("pose of b in a"),
so a point p_b maps to p_a = T_a_b @ [p_b, 1].

Axis conventions: ROS body frames are FLU (REP 103: x forward, y left, z up). A convention
here is named by the direction of its x, y, z axes in body terms, one letter each from
f/b (forward/back), l/r (left/right), u/d (up/down): "frd" is x forward, y right, z down.
A few common names are aliases of those codes (NED at zero yaw is FRD, ENU and NWU are
FLU, CAD "y-up" is LUF). `R_flu_src` maps a vector in the source axes to FLU axes:
v_flu = R_flu_src @ v_src.
"""

from __future__ import annotations

from dataclasses import dataclass
from itertools import permutations, product

import numpy as np

from reedtool.errors import ReedtoolError

# ---------------------------------------------------------------- rotations

def rot_x(angle_rad: float) -> np.ndarray:
    c, s = np.cos(angle_rad), np.sin(angle_rad)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def rot_y(angle_rad: float) -> np.ndarray:
    c, s = np.cos(angle_rad), np.sin(angle_rad)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def rot_z(angle_rad: float) -> np.ndarray:
    c, s = np.cos(angle_rad), np.sin(angle_rad)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def rpy_to_matrix(rpy) -> np.ndarray:
    """URDF roll, pitch, yaw [rad] (fixed axes X, Y, Z) -> 3x3 rotation Rz @ Ry @ Rx."""
    roll, pitch, yaw = (float(v) for v in rpy)
    return rot_z(yaw) @ rot_y(pitch) @ rot_x(roll)


def matrix_to_rpy(R) -> np.ndarray:
    """Inverse of `rpy_to_matrix`: (roll, pitch, yaw) [rad], pitch in [-pi/2, pi/2].

    At gimbal lock (pitch = +-pi/2) roll and yaw are not separable; roll is set to 0 and
    the whole rotation about the vertical goes into yaw, which still reproduces R.
    """
    R = np.asarray(R, dtype=float)
    # R[2,0] = -sin(pitch); clip guards against |value| a hair above 1 from round-off.
    pitch = float(np.arcsin(np.clip(-R[2, 0], -1.0, 1.0)))
    cos_pitch = np.hypot(R[0, 0], R[1, 0])
    if cos_pitch > 1e-9:
        roll = float(np.arctan2(R[2, 1], R[2, 2]))
        yaw = float(np.arctan2(R[1, 0], R[0, 0]))
    else:
        roll = 0.0
        # With roll = 0: R[0,1] = -sin(yaw) and R[1,1] = cos(yaw).
        yaw = float(np.arctan2(-R[0, 1], R[1, 1]))
    return np.array([roll, pitch, yaw])


def make_T(R=None, p=None) -> np.ndarray:
    """4x4 homogeneous transform from a 3x3 rotation (default identity) and a translation."""
    T = np.eye(4)
    if R is not None:
        T[:3, :3] = np.asarray(R, dtype=float)
    if p is not None:
        T[:3, 3] = np.asarray(p, dtype=float)
    return T


def invert_T(T_a_b) -> np.ndarray:
    """T_b_a from T_a_b, using R^T rather than a general matrix inverse."""
    T_a_b = np.asarray(T_a_b, dtype=float)
    R = T_a_b[:3, :3]
    T = np.eye(4)
    T[:3, :3] = R.T
    T[:3, 3] = -R.T @ T_a_b[:3, 3]
    return T


def axis_angle(R) -> tuple[np.ndarray, float]:
    """(unit axis, angle in [0, pi] rad) of a rotation matrix; axis is x for identity."""
    R = np.asarray(R, dtype=float)
    cos_angle = np.clip((np.trace(R) - 1.0) / 2.0, -1.0, 1.0)
    angle = float(np.arccos(cos_angle))
    if angle < 1e-12:
        return np.array([1.0, 0.0, 0.0]), 0.0
    if np.pi - angle < 1e-6:
        # Near 180 deg the skew part vanishes; the axis is the dominant column of (R + I)/2.
        B = (R + np.eye(3)) / 2.0
        k = int(np.argmax(np.diag(B)))
        axis = B[:, k] / np.sqrt(B[k, k])
        return axis / np.linalg.norm(axis), angle
    axis = np.array([R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1]])
    return axis / np.linalg.norm(axis), angle


def describe_rotation(R) -> str:
    """Human text for a rotation: 'identity', '180° about x', '120° about (0.577, 0.577, 0.577)'."""
    axis, angle = axis_angle(R)
    if angle < 1e-9:
        return "identity (no rotation)"
    degrees = np.degrees(angle)
    for index, name in enumerate("xyz"):
        unit = np.zeros(3)
        unit[index] = 1.0
        if np.allclose(axis, unit, atol=1e-9):
            return f"{degrees:g}° about {name}"
        if np.allclose(axis, -unit, atol=1e-9):
            return f"{degrees:g}° about -{name}"
    return f"{degrees:g}° about ({axis[0]:.3f}, {axis[1]:.3f}, {axis[2]:.3f})"


# ------------------------------------------------------- axis conventions

# Body direction letter -> that direction in FLU coordinates.
_DIRECTIONS_FLU = {
    "f": (1.0, 0.0, 0.0), "b": (-1.0, 0.0, 0.0),
    "l": (0.0, 1.0, 0.0), "r": (0.0, -1.0, 0.0),
    "u": (0.0, 0.0, 1.0), "d": (0.0, 0.0, -1.0),
}
_WORDS = {"f": "forward", "b": "back", "l": "left", "r": "right", "u": "up", "d": "down"}

# Common names -> (letter code, what the name means for a body/mesh frame).
ALIASES: dict[str, tuple[str, str]] = {
    "ned": ("frd", "NED at zero yaw, as PX4 and aerospace use it: x north = forward, "
                   "y east = right, z down"),
    "enu": ("flu", "ENU at zero yaw, the ROS world frame: x east = forward, y north = left, z up"),
    "nwu": ("flu", "NWU: x north = forward, y west = left, z up"),
    "z-up": ("flu", "Z-up CAD with x forward: same axes as FLU"),
    "y-up": ("luf", "Y-up CAD as in SolidWorks and glTF: x left, y up, z forward; "
                    "the front faces +z"),
}


@dataclass(frozen=True)
class AxisConvention:
    name: str                 # as the user wrote it (lower-case)
    code: str                 # the letter code of its axes, e.g. "frd"
    R_flu_src: np.ndarray     # v_flu = R_flu_src @ v_src
    meaning: str              # what the axes are

    @property
    def rotation_text(self) -> str:
        return describe_rotation(self.R_flu_src)

    @property
    def description(self) -> str:
        """e.g. 'NED → FLU: 180° about x (NED at zero yaw: x north = forward, ...)'."""
        return f"{self.name.upper()} → FLU: {self.rotation_text} ({self.meaning})"


def _matrix_for_code(code: str) -> np.ndarray:
    # Column i is where source axis i points, in FLU coordinates.
    return np.column_stack([_DIRECTIONS_FLU[letter] for letter in code])


def _right_handed_codes() -> list[str]:
    codes = []
    for pair_order in permutations(("fb", "lr", "ud")):
        for letters in product(*pair_order):
            code = "".join(letters)
            if np.linalg.det(_matrix_for_code(code)) > 0:
                codes.append(code)
    return sorted(codes)


RIGHT_HANDED_CODES: tuple[str, ...] = tuple(_right_handed_codes())   # 24 codes


def valid_frame_names() -> list[str]:
    return sorted(ALIASES) + list(RIGHT_HANDED_CODES)


def _is_axis_code(key: str) -> bool:
    """Three letters naming one direction from each of the pairs f/b, l/r, u/d."""
    pairs = ("fb", "lr", "ud")
    return (len(key) == 3
            and sorted(next((i for i, pair in enumerate(pairs) if c in pair), -1)
                       for c in key) == [0, 1, 2])


def axis_convention(name: str) -> AxisConvention:
    """Look up a named or letter-coded axis convention; unknown names raise ReedtoolError."""
    key = name.strip().lower().replace("_", "-")
    if key in ALIASES:
        code, meaning = ALIASES[key]
        return AxisConvention(key, code, _matrix_for_code(code), meaning)
    if key in RIGHT_HANDED_CODES:
        meaning = ", ".join(f"{axis} {_WORDS[letter]}" for axis, letter in zip("xyz", key))
        return AxisConvention(key, key, _matrix_for_code(key), meaning)
    if _is_axis_code(key):
        raise ReedtoolError(
            f"axis convention '{name}' is left-handed (a mirror image), not a rotation of FLU",
            hint="check the CAD export; mirror the part there, or name a right-handed convention")
    raise ReedtoolError(
        f"unknown axis convention '{name}'",
        hint="use one of: " + ", ".join(sorted(ALIASES)) +
             ", or three letters for x, y, z from f/b, l/r, u/d such as "
             + ", ".join(RIGHT_HANDED_CODES))


def frame_table() -> list[AxisConvention]:
    """Every convention reedtool accepts: aliases first, then the 24 letter codes."""
    return [axis_convention(name) for name in valid_frame_names()]
