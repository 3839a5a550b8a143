"""What hover-test concludes about the vehicle, with the cause named.

One flight from the start disturbance is a test of the controller as much as of the
vehicle; the verdict separates what the vehicle cannot do from what a start asked of it:

- `cannot-hover`: no trim holds the weight (physics.trim).
- `cannot-stabilise`: the trim exists but the rotors cannot push the wrench both ways
  about it: the available control authority index is <= 0 (physics.authority), so no
  controller within the rotors' limits can stabilise it.
- `marginal`: it hovers, but recovers only from disturbances smaller than the start:
  the largest recoverable tilt and offset are found by bisection on the start (all of
  roll, pitch, yaw and offset scaled together), a bounded number of short flights.
- `flies`: it settles from the start disturbance without sustained saturation.
- `not-flown`: the frame is one the geometric controller cannot fly (omnidirectional).

"Recovers" means: the flight passes (settles within the tolerances and holds) and the
rotors were never out of range for `config.saturation_limit_s` in a row: a recovery that
rides the rotors' limits for a second is luck of the start, not margin. Only the first
two fail whatever is asked; `Requirement` decides what else a run demands, and its
default, `flies`, demands the verdict `flies`. `final_line` is the one place that words
the conclusion: PASSED only after the verdict `flies`; a weaker verdict that an explicit
`--require` accepts is ACCEPTED, never PASSED (a "MARGINAL" then "PASSED" is a green
check that is false).
"""

from __future__ import annotations

import dataclasses
import enum
import math
from dataclasses import dataclass

from reedtool.sim import HoverConfig
from reedtool.sim.params import VehicleParams

# Bisection on the start's scale: BISECTION_FLIGHTS flights give it to 1 / 2^that.
BISECTION_FLIGHTS = 6


class Verdict(enum.Enum):
    CANNOT_HOVER = "cannot-hover"
    CANNOT_STABILISE = "cannot-stabilise"
    MARGINAL = "marginal"
    FLIES = "flies"
    NOT_FLOWN = "not-flown"

    @property
    def is_failure(self) -> bool:
        """A failure whatever --require says (the first two)."""
        return self in (Verdict.CANNOT_HOVER, Verdict.CANNOT_STABILISE)


@dataclass(frozen=True)
class Requirement:
    """`--require`: flies (default: the verdict is `flies`), hover (a trim exists), stable
    (and it can be stabilised), or margin:DEG (and it recovers from a start tilted by DEG
    degrees)."""

    level: str = "flies"
    margin_deg: float = 0.0

    @classmethod
    def parse(cls, text: str) -> "Requirement":
        text = text.strip().lower()
        if text in ("flies", "hover", "stable"):
            return cls(text)
        head, sep, value = text.partition(":")
        if head == "margin" and sep:
            try:
                deg = float(value)
            except ValueError:
                deg = math.nan
            if math.isfinite(deg) and 0.0 < deg < 90.0:
                return cls("margin", deg)
        raise ValueError(f"--require '{text}': expected flies, hover, stable or margin:DEG "
                         "with 0 < DEG < 90")

    def __str__(self) -> str:
        return f"margin:{self.margin_deg:g}" if self.level == "margin" else self.level


@dataclass
class HoverVerdict:
    verdict: Verdict
    message: str
    recoverable_tilt_deg: float | None = None    # largest start tilt recovered from
    recoverable_offset_m: float | None = None    # ... and its offset (same scale)
    start_tilt_deg: float | None = None
    start_offset_m: float | None = None
    flights: int = 0                             # flights flown to find the margin

    def passes(self, requirement: Requirement) -> bool:
        if self.verdict is Verdict.CANNOT_HOVER:
            return False
        if self.verdict is Verdict.CANNOT_STABILISE:
            return requirement.level == "hover"
        if requirement.level == "flies":
            return self.verdict is Verdict.FLIES
        if requirement.level != "margin" or self.verdict is Verdict.NOT_FLOWN:
            return True
        return (self.recoverable_tilt_deg or 0.0) >= requirement.margin_deg - 1e-9

    def to_dict(self) -> dict:
        return {"status": self.verdict.value, "message": self.message,
                "recoverable_tilt_deg": self.recoverable_tilt_deg,
                "recoverable_offset_m": self.recoverable_offset_m,
                "start_tilt_deg": self.start_tilt_deg, "start_offset_m": self.start_offset_m,
                "flights": self.flights}


