"""Static hover trim: the rotor speeds that hold the robot still, or why none exist.

Hover needs the rotors to produce the wrench [m*g, 0, 0, 0] (collective thrust along
body z, no roll, pitch or yaw torque about the centre of mass) with every thrust inside
[0, k*omega_max^2]. The thrusts are the minimum-norm least-squares solution of
allocation @ thrust = wrench (the pseudo-inverse the controller allocates with). When that
solution leaves the box but the allocation has a null space (six or more rotors), another
split may still fit; it is searched for before the trim is declared infeasible.

A trim with a rotor at exactly 0 or at its maximum is treated as infeasible: that rotor
has no authority left in one direction, so the vehicle cannot be controlled about hover.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass
from typing import Sequence

import numpy as np

from reedtool.io.json_values import finite_or_none

STANDARD_GRAVITY_M_S2 = 9.80665

# A rotor closer than this fraction of its maximum thrust to 0 or to the maximum counts
# as on the bound. Round-off scale, not a design margin: it only separates "exactly at
# zero" (e.g. one rotor's direction flipped on a quad) from a real interior trim.
BOUND_MARGIN = 1e-6
# Residual wrench below this fraction of the weight counts as balanced.
RESIDUAL_TOL = 1e-9
DIRECTION_HINT = ("; check the rotors' turning directions (ccw and cw must balance) and "
                  "moment constants")


class TrimCause(enum.Enum):
    """Why no hover trim exists."""

    NO_ROTORS = "no-rotors"
    INVALID_PARAMETERS = "invalid-parameters"
    INSUFFICIENT_THRUST = "insufficient-thrust"
    COM_UNBALANCED = "com-unbalanced"
    YAW_UNBALANCED = "yaw-unbalanced"
    RANK_DEFICIENT = "rank-deficient"


@dataclass
class TrimResult:
    feasible: bool
    cause: TrimCause | None
    message: str
    thrust_N: np.ndarray            # (n,) trim thrusts; when infeasible, the demand clipped
                                    # to what each rotor can give: k*omega_rad_s^2 always
    omega_rad_s: np.ndarray         # (n,) speeds of those thrusts
    throttle: np.ndarray            # (n,) omega / omega_max
    thrust_to_weight: float         # maximum upward thrust / weight
    hover_throttle_max: float       # max(throttle)
    residual_wrench: np.ndarray     # (4,) allocation @ clipped thrusts - [m*g, 0, 0, 0]
    torque_authority_N_m: np.ndarray  # (3,) roll, pitch, yaw torque still available at hover
    allocation: np.ndarray          # (4, n)
    rank: int
    condition_number: float
    weight_N: float = float("nan")
    rotor_names: tuple[str, ...] = ()
    # (n,) the unbounded least-squares thrusts the allocation asks for (may be < 0 or
    # above the maximum when infeasible; equal to thrust_N when feasible).
    demand_N: np.ndarray | None = None
    # (n,) per rotor "max" or "min" when the demand is beyond that limit (by more than
    # round-off, BOUND_MARGIN of its range) and the rotor is shown saturated there, else
    # None: the table says which rotors cannot comply.
    limit: tuple[str | None, ...] = ()

    def limits(self) -> list[str | None]:
        return list(self.limit) or [None] * len(self.thrust_N)

    def to_dict(self) -> dict:
        return {
            "feasible": self.feasible,
            "cause": self.cause.value if self.cause else None,
            "message": self.message,
            "weight_N": self.weight_N,
            "thrust_to_weight": self.thrust_to_weight,
            "hover_throttle_max": self.hover_throttle_max,
            "rotors": [
                {"name": name, "thrust_N": float(t), "omega_rad_s": float(w),
                 "throttle": float(u), "demand_N": float(d), "limit": limit}
                for name, t, w, u, d, limit in zip(
                    self.rotor_names, self.thrust_N, self.omega_rad_s, self.throttle,
                    self.thrust_N if self.demand_N is None else self.demand_N,
                    self.limits())],
            "residual_wrench": [float(v) for v in self.residual_wrench],
            "torque_authority_N_m": dict(zip(("roll", "pitch", "yaw"),
                                             (float(v) for v in self.torque_authority_N_m))),
            "allocation_rank": self.rank,
            "allocation_condition_number": finite_or_none(self.condition_number),
        }


def solve_trim(mass_kg: float, com_m: np.ndarray, rotors: Sequence,
               g_m_s2: float = STANDARD_GRAVITY_M_S2) -> TrimResult:
    """Hover trim of a robot of `mass_kg` with its COM at `com_m` (base frame) on `rotors`."""
    from reedtool.physics.allocation import allocation_matrix

    names = tuple(r.name for r in rotors)
    k = np.array([r.motor_constant for r in rotors], dtype=float)
    omega_max = np.array([r.max_rot_velocity_rad_s for r in rotors], dtype=float)
    bad = _invalid_rotor(rotors)
    if bad:
        return _empty(TrimCause.INVALID_PARAMETERS, bad, len(rotors), mass_kg * g_m_s2, names)
    A = allocation_matrix(rotors, np.asarray(com_m, dtype=float)) if rotors else np.zeros((4, 0))
    return trim_from_allocation(A, k, omega_max, mass_kg * g_m_s2, names)


def trim_from_allocation(A: np.ndarray, motor_constant: np.ndarray, omega_max_rad_s: np.ndarray,
                         weight_N: float, names: Sequence[str] = ()) -> TrimResult:
    """The trim core, on an allocation matrix (used by solve_trim and the simulator)."""
    A = np.asarray(A, dtype=float)
    n = A.shape[1]
    names = tuple(names) or tuple(f"rotor_{i}" for i in range(n))
    if n == 0:
        return _empty(TrimCause.NO_ROTORS, "the model has no rotors (no motor plugin drives a rotor joint)",
                      0, weight_N, names)
    k = np.asarray(motor_constant, dtype=float)
    omega_max = np.asarray(omega_max_rad_s, dtype=float)
    if not (np.all(np.isfinite(A)) and weight_N > 0):
        return _empty(TrimCause.INVALID_PARAMETERS,
                      "rotor geometry or mass is not a finite number", n, weight_N, names)
    thrust_max = k * omega_max ** 2
    wrench = np.array([weight_N, 0.0, 0.0, 0.0])
    rank = int(np.linalg.matrix_rank(A))
    cond = float(np.linalg.cond(A)) if rank == 4 else float("inf")
    # Only rotors pointing up can lift; a rotor pointing down cannot reverse.
    thrust_to_weight = float(np.clip(A[0], 0.0, None) @ thrust_max / weight_N)
    A_pinv = np.linalg.pinv(A)
    demand = A_pinv @ wrench

    def result(feasible: bool, cause: TrimCause | None, message: str,
               thrust: np.ndarray) -> TrimResult:
        # Infeasible: each rotor shown at what it can give (saturated at 0 or k*w_max^2),
        # the demand beside it; never a thrust the speed beside it cannot make.
        clipped = np.clip(thrust, 0.0, thrust_max) + 0.0    # + 0.0: no "-0.0000 N"
        omega = np.sqrt(clipped / k)
        throttle = omega / omega_max
        authority = _authority(A_pinv, clipped, thrust_max) if feasible else np.zeros(3)
        return TrimResult(feasible, cause, message, clipped, omega, throttle, thrust_to_weight,
                          float(throttle.max()), A @ clipped - wrench, authority, A, rank, cond,
                          weight_N, names, demand_N=np.asarray(thrust, dtype=float),
                          limit=_limits(thrust, 0.0, thrust_max))

    if thrust_to_weight < 1.0:
        return result(False, TrimCause.INSUFFICIENT_THRUST,
                      f"the rotors lift at most {thrust_to_weight * weight_N:.4g} N but the "
                      f"robot weighs {weight_N:.4g} N (thrust-to-weight "
                      f"{thrust_to_weight:.3g})", demand)
    if rank < 4:
        yaw_lost = int(np.linalg.matrix_rank(A[:3])) == 3
        cause = TrimCause.YAW_UNBALANCED if yaw_lost else TrimCause.RANK_DEFICIENT
        what = ("yaw torque cannot be set independently of thrust, roll and pitch"
                + DIRECTION_HINT) if yaw_lost else (
                "the rotor layout cannot set roll and pitch torque independently")
        return result(False, cause, f"{what} (allocation rank {rank} < 4)", demand)

    lo, hi = BOUND_MARGIN * thrust_max, (1.0 - BOUND_MARGIN) * thrust_max
    thrust = demand if _inside(demand, lo, hi) else _redistribute(A, wrench, thrust_max, demand)
    if thrust is not None:
        omega = np.sqrt(thrust / k)
        u = omega / omega_max
        return result(True, None,
                      f"hover at {_span(omega, '.1f')} rad/s "
                      f"({_span(100 * u, '.0f')}% of max speed), "
                      f"thrust-to-weight {thrust_to_weight:.2f}", thrust)

    # Infeasible with enough thrust: is it the weight (roll/pitch) or the yaw that cannot
    # be balanced? Drop the yaw row and try again.
    if _feasible_point(A[:3], wrench[:3], lo, hi, np.linalg.pinv(A[:3]) @ wrench[:3]) is None:
        worst = int(np.argmax(np.maximum(lo - demand, demand - hi) / thrust_max))
        return result(False, TrimCause.COM_UNBALANCED,
                      f"the rotors cannot balance the weight about the centre of mass: "
                      f"{names[worst]} would need {demand[worst]:.4g} N "
                      f"(allowed 0-{thrust_max[worst]:.4g} N); the COM is outside what the "
                      f"rotor layout can hold level", demand)
    return result(False, TrimCause.YAW_UNBALANCED,
                  "the rotors' yaw drag torques cannot cancel while holding the weight"
                  + DIRECTION_HINT, demand)


def solve_trim_6dof(mass_kg: float, com_m: np.ndarray, rotors: Sequence,
                    g_m_s2: float = STANDARD_GRAVITY_M_S2) -> TrimResult:
    """Hover trim of an omnidirectional frame: the full force-and-torque allocation.

    The wrench to produce is [0, 0, m*g, 0, 0, 0] (no side force either: the rotors point
    in many directions); a reversible rotor's thrust may be negative, down to -k*omega_max^2.
    Thrust-to-weight is the upward force with every rotor pushing its most upward way
    (an upper bound: it ignores the torques that leaves).
    """
    from reedtool.physics.allocation import wrench_matrix

    names = tuple(r.name for r in rotors)
    weight_N = mass_kg * g_m_s2
    bad = _invalid_rotor(rotors)
    if bad or not rotors:
        cause = TrimCause.INVALID_PARAMETERS if bad else TrimCause.NO_ROTORS
        return _empty(cause, bad or "the model has no rotors", len(rotors), weight_N, names)
    A = wrench_matrix(rotors, np.asarray(com_m, dtype=float))
    k = np.array([r.motor_constant for r in rotors], dtype=float)
    omega_max = np.array([r.max_rot_velocity_rad_s for r in rotors], dtype=float)
    if not (np.all(np.isfinite(A)) and weight_N > 0):
        return _empty(TrimCause.INVALID_PARAMETERS,
                      "rotor geometry or mass is not a finite number", len(rotors), weight_N,
                      names)
    thrust_max = k * omega_max ** 2
    reversible = np.array([bool(getattr(r, "reversible", False)) for r in rotors])
    thrust_min = np.where(reversible, -thrust_max, 0.0)
    wrench = np.array([0.0, 0.0, weight_N, 0.0, 0.0, 0.0])
    rank = int(np.linalg.matrix_rank(A))
    cond = float(np.linalg.cond(A)) if rank == 6 else float("inf")
    thrust_to_weight = float(np.sum(np.maximum(A[2] * thrust_max, A[2] * thrust_min))
                             / weight_N)
    demand = np.linalg.pinv(A) @ wrench
    span = thrust_max - thrust_min
    lo, hi = thrust_min + BOUND_MARGIN * span, thrust_max - BOUND_MARGIN * span
    thrust = None
    if thrust_to_weight >= 1.0:
        thrust = demand if _inside(demand, lo, hi) else None
        for margin in (0.1, 0.02, BOUND_MARGIN):
            if thrust is not None:
                break
            thrust = _feasible_point(A, wrench, thrust_min + margin * span,
                                     thrust_max - margin * span, demand)
    shown = thrust if thrust is not None else demand
    clipped = np.clip(shown, thrust_min, thrust_max) + 0.0      # + 0.0: no "-0.0000 N"
    omega = np.sign(clipped) * np.sqrt(np.abs(clipped) / k)
    throttle = np.abs(omega) / omega_max
    if thrust is not None:
        message = (f"hover at |omega| {np.abs(omega).min():.1f}-{np.abs(omega).max():.1f} rad/s "
                   f"(6-DoF allocation), thrust-to-weight {thrust_to_weight:.2f}")
        cause = None
    elif thrust_to_weight < 1.0:
        cause = TrimCause.INSUFFICIENT_THRUST
        message = (f"the rotors lift at most {thrust_to_weight * weight_N:.4g} N but the robot "
                   f"weighs {weight_N:.4g} N")
    else:
        cause = TrimCause.RANK_DEFICIENT if rank < 6 else TrimCause.COM_UNBALANCED
        message = (f"no thrusts within the rotors' limits give force m*g up and no torque "
                   f"(6-DoF allocation rank {rank})")
    return TrimResult(thrust is not None, cause, message, clipped, omega, throttle,
                      thrust_to_weight, float(throttle.max()), A @ clipped - wrench,
                      # roll/pitch/yaw authority is the 4-row trim's; not computed here
                      np.full(3, np.nan), A, rank, cond, weight_N, names, demand_N=shown,
                      limit=_limits(shown, thrust_min, thrust_max))


# ------------------------------------------------------------------- helpers

def _limits(demand: np.ndarray, lo, hi: np.ndarray) -> tuple[str | None, ...]:
    """Which limit each rotor's demand passes by more than round-off (see TrimResult.limit)."""
    lo = np.broadcast_to(np.asarray(lo, dtype=float), np.shape(hi))
    tol = BOUND_MARGIN * (hi - lo)
    return tuple("max" if d > h + t else "min" if d < l - t else None
                 for d, l, h, t in zip(demand, lo, hi, tol))


