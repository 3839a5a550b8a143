"""Headless hover simulation: vehicle parameters, motor model, rigid body, controller.

The vocabulary shared by the single-vehicle run (`run`) and the robustness batch
(`batch`) lives here: how a simulation ends (`ExitStatus`) and what is asked of it
(`HoverConfig`). Nothing here imports matplotlib; `plot` does, lazily.
"""

from __future__ import annotations

import enum
import math
from dataclasses import dataclass


class ExitStatus(enum.Enum):
    """Every way a hover test ends. `value` is the stable name used in JSON."""

    PASSED = "passed"                  # settled within the tolerances and stayed there
    NOT_SETTLED = "not-settled"        # ran to the end without settling (or left the band)
    DIVERGED = "diverged"              # state not finite, or drifting/rotating away without bound
    CRASHED = "crashed"                # hit the ground or flipped over
    SATURATED = "saturated"            # not settled, the demand long beyond the rotors' range
    YAW_SPIN = "yaw-spin"              # spinning about the vertical
    TRIM_INFEASIBLE = "trim-infeasible"  # no hover trim exists, nothing was simulated
    # After a rotor failure without yaw control (sim.failure): held position and stayed
    # upright while spinning about the vertical. Last, so the batch codes above keep theirs.
    SPINNING_HOLD = "spinning-hold"

    @property
    def passed(self) -> bool:
        return self is ExitStatus.PASSED


# Integer codes for the batch engine's status array (0: still running).
STATUS_CODES = {status: i + 1 for i, status in enumerate(ExitStatus)}
STATUS_FROM_CODE = {code: status for status, code in STATUS_CODES.items()}


@dataclass(frozen=True)
class HoverConfig:
    """What a hover test simulates and how it is judged."""

    duration_s: float = 10.0
    rate_hz: float = 1000.0              # integration and control rate (fixed step)
    offset_m: tuple[float, float, float] = (0.5, 0.0, 0.0)  # start minus setpoint, world
    roll_rad: float = 0.2                # initial attitude (URDF rpy convention)
    pitch_rad: float = 0.0
    yaw_rad: float = 0.0
    hover_altitude_m: float = 2.0        # setpoint height above the ground (z = 0)
    position_tol_m: float = 0.05
    attitude_tol_deg: float = 2.0
    hold_s: float = 1.0                  # must stay settled at least this long before the end
    saturation_limit_s: float = 1.0      # not settled and saturated this long: SATURATED
    yaw_spin_rad_s: float = math.pi      # |body yaw rate| above this is a spin
    diverged_rate_rad_s: float = 50.0    # |roll/pitch rate| above this is divergence
    diverged_distance_m: float = 10.0    # position error above this (plus the offset)
    sample_hz: float = 100.0             # checks, settling and time series

    @property
    def dt_s(self) -> float:
        return 1.0 / self.rate_hz

    @property
    def n_steps(self) -> int:
        return int(round(self.duration_s * self.rate_hz))

    @property
    def sample_every(self) -> int:
        return max(1, int(round(self.rate_hz / self.sample_hz)))

    @property
    def offset_norm_m(self) -> float:
        return math.sqrt(sum(v * v for v in self.offset_m))

    @property
    def divergence_distance_m(self) -> float:
        return self.diverged_distance_m + self.offset_norm_m

    @property
    def cos_attitude_tol(self) -> float:
        return math.cos(math.radians(self.attitude_tol_deg))

    def validate(self) -> None:
        """Raise ValueError naming the first setting that makes no sense."""
        if not (self.rate_hz > 0 and math.isfinite(self.rate_hz)):
            raise ValueError(f"rate must be positive, got {self.rate_hz}")
        if not (self.duration_s > 0 and math.isfinite(self.duration_s)):
            raise ValueError(f"duration must be positive, got {self.duration_s}")
        if self.hold_s >= self.duration_s:
            raise ValueError(f"duration {self.duration_s} s must exceed the hold time "
                             f"{self.hold_s} s")
        values = (*self.offset_m, self.roll_rad, self.pitch_rad, self.yaw_rad)
        if not all(math.isfinite(v) for v in values):
            raise ValueError("the disturbance must be finite numbers")


ENGINES = ("auto", "numpy", "numba")


# Up to this many batch vehicles "auto" keeps numpy, when told the batch's size: they fly
# one by one on the float step (batch.FLOAT_ENGINE_MAX_VEHICLES), faster than numba's
# start-up. Whole `hover-test examples/reed_quad_x --samples N` processes, wall, numpy /
# numba, load ~0.5: N=2 0.58-0.67 / 0.91-1.02 s; N=4 0.69-0.89 / 0.86-0.87; N=8
# 1.06-1.18 / 0.99-1.29; N=16 1.54-1.88 / 0.88-0.96.
AUTO_NUMPY_MAX_VEHICLES = 3


def choose_engine(requested: str, batch: bool, vehicles: int | None = None) -> str:
    """The engine that flies a run: `requested` unless "auto".

    `vehicles`, when given, is the batch's size: up to AUTO_NUMPY_MAX_VEHICLES of them,
    auto keeps numpy (they fly one by one on the float step, in less time than numba
    takes to start).

    "auto" is numba for a run with a batch, when numba imports, and numpy otherwise.
    Measured as whole `hover-test` processes (benchmarks/bench_hover.py, docs/hover-test.md,
    "Speed"): one vehicle flies 10 s in ~50 ms on numpy, less than numba's own start-up
    (importing numba and loading its cached kernel, ~0.55 s of CPU), so numpy finishes
    first (1.05 s against 2.10 s wall); a batch in numpy columns pays its per-step array
    overhead ~10,000 times (`--samples 2`: 4.77 s against numba's 1.29 s), and since
    small batches fly one by one instead, numba wins from about 8 vehicles (above).
    """
    if requested != "auto":
        return requested
    if not batch or (vehicles is not None and vehicles <= AUTO_NUMPY_MAX_VEHICLES):
        return "numpy"
    from reedtool.sim.compiled import available

    return "numba" if available() else "numpy"
