"""Vehicle parameters: everything the hover simulation knows about one multirotor.

One data object, as in RotorPy, with SI units and the frame in the names. The body frame
has the base link's axes and its origin at the centre of mass, so rotor positions here
are lever arms about the COM and gravity produces no torque.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import Sequence

import numpy as np

STANDARD_GRAVITY_M_S2 = 9.80665


@dataclass(frozen=True)
class VehicleParams:
    mass_kg: float
    inertia_kg_m2: np.ndarray              # (3, 3) about the COM, body (base link) axes
    rotor_position_m: np.ndarray           # (n, 3) rotor origins relative to the COM, body axes
    rotor_axis: np.ndarray                 # (n, 3) unit thrust axes, body axes
    turning_sign: np.ndarray               # (n,) +1 ccw, -1 cw (RotorS convention)
    motor_constant: np.ndarray             # (n,) thrust = k * omega^2 [N/(rad/s)^2]
    moment_constant: np.ndarray            # (n,) yaw drag torque = c_m * thrust [m]
    omega_max_rad_s: np.ndarray            # (n,)
    time_constant_up_s: np.ndarray         # (n,) first-order speed response, spinning up
    time_constant_down_s: np.ndarray       # (n,) ... and spinning down
    rotor_drag_coefficient: np.ndarray     # (n,) [N/((rad/s)(m/s))]
    rolling_moment_coefficient: np.ndarray  # (n,) [N*m/((rad/s)(m/s))]
    rotor_names: tuple[str, ...] = field(default=())
    g_m_s2: float = STANDARD_GRAVITY_M_S2

    def __post_init__(self) -> None:
        position_m = np.asarray(self.rotor_position_m, dtype=float).reshape(-1, 3)
        n = len(position_m)
        as_float = {
            "inertia_kg_m2": np.asarray(self.inertia_kg_m2, dtype=float).reshape(3, 3),
            "rotor_position_m": position_m,
            "rotor_axis": _unit_rows(np.asarray(self.rotor_axis, dtype=float).reshape(n, 3)),
        }
        for name in ("turning_sign", "motor_constant", "moment_constant", "omega_max_rad_s",
                     "time_constant_up_s", "time_constant_down_s", "rotor_drag_coefficient",
                     "rolling_moment_coefficient"):
            as_float[name] = np.broadcast_to(
                np.asarray(getattr(self, name), dtype=float), (n,)).copy()
        for name, value in as_float.items():
            value.setflags(write=False)
            object.__setattr__(self, name, value)
        object.__setattr__(self, "mass_kg", float(self.mass_kg))
        if not self.rotor_names:
            object.__setattr__(self, "rotor_names", tuple(f"rotor_{i}" for i in range(n)))

    @property
    def n_rotors(self) -> int:
        return len(self.motor_constant)

    @property
    def weight_N(self) -> float:
        return self.mass_kg * self.g_m_s2

    @property
    def thrust_max_N(self) -> np.ndarray:
        return self.motor_constant * self.omega_max_rad_s ** 2

    def allocation(self) -> np.ndarray:
        """(4, n): per-rotor thrust -> [thrust along body z, roll, pitch, yaw torque] about the COM.

        Same convention as reedtool.physics.allocation.allocation_matrix (RotorS yaw reaction
        -turning_sign * c_m * thrust along the rotor axis), from these arrays so that the
        batch engine can build one per perturbed vehicle.
        """
        return allocation_from_arrays(self.rotor_position_m, self.rotor_axis,
                                      self.turning_sign, self.moment_constant)

    def with_changes(self, **changes) -> "VehicleParams":
        return replace(self, **changes)

    @classmethod
    def from_rotors(cls, mass_kg: float, com_m: np.ndarray, inertia_kg_m2: np.ndarray,
                    rotors: Sequence, g_m_s2: float = STANDARD_GRAVITY_M_S2) -> "VehicleParams":
        """From whole-robot mass properties (COM and inertia in base axes) and Rotors."""
        com_m = np.asarray(com_m, dtype=float)
        return cls(
            mass_kg=mass_kg,
            inertia_kg_m2=inertia_kg_m2,
            rotor_position_m=[np.asarray(r.position_m, dtype=float) - com_m for r in rotors],
            rotor_axis=[r.axis for r in rotors],
            turning_sign=[r.turning_sign for r in rotors],
            motor_constant=[r.motor_constant for r in rotors],
            moment_constant=[r.moment_constant for r in rotors],
            omega_max_rad_s=[r.max_rot_velocity_rad_s for r in rotors],
            time_constant_up_s=[r.time_constant_up_s for r in rotors],
            time_constant_down_s=[r.time_constant_down_s for r in rotors],
            rotor_drag_coefficient=[_zero_if_nan(r.rotor_drag_coefficient) for r in rotors],
            rolling_moment_coefficient=[_zero_if_nan(r.rolling_moment_coefficient)
                                        for r in rotors],
            rotor_names=tuple(r.name for r in rotors),
            g_m_s2=g_m_s2,
        )


def allocation_from_arrays(position_m: np.ndarray, axis: np.ndarray, turning_sign: np.ndarray,
                           moment_constant: np.ndarray) -> np.ndarray:
    """(4, n) allocation from rotor arrays (positions relative to the COM)."""
    torque = np.cross(position_m, axis) - (turning_sign * moment_constant)[:, None] * axis
    return np.vstack([axis[:, 2], torque.T])


def symmetric_multirotor(n_rotors: int, *, arm_m: float = 0.2, mass_kg: float = 1.5,
                         inertia_diag_kg_m2: Sequence[float] = (0.03, 0.03, 0.06),
                         motor_constant: float = 8.54858e-06, moment_constant: float = 0.016,
                         omega_max_rad_s: float = 838.0, time_constant_up_s: float = 0.0125,
                         time_constant_down_s: float = 0.025,
                         rotor_drag_coefficient: float = 8.06428e-05,
                         rolling_moment_coefficient: float = 1e-06,
                         height_m: float = 0.0) -> VehicleParams:
    """A flat 'x' frame: n rotors evenly on a circle, alternating ccw/cw, COM at the centre.

    Used by tests and benchmarks as a vehicle whose trim is known in closed form:
    every rotor carries m*g/n.
    """
    angles = (np.arange(n_rotors) + 0.5) * 2.0 * math.pi / n_rotors
    positions = np.column_stack([arm_m * np.cos(angles), arm_m * np.sin(angles),
                                 np.full(n_rotors, height_m)])
    return VehicleParams(
        mass_kg=mass_kg,
        inertia_kg_m2=np.diag(inertia_diag_kg_m2),
        rotor_position_m=positions,
        rotor_axis=np.tile([0.0, 0.0, 1.0], (n_rotors, 1)),
        turning_sign=[1 if i % 2 == 0 else -1 for i in range(n_rotors)],
        motor_constant=motor_constant,
        moment_constant=moment_constant,
        omega_max_rad_s=omega_max_rad_s,
        time_constant_up_s=time_constant_up_s,
        time_constant_down_s=time_constant_down_s,
        rotor_drag_coefficient=rotor_drag_coefficient,
        rolling_moment_coefficient=rolling_moment_coefficient,
    )


def _unit_rows(v: np.ndarray) -> np.ndarray:
    norm = np.linalg.norm(v, axis=1, keepdims=True)
    with np.errstate(invalid="ignore", divide="ignore"):
        return v / norm


def _zero_if_nan(value: float) -> float:
    # A motor plugin without drag coefficients simply has no rotor drag.
    return 0.0 if value is None or not math.isfinite(value) else float(value)


def check_rotor_dynamics(rotors: Sequence) -> None:
    """Raise ReedtoolError when a rotor lacks what the simulation needs beyond the trim.

    The trim needs positions, axes and constants (and reports their absence itself); the
    speed response needs both time constants. Drag coefficients may be absent (no drag),
    but not present and unreadable.
    """
    from reedtool.errors import ReedtoolError

    for rotor in rotors:
        for attr, tag in (("time_constant_up_s", "timeConstantUp"),
                          ("time_constant_down_s", "timeConstantDown")):
            value = getattr(rotor, attr)
            if not (value is not None and math.isfinite(value) and value > 0.0):
                loc = rotor.plugin.param_loc(tag) if rotor.plugin is not None else rotor.loc
                raise ReedtoolError(
                    f"rotor {rotor.name}: <{tag}> must be a positive time in seconds, "
                    f"got {value}", file=loc.file, line=loc.line,
                    hint=f"set <{tag}> in the motor plugin (RotorS models use 0.0125 up, "
                         f"0.025 down)")
        for attr, tag in (("rotor_drag_coefficient", "rotorDragCoefficient"),
                          ("rolling_moment_coefficient", "rollingMomentCoefficient")):
            # Absent means no drag; written but unreadable or negative is a mistake that
            # would otherwise fly as "no drag" and pass.
            if rotor.plugin is None or rotor.plugin.param(tag) is None:
                continue
            value = getattr(rotor, attr)
            if not (math.isfinite(value) and value >= 0.0):
                loc = rotor.plugin.param_loc(tag)
                raise ReedtoolError(
                    f"rotor {rotor.name}: <{tag}> must be a number >= 0, got "
                    f"'{rotor.plugin.param(tag)}'", file=loc.file, line=loc.line,
                    hint=f"fix <{tag}> in the motor plugin, or remove it for no drag")
