"""Available control authority: can the rotors hold hover, intact and after a failure?

The thrusts a rotor set can give, f in [0, K_1] x ... x [0, K_n], map through the
allocation matrix B (collective thrust and the three body torques per newton of rotor
thrust, `physics.allocation`) onto the attainable set Omega = {B f}: a zonotope in R^4.
The Available Control Authority Index (ACAI) of Du, Quan, Yang and Cai, "Controllability
Analysis for Multirotor Helicopter Rotor Degradation and Failure" (JGCD 2015, arXiv
1403.5986) is the signed distance from the hover point G = [m g, 0, 0, 0] to the boundary
of Omega: positive when G lies inside, so the vehicle can hold hover and still push the
thrust and every torque both ways; zero or negative when some direction is lost.

Every facet of a zonotope in R^m is parallel to m - 1 of its generators, so the facets
come from the (n choose m - 1) column subsets of B (the paper's Section III.B): for a
subset with unit normal xi, the two parallel facets lie at distance
d = sum_j (K_j / 2) |xi . b_j| from the centre F_c = B K / 2, and G is
d - |xi . (F_c - G)| inside them. The ACAI is the smallest of these over all subsets.
docs/fault-tolerance.md explains the construction and how to read the verdicts.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass, field
from typing import Sequence

import numpy as np

# Relative to the scale of the attainable set, an ACAI below this is zero: the hover point
# is on the boundary, as it is for every single failure of an alternating hexacopter.
ZERO_TOL = 1e-9
# A failure no thrust can cure: the search for the smallest sufficient thrust-to-weight
# ratio stops at this many times the weight.
MAX_THRUST_TO_WEIGHT = 100.0


def acai(B: np.ndarray, K_N: np.ndarray, G: np.ndarray) -> float:
    """Signed distance from G to the boundary of {B f : 0 <= f <= K_N} (the facet method).

    B is (m, n) with m - 1 <= n; rows are whatever the caller controls (thrust and three
    torques, or thrust and roll/pitch without yaw). A set without interior (rank of B
    below m) has G on its boundary at best, so the answer is 0 or less.
    """
    B = np.asarray(B, dtype=float)
    K_N = np.asarray(K_N, dtype=float)
    G = np.asarray(G, dtype=float)
    m, n = B.shape
    normals = _facet_normals(B)
    half_K = K_N / 2.0
    F_c = B @ half_K
    if len(normals) == 0:
        return -float(np.linalg.norm(G - F_c)) if np.linalg.matrix_rank(B) == 0 else 0.0
    d = np.abs(normals @ B) @ half_K                     # centre to each facet pair
    inside = d - np.abs(normals @ (F_c - G))
    scale = max(float(np.abs(B).max() * half_K.max()), 1e-300)
    value = float(inside.min())
    if np.linalg.matrix_rank(B, tol=ZERO_TOL * np.abs(B).max()) < m:
        value = min(value, 0.0)
    return 0.0 if abs(value) < ZERO_TOL * scale else value


def _facet_normals(B: np.ndarray) -> np.ndarray:
    """Unit normals of the hyperplanes spanned by each (m - 1)-subset of B's columns.

    Subsets whose columns are dependent span no facet and are skipped. The normal of m - 1
    vectors in R^m is their generalised cross product: component k is (-1)^k times the
    minor with row k deleted.
    """
    m, n = B.shape
    subsets = np.array(list(itertools.combinations(range(n), m - 1)), dtype=int)
    if len(subsets) == 0:
        return np.zeros((0, m))
    C = np.transpose(B[:, subsets], (1, 0, 2))          # (subsets, m, m - 1)
    rows = np.arange(m)
    normals = np.stack([(-1) ** k * np.linalg.det(C[:, rows != k, :]) for k in range(m)],
                       axis=1)
    length = np.linalg.norm(normals, axis=1)
    scale = np.abs(B).max() ** (m - 1) if B.size else 1.0
    keep = length > 1e-12 * max(scale, 1e-300)
    return normals[keep] / length[keep, None]


def full_rank(B: np.ndarray) -> bool:
    """The rank condition of the paper's controllability test: B spans every direction.

    For the hover linearisation (x = [height, attitude, their rates]) the controllability
    matrix has full rank exactly when the control effectiveness does.
    """
    B = np.asarray(B, dtype=float)
    return bool(B.size) and bool(np.linalg.matrix_rank(B, tol=ZERO_TOL * np.abs(B).max())
                                 == B.shape[0])


def min_thrust_to_weight(B: np.ndarray, K_N: np.ndarray, G: np.ndarray,
                         weight_N: float, intact_thrust_N: float) -> float | None:
    """The smallest thrust-to-weight ratio (of the intact rotor set) at which G is inside.

    Scaling every K by s scales Omega by s, and Omega contains the origin (all rotors off),
    so the ACAI does not decrease with s: a bisection finds the threshold. None when even
    MAX_THRUST_TO_WEIGHT is not enough (a direction is lost whatever the thrust).
    """
    K_N = np.asarray(K_N, dtype=float)
    if intact_thrust_N <= 0 or weight_N <= 0:
        return None
    per_ratio = weight_N / intact_thrust_N       # the scale s giving thrust-to-weight 1
    hi = MAX_THRUST_TO_WEIGHT
    if acai(B, K_N * per_ratio * hi, G) <= 0:
        return None
    lo = 0.0
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        if acai(B, K_N * per_ratio * mid, G) > 0:
            hi = mid
        else:
            lo = mid
        if hi - lo < 1e-6 * hi:
            break
    return hi


@dataclass(frozen=True)
class AuthorityCase:
    """One rotor configuration: intact, or one rotor failed (or degraded to `efficiency`)."""

    failed_index: int | None            # index into the rotor list; None: intact
    failed_name: str | None
    failed_number: int | None           # the motor number the model gives it
    efficiency: float                   # what is left of the failed rotor's thrust (0: stopped)
    acai: float                         # [thrust, roll, pitch, yaw]
    acai_without_yaw: float             # [thrust, roll, pitch]: yaw left to spin
    rank_ok: bool
    rank_ok_without_yaw: bool
    min_thrust_to_weight: float | None  # of the intact set, for this case to be controllable

    @property
    def controllable(self) -> bool:
        return self.rank_ok and self.acai > 0

    @property
    def controllable_without_yaw(self) -> bool:
        return self.rank_ok_without_yaw and self.acai_without_yaw > 0

    def to_dict(self) -> dict:
        return {
            "failed_rotor": None if self.failed_index is None else {
                "name": self.failed_name, "number": self.failed_number,
                "index": self.failed_index},
            "efficiency": self.efficiency,
            "acai": self.acai,
            "controllable": self.controllable,
            "acai_without_yaw": self.acai_without_yaw,
            "controllable_without_yaw": self.controllable_without_yaw,
            "min_thrust_to_weight": self.min_thrust_to_weight,
        }


@dataclass
class AuthorityReport:
    mass_kg: float
    weight_N: float
    thrust_max_N: np.ndarray            # K_i of each rotor, intact
    intact: AuthorityCase
    failures: list[AuthorityCase] = field(default_factory=list)

    @property
    def thrust_to_weight(self) -> float:
        return float(self.thrust_max_N.sum() / self.weight_N)

    def survivable(self) -> list[AuthorityCase]:
        return [case for case in self.failures if case.controllable]


def analyse_cases(B: np.ndarray, K_N: np.ndarray, weight_N: float,
                  names: Sequence[str] | None = None, numbers: Sequence[int | None] | None = None,
                  efficiency: float = 0.0, mass_kg: float | None = None) -> AuthorityReport:
    """The intact case and one case per rotor failed (or left with `efficiency` of its thrust).

    B is the (4, n) allocation of the lift rotors about the COM; K_N their maximum thrusts.
    """
    B = np.asarray(B, dtype=float)
    K_N = np.asarray(K_N, dtype=float)
    n = B.shape[1]
    names = list(names) if names is not None else [f"rotor_{i}" for i in range(n)]
    numbers = list(numbers) if numbers is not None else [None] * n
    G = np.array([weight_N, 0.0, 0.0, 0.0])
    intact_thrust = float(K_N.sum())

    def case(index: int | None) -> AuthorityCase:
        K_case = K_N.copy()
        if index is not None:
            K_case[index] *= efficiency
        B_case = B if index is None or efficiency > 0 else np.delete(B, index, axis=1)
        K_used = K_case if index is None or efficiency > 0 else np.delete(K_case, index)
        return AuthorityCase(
            failed_index=index,
            failed_name=None if index is None else names[index],
            failed_number=None if index is None else numbers[index],
            efficiency=1.0 if index is None else efficiency,
            acai=acai(B_case, K_used, G),
            acai_without_yaw=acai(B_case[:3], K_used, G[:3]),
            rank_ok=full_rank(B_case),
            rank_ok_without_yaw=full_rank(B_case[:3]),
            min_thrust_to_weight=min_thrust_to_weight(B_case, K_used, G, weight_N,
                                                      intact_thrust))

    mass = mass_kg if mass_kg is not None else weight_N / 9.80665
    return AuthorityReport(mass, weight_N, K_N, case(None), [case(i) for i in range(n)])


def spin_orders(turning_signs: Sequence[int]) -> list[tuple[int, ...]]:
    """Every assignment of the same number of cw and ccw rotors to the same positions."""
    n = len(turning_signs)
    n_ccw = sum(1 for s in turning_signs if s > 0)
    orders = []
    for ccw in itertools.combinations(range(n), n_ccw):
        chosen = set(ccw)
        orders.append(tuple(1 if i in chosen else -1 for i in range(n)))
    return orders


def survivable_failures(B_of_signs, K_N: np.ndarray, weight_N: float,
                        signs: Sequence[int]) -> int:
    """How many single rotor failures leave the vehicle controllable with spins `signs`."""
    B = B_of_signs(signs)
    G = np.array([weight_N, 0.0, 0.0, 0.0])
    count = 0
    for i in range(B.shape[1]):
        B_i = np.delete(B, i, axis=1)
        if full_rank(B_i) and acai(B_i, np.delete(K_N, i), G) > 0:
            count += 1
    return count


def analyse_rotors(rotors: Sequence, mass_kg: float, com_m: np.ndarray,
                   efficiency: float = 0.0, gravity_m_s2: float = 9.80665) -> AuthorityReport:
    """`analyse_cases` for a model's lift rotors about its COM (`physics.allocation`)."""
    from reedtool.physics.allocation import allocation_matrix

    B = allocation_matrix(rotors, com_m)
    K_N = np.array([r.max_thrust_N for r in rotors], dtype=float)
    return analyse_cases(B, K_N, mass_kg * gravity_m_s2, [r.name for r in rotors],
                         [r.motor_number for r in rotors], efficiency, mass_kg)
