"""Numbers as XML text, the two ways reedtool writes them.

`float_text`: the shortest text that reads back as the same float, for files reedtool
generates (the gz port, a URDF equivalent of an SDF): reading them gives the numbers back.
`short_text`: ten significant digits, for numbers spliced into a user's own file or printed
for them to paste (an inertia a person reads), where 0.123456789012345 would be noise.
"""

from __future__ import annotations

import numpy as np


def float_text(value: float) -> str:
    """Shortest text that reads back as the same float; -0 written as 0."""
    value = float(value)
    return "0" if value == 0 else repr(value)


def short_text(value: float) -> str:
    """Ten significant digits (no '-0'): what a person reads and pastes."""
    value = float(value)
    return "0" if value == 0.0 else f"{value:.10g}"


def clean_tensor(inertia_kg_m2, rel: float = 1e-12) -> np.ndarray:
    """Symmetrised tensor with round-off-sized entries (relative to its largest) set to 0:
    the tensor as written for a person (an exported part's 1e-20 products are noise)."""
    I = np.asarray(inertia_kg_m2, dtype=float)
    I = (I + I.T) / 2.0
    scale = float(np.max(np.abs(I))) if I.size else 0.0
    return np.where(np.abs(I) <= rel * scale, 0.0, I) + 0.0   # + 0.0 turns -0.0 into 0.0


def vector_text(values, number=float_text) -> str:
    """Space-separated numbers, as URDF attributes and SDF elements hold vectors."""
    return " ".join(number(v) for v in np.asarray(values, dtype=float).ravel())


def pose_values(T: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(xyz, roll pitch yaw) of a 4x4 transform, as URDF <origin> and SDF <pose> hold it."""
    from reedtool.frames import matrix_to_rpy

    return np.asarray(T[:3, 3], dtype=float), np.asarray(matrix_to_rpy(T[:3, :3]), dtype=float)