def outcome(status: str, passed: bool) -> str:
    """"passed" (exit 0 after the verdict `flies`), "accepted" (exit 0 because an explicit
    --require accepts a weaker verdict: not a pass of the flight) or "failed" (exit 1)."""
    if not passed:
        return "failed"
    return "passed" if status == Verdict.FLIES.value else "accepted"


def final_line(status: str, passed: bool, requirement: str, message: str) -> str:
    """hover-test's last line: PASSED only when the verdict is `flies`.

    `status` is the verdict's value, `passed` the verdict (and batch) against
    `requirement` (its text), `message` why it failed."""
    kind = outcome(status, passed)
    if kind == "passed":
        return "PASSED"
    if kind == "accepted":
        return (f"ACCEPTED by --require {requirement}: the verdict is {status.upper()}, "
                "not FLIES (exit 0, not a pass of the flight)")
    if status in (Verdict.MARGINAL.value, Verdict.NOT_FLOWN.value) and requirement == "flies":
        return (f"FAILED: the verdict is {status.upper()}, not FLIES (above); --require "
                "stable accepts a vehicle that hovers and can be stabilised")
    return f"FAILED: {message}"


def tilt_deg(config: HoverConfig) -> float:
    """The start's tilt from level: the angle between body z and world z."""
    return math.degrees(math.acos(max(-1.0, min(1.0, math.cos(config.roll_rad)
                                                 * math.cos(config.pitch_rad)))))


def scaled_start(config: HoverConfig, scale: float) -> HoverConfig:
    return dataclasses.replace(config, offset_m=tuple(scale * v for v in config.offset_m),
                               roll_rad=scale * config.roll_rad,
                               pitch_rad=scale * config.pitch_rad,
                               yaw_rad=scale * config.yaw_rad)


def recovered(run, config: HoverConfig) -> bool:
    return run.passed and run.longest_saturation_s < config.saturation_limit_s - 1e-9


# A position PID with a triple pole at w_p, started at rest from an offset, is within 10 %
# of it (the 5 cm of a 0.5 m start) after w_p t = 5.3: (1 + x + x^2 / 2) e^-x = 0.1.
SETTLE_BANDWIDTHS = 5.3
SETTLE_MARGIN = 1.5          # for the attitude loop's lag and the saturated start
MAX_AUTO_DURATION_S = 60.0


def with_time_to_settle(config: HoverConfig, gains) -> HoverConfig:
    """`config` with a duration long enough for the tuned position loop to settle and
    hold: SETTLE_MARGIN * SETTLE_BANDWIDTHS / w_p + the hold time, rounded up to whole
    seconds, never shorter than asked nor longer than MAX_AUTO_DURATION_S."""
    need = SETTLE_MARGIN * SETTLE_BANDWIDTHS / gains.position_bandwidth_rad_s + config.hold_s
    need = min(float(math.ceil(need)), MAX_AUTO_DURATION_S)
    if need <= config.duration_s:
        return config
    return dataclasses.replace(config, duration_s=need)


def batch_start_scale(found: HoverVerdict) -> float:
    """The start the robustness batch flies, as a fraction of the test's: all of it when
    the nominal vehicle flies it, its recoverable margin when marginal."""
    if found.verdict is not Verdict.MARGINAL:
        return 1.0
    if found.start_tilt_deg:
        return (found.recoverable_tilt_deg or 0.0) / found.start_tilt_deg
    if found.start_offset_m:
        return (found.recoverable_offset_m or 0.0) / found.start_offset_m
    return 1.0


def stabilisable(params: VehicleParams) -> tuple[bool, float]:
    """(ACAI > 0 with full rank, ACAI) of the vehicle about hover (physics.authority)."""
    from reedtool.physics.authority import authority

    result = authority(params.allocation(), params.thrust_max_N, params.weight_N)
    return result.controllable, float(result.acai)


def uncontrollable(acai: float) -> HoverVerdict:
    return HoverVerdict(
        Verdict.CANNOT_STABILISE,
        f"no controller within its rotors' limits can stabilise it: the available "
        f"control authority index about hover is {acai:.3g} (<= 0; `reedtool authority` "
        "explains it)")