def _inside(thrust: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> bool:
    return bool(np.all(thrust >= lo) and np.all(thrust <= hi))


def _redistribute(A: np.ndarray, wrench: np.ndarray, thrust_max: np.ndarray,
                  demand: np.ndarray) -> np.ndarray | None:
    """A split inside the limits, with as much margin as a few tries find, or None.

    Alternating projections land on the boundary of the box they are given, so the box
    is shrunk first (10%, then 2% of each rotor's range) to get a trim that keeps some
    authority on every rotor, and only then taken at the round-off margin.
    """
    for margin in (0.1, 0.02, BOUND_MARGIN):
        found = _feasible_point(A, wrench, margin * thrust_max, (1.0 - margin) * thrust_max,
                                demand)
        if found is not None:
            return found
    return None


def _feasible_point(A: np.ndarray, wrench: np.ndarray, lo: np.ndarray, hi: np.ndarray,
                    start: np.ndarray, iterations: int = 20000) -> np.ndarray | None:
    """A thrust vector with A @ T = wrench and lo <= T <= hi, or None.

    Alternating projections between the affine solution set and the box (von Neumann):
    they converge to a point of the intersection when it is not empty and stall at a
    positive gap when it is. Small (n <= ~12) and only run when the minimum-norm
    solution is outside the box, so plain iteration is fast enough and needs no LP solver.
    """
    A_pinv = np.linalg.pinv(A)
    projector = np.eye(A.shape[1]) - A_pinv @ A
    offset = A_pinv @ wrench
    tol = RESIDUAL_TOL * max(abs(wrench[0]), 1.0)
    still = 1e-14 * max(1.0, float(hi.max()))
    thrust = start.copy()
    for _ in range(iterations):
        boxed = np.clip(thrust, lo, hi)
        if np.abs(A @ boxed - wrench).max() <= tol:
            return boxed
        previous, thrust = thrust, projector @ boxed + offset
        if np.abs(thrust - previous).max() < still:
            break  # the sets do not meet: the projections settled at a positive gap
    return None


def _authority(A_pinv: np.ndarray, thrust: np.ndarray, thrust_max: np.ndarray) -> np.ndarray:
    """Largest roll, pitch, yaw torque reachable in both signs from hover, each axis alone.

    Moves along the pseudo-inverse direction for a pure torque on one axis (the way the
    controller allocates) until a rotor reaches 0 or its maximum.
    """
    out = np.zeros(3)
    for axis in range(3):
        d = A_pinv[:, axis + 1]
        reach = []
        for sign in (1.0, -1.0):
            step = sign * d
            with np.errstate(divide="ignore"):
                up = np.where(step > 0, (thrust_max - thrust) / step, np.inf)
                down = np.where(step < 0, -thrust / step, np.inf)
            reach.append(min(up.min(), down.min()))
        out[axis] = min(reach)
    return out


def _invalid_rotor(rotors: Sequence) -> str | None:
    for r in rotors:
        values = {"position": np.asarray(r.position_m, dtype=float),
                  "axis": np.asarray(r.axis, dtype=float)}
        for name, v in values.items():
            if not np.all(np.isfinite(v)):
                return f"rotor {r.name}: {name} unknown (its link is not in the model tree)"
        for attr, label in (("motor_constant", "motorConstant"),
                            ("max_rot_velocity_rad_s", "maxRotVelocity")):
            value = getattr(r, attr)
            if not (np.isfinite(value) and value > 0):
                return f"rotor {r.name}: {label} must be a positive number, got {value}"
        if not np.isfinite(r.moment_constant):
            return f"rotor {r.name}: momentConstant is not a number"
    return None


def _empty(cause: TrimCause, message: str, n: int, weight_N: float,
           names: tuple[str, ...]) -> TrimResult:
    nan = np.full(n, np.nan)
    return TrimResult(False, cause, message, nan, nan.copy(), nan.copy(), 0.0, float("nan"),
                      np.full(4, np.nan), np.zeros(3), np.zeros((4, n)), 0, float("inf"),
                      weight_N, names)


def _span(values, spec: str) -> str:
    """'low-high' as printed, or one number where both print alike (a symmetric frame)."""
    low, high = format(float(values.min()), spec), format(float(values.max()), spec)
    return low if low == high else f"{low}-{high}"
