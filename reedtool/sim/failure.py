"""A rotor failure in flight: hover, lose one rotor at t_fail, fly on with what is left.

The failure schedule lives here, outside the engines: before t_fail the vehicle holds
its trimmed hover at the setpoint (level, at rest, every rotor at its trim speed); at
t_fail the failed rotor's speed is zero from then on, which for the rigid-body plant is
the vehicle without that rotor. The controller is reconfigured as a fault-tolerant one
would be after detection (here: at once): its allocation is recomputed without the
rotor and, when the analysis (reedtool.physics.authority) says yaw is lost but thrust,
roll and pitch are not, the yaw row is dropped and the vehicle is allowed to spin (the
yaw-spin ending is switched off). The flight after t_fail is an ordinary run of the
single-vehicle engine (run.simulate_hover) from the pre-failure state, judged as a hover
test: it must stay within the bounds. Without yaw the heading cannot settle, so such a
flight that ends not settled is judged on position and tilt alone over the last hold
time: within SPIN_POSITION_TOL_M and upright -> ExitStatus.SPINNING_HOLD.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from reedtool.sim import ExitStatus, HoverConfig
from reedtool.sim.layout import hover_speeds
from reedtool.sim.controller import ControllerDesign, ControllerGains
from reedtool.sim.params import VehicleParams
from reedtool.sim.run import HoverRun, simulate_hover

PER_ROTOR = ("rotor_position_m", "rotor_axis", "turning_sign", "motor_constant",
             "moment_constant", "omega_max_rad_s", "time_constant_up_s",
             "time_constant_down_s", "rotor_drag_coefficient", "rolling_moment_coefficient")


# Largest tilt [deg] of a vehicle spinning without yaw control that still counts as held
# upright: a spinning multirotor cones about the vertical (the generated hex-x missing a
# rotor cones at about 25 deg); beyond 30 deg it is no longer a hover.
SPIN_TILT_TOL_DEG = 30.0
# Largest position error [m] of such a vehicle over the last hold time. Without yaw the
# rotor thrusts precess with the spin, so the vehicle circles its setpoint instead of
# settling on it; a vehicle that stays within half a metre and upright after losing a rotor
# has survived it (the intact hover keeps the 5 cm band).
SPIN_POSITION_TOL_M = 0.5


@dataclass(frozen=True)
class FailureSchedule:
    rotor_index: int          # 0-based, in VehicleParams order
    time_s: float             # when the rotor stops [s], from the start of the run


@dataclass
class FailureRun:
    schedule: FailureSchedule
    rotor_name: str
    yaw_controlled: bool      # False: the controller dropped yaw and let the vehicle spin
    after: HoverRun           # the flight from t_fail on (its times start at 0)

    status: ExitStatus = ExitStatus.NOT_SETTLED   # the verdict (spinning-hold included)
    message: str = ""

    @property
    def passed(self) -> bool:
        return self.status in (ExitStatus.PASSED, ExitStatus.SPINNING_HOLD)

    def series(self) -> dict[str, np.ndarray]:
        """The time series on the run's clock (failure at schedule.time_s), failed rotor at 0."""
        out = {k: np.asarray(v) for k, v in self.after.series.items()}
        if "t_s" in out:
            out["t_s"] = out["t_s"] + self.schedule.time_s
        return out

    def to_dict(self) -> dict:
        return {**self.after.to_dict(), "status": self.status.value, "passed": self.passed,
                "message": self.message, "failed_rotor": self.rotor_name,
                "rotor_index": self.schedule.rotor_index,
                "failure_time_s": self.schedule.time_s, "yaw_controlled": self.yaw_controlled}


# The loop gains and limits an autopilot keeps through a rotor failure.
TUNING = ("kp_1_s2", "kd_1_s", "ki_1_s3", "kR_1_s2", "kw_1_s", "max_horizontal_accel_m_s2",
          "max_vertical_accel_m_s2", "max_integral_m_s", "attitude_bandwidth_rad_s",
          "position_bandwidth_rad_s", "limited_by", "angular_authority_rad_s2")


def without_rotor(params: VehicleParams, index: int) -> VehicleParams:
    """The vehicle with rotor `index` stopped for good (no thrust, no drag torque)."""
    keep = [i for i in range(params.n_rotors) if i != index]
    changes = {name: np.asarray(getattr(params, name))[keep] for name in PER_ROTOR}
    names = tuple(n for i, n in enumerate(params.rotor_names) if i != index)
    return dataclasses.replace(params, rotor_names=names, **changes)