def judge_flight(params: VehicleParams, config: HoverConfig, run, fly,
                 requirement: Requirement = Requirement()) -> HoverVerdict:
    """The verdict on a vehicle that flew `run` from `config`'s start.

    `fly(config)` flies the same vehicle (same gains) from another start and returns its
    HoverRun; it is called at most BISECTION_FLIGHTS (+1 for --require margin) times.
    """
    tilt0, offset0 = tilt_deg(config), config.offset_norm_m
    flights = 0
    if recovered(run, config):
        verdict = HoverVerdict(Verdict.FLIES, run.message, tilt0, offset0,
                               tilt0, offset0)
        if requirement.level == "margin" and requirement.margin_deg > tilt0 + 1e-9:
            # The start did not ask that much: fly the required tilt itself (the start
            # scaled up to it, or rolled by it when the start is level).
            if tilt0 > 0:
                scale = requirement.margin_deg / tilt0
                start = scaled_start(config, scale)
            else:
                scale = 1.0
                start = dataclasses.replace(config, roll_rad=math.radians(requirement.margin_deg))
            flights += 1
            if not recovered(fly(start), config):
                verdict.message += (f"; does not recover from the {requirement.margin_deg:g}"
                                    " deg required")
            else:
                verdict.recoverable_tilt_deg = requirement.margin_deg
                verdict.recoverable_offset_m = scale * offset0
        verdict.flights = flights
        return verdict
    lo, hi = 0.0, 1.0            # recovers at lo (trivially: the trim), not at hi
    for _ in range(BISECTION_FLIGHTS):
        mid = 0.5 * (lo + hi)
        flights += 1
        if recovered(fly(scaled_start(config, mid)), config):
            lo = mid
        else:
            hi = mid
    why = (f"from the {tilt0:.3g} deg / {offset0:.3g} m start: {run.status.value}: "
           f"{run.message}")
    if run.passed:
        why = (f"from the {tilt0:.3g} deg / {offset0:.3g} m start it settled only by riding "
               f"the rotors' limits for {run.longest_saturation_s:.2f} s in a row")
    if lo == 0.0:
        message = (f"hovers in trim, but recovers from none of the starts tried "
                   f"down to 1/{2 ** BISECTION_FLIGHTS} of the start ({why})")
    else:
        message = (f"recovers from up to {lo * tilt0:.3g} deg of tilt and "
                   f"{lo * offset0:.3g} m of offset, not more ({why})")
    return HoverVerdict(Verdict.MARGINAL, message, lo * tilt0, lo * offset0, tilt0, offset0,
                        flights)


def omnidirectional(trim_message: str) -> HoverVerdict:
    return HoverVerdict(
        Verdict.NOT_FLOWN,
        f"omnidirectional frame ({trim_message}); hover-test's geometric "
        "controller commands thrust along body z and three torques from rotors that push "
        "one way, which does not apply to reversible or many-direction rotors. The 6-DoF "
        "trim above is what was checked (`reedtool validate` checks its allocation)")


# Trim failures a tilt-rotor's servos resolve (thrust-to-weight is not one of them);
# "no-rotors" here is a frame whose only rotors point sideways at zero tilt (skycat).
TILT_CAUSES = ("rank-deficient", "yaw-unbalanced", "com-unbalanced", "no-rotors")


def tilt_rotor(trim_message: str, tilting: list[tuple[str, str]]) -> HoverVerdict:
    pairs = ", ".join(f"{rotor} on {joint}" for rotor, joint in tilting)
    return HoverVerdict(
        Verdict.NOT_FLOWN,
        f"tilt-rotor frame ({pairs}: a plugin drives the joint the rotor tilts on, a "
        f"servo or swashplate); with the rotors fixed there is no hover trim "
        f"({trim_message}), but its flight controller steers with the tilt, which "
        "hover-test's fixed-axis trim and controller do not model")


def tuning_line(gains: dict) -> str:
    """One line from ControllerGains.to_dict(): the bandwidths used and what limited them."""
    lead = ""
    if gains.get("motor_lead"):
        m = gains["motor_lead"]
        lead = (f"; slow motors' lag {max(m['time_constant_up_s'] + m['time_constant_down_s']):.3g}"
                f" s led to {max(m['led_up_s'] + m['led_down_s']):.3g} s")
    return (f"attitude {gains['attitude_bandwidth_rad_s']:.3g} rad/s, position "
            f"{gains['position_bandwidth_rad_s']:.3g} rad/s (limited by {gains['limited_by']}; "
            f"roll/pitch authority {gains['angular_authority_rad_s2']:.3g} rad/s^2, tilt cap "
            f"{gains['max_tilt_deg']:.3g} deg{lead})")