def reconfigured_gains(params: VehicleParams, design: ControllerDesign,
                       yaw_controlled: bool,
                       tuned: ControllerGains | None = None) -> ControllerGains:
    """Gains for the remaining rotors; without yaw the allocation ignores the yaw demand.

    With `tuned` (the intact vehicle's gains) the loops keep that tuning: an autopilot
    reconfigures its allocation after a failure, it does not retune its loops in flight.
    """
    gains = ControllerGains.from_params(params, design)
    if tuned is not None:
        gains = dataclasses.replace(gains, **{name: getattr(tuned, name) for name in TUNING})
    if yaw_controlled:
        return gains
    pinv3 = np.linalg.pinv(params.allocation()[:3])
    return dataclasses.replace(gains, allocation_pinv=np.hstack([pinv3, np.zeros((len(pinv3), 1))]))


def after_failure(params: VehicleParams, schedule: FailureSchedule, config: HoverConfig,
                  design: ControllerDesign, yaw_controlled: bool):
    """(vehicle, gains, config, starting rotor speeds) of the flight from t_fail on.

    Any engine can fly it: run.simulate_hover and batch.simulate_batch take the gains and
    starting speeds as overrides (tests/test_failure_flight.py holds them to one verdict).
    """
    intact_gains = ControllerGains.from_params(params, design)
    before_omega = hover_speeds(params, intact_gains)
    keep = [i for i in range(params.n_rotors) if i != schedule.rotor_index]
    after_params = without_rotor(params, schedule.rotor_index)
    gains = reconfigured_gains(after_params, design, yaw_controlled, intact_gains)
    after_config = dataclasses.replace(
        config, duration_s=config.duration_s - schedule.time_s, offset_m=(0.0, 0.0, 0.0),
        roll_rad=0.0, pitch_rad=0.0, yaw_rad=0.0,
        yaw_spin_rad_s=config.yaw_spin_rad_s if yaw_controlled else math.inf)
    return after_params, gains, after_config, before_omega[keep]


def simulate_rotor_failure(params: VehicleParams, schedule: FailureSchedule,
                           config: HoverConfig = HoverConfig(),
                           design: ControllerDesign = ControllerDesign(),
                           yaw_controlled: bool = True, record: bool = True) -> FailureRun:
    """Hover until schedule.time_s, lose the rotor, fly until config.duration_s."""
    if not 0 <= schedule.rotor_index < params.n_rotors:
        raise ValueError(f"rotor index {schedule.rotor_index} out of range 0..{params.n_rotors - 1}")
    if not 0 <= schedule.time_s < config.duration_s - config.hold_s:
        raise ValueError(f"failure time {schedule.time_s} s must leave more than the hold "
                         f"time {config.hold_s} s before the end {config.duration_s} s")
    after_params, gains, after_config, omega0 = after_failure(params, schedule, config, design,
                                                              yaw_controlled)
    after = simulate_hover(after_params, after_config, design,
                           record=record or not yaw_controlled, gains=gains,
                           initial_omega_rad_s=omega0)
    status, message = after.status, after.message
    if not yaw_controlled and status is ExitStatus.NOT_SETTLED:
        held = _spinning_hold(after.series, after_config)
        if held is not None:
            status = ExitStatus.SPINNING_HOLD
            message = (f"held within {100 * held[0]:.1f} cm and {held[1]:.1f} deg of tilt "
                       f"over the last {after_config.hold_s:g} s, spinning at up to "
                       f"{held[2]:.1f} rad/s without yaw control")
    return FailureRun(schedule=schedule, rotor_name=params.rotor_names[schedule.rotor_index],
                      yaw_controlled=yaw_controlled, after=after, status=status,
                      message=f"rotor {params.rotor_names[schedule.rotor_index]} failed at "
                              f"t = {schedule.time_s:g} s; since then: {message}")


def _spinning_hold(series: dict, config: HoverConfig) -> tuple[float, float, float] | None:
    """(max position error, max tilt, max yaw rate) over the last hold time if held, else None."""
    t = np.asarray(series.get("t_s", ()))
    if len(t) < 3:
        return None
    last = t >= t[-1] - config.hold_s
    pos = float(np.max(series["position_error_m"][last]))
    tilt = np.degrees(np.arccos(np.clip(np.cos(series["roll_rad"][last])
                                        * np.cos(series["pitch_rad"][last]), -1.0, 1.0)))
    yaw = np.unwrap(series["yaw_rad"])
    rate = float(np.max(np.abs(np.diff(yaw) / np.diff(t)))) if len(t) > 1 else 0.0
    if pos <= SPIN_POSITION_TOL_M and float(np.max(tilt)) <= SPIN_TILT_TOL_DEG:
        return pos, float(np.max(tilt)), rate
    return None
