"""The frame catalogue: where the rotors (or wheels) of each supported layout sit.

Multirotor frames follow PX4's airframe reference for positions, numbering and spin
directions, so a model generated here can be flown by PX4 SITL through the MAVLink
interface without remapping motors:

- a rotor is placed by its *bearing*: degrees clockwise from the nose, seen from above
  (PX4's mixer angle). In the ROS body frame (FLU, REP 103) that is
  x = r cos(bearing), y = -r sin(bearing).
- `motor_number` is RotorS' 0-based `motorNumber` = PX4 motor index - 1 (PX4 MAIN1 is
  RotorS motor 0). The MAVLink interface forwards actuator i to motor number i.
- `direction` is the RotorS `turningDirection`, seen from above with z up: a "ccw" rotor
  turns counter-clockwise and pushes the body clockwise (yaw reaction -k_m * thrust).

Arm length L: the distance from the centre to each rotor axis, except for quad-x, where
L is the rotor's x and y offset (rotors at (+-L, +-L); the motor sits L*sqrt(2) from the
centre). That is how the seed and RotorS-derived quad-x models write it
(`arm_length_front_x`, `arm_length_front_y`); every other frame follows RotorS' firefly
and hummingbird, whose `arm_length` is the centre-to-rotor distance.

Ground layouts (car-4w, diff-drive) list their wheels instead; they carry no thrust.
"""

from __future__ import annotations

import difflib
import math
from dataclasses import dataclass

import numpy as np

from reedtool.errors import ReedtoolError


@dataclass(frozen=True)
class RotorSlot:
    suffix: str            # RotorS `suffix` (plugin and link naming), e.g. "front_right"
    motor_number: int      # RotorS motorNumber, 0-based; PX4 MAIN(motor_number + 1)
    bearing_deg: float     # clockwise from the nose seen from above (PX4 mixer angle)
    direction: str         # "ccw" | "cw", seen from above (RotorS turningDirection)
    level: int = 1         # +1 at +rotor_offset_top; -1 the lower rotor of a coaxial pair


@dataclass(frozen=True)
class Airframe:
    name: str
    title: str
    rotors: tuple[RotorSlot, ...]
    radial_per_arm_length: float   # centre-to-rotor distance per unit arm length
    reference: str                 # where the numbering convention comes from
    kind: str = "multirotor"

    @property
    def rotor_count(self) -> int:
        return len(self.rotors)

    def unit_xy(self, slot: RotorSlot) -> tuple[float, float]:
        """Rotor (x, y) in FLU for arm length 1, rounded so +-1 stays exactly +-1."""
        bearing_rad = math.radians(slot.bearing_deg)
        r = self.radial_per_arm_length
        x = round(r * math.cos(bearing_rad), 12) + 0.0   # + 0.0 turns -0.0 into 0.0
        y = round(-r * math.sin(bearing_rad), 12) + 0.0
        return x, y

    def rotor_positions_m(self, arm_length_m: float, rotor_offset_top_m: float) -> np.ndarray:
        """(n, 3) rotor hub positions in the base frame (FLU), ordered as `rotors`."""
        rows = []
        for slot in self.rotors:
            x, y = self.unit_xy(slot)
            rows.append([x * arm_length_m, y * arm_length_m, slot.level * rotor_offset_top_m])
        return np.array(rows)

    def turning_signs(self) -> np.ndarray:
        """+1 for ccw, -1 for cw, ordered as `rotors` (the RotorS sign convention)."""
        return np.array([1.0 if s.direction == "ccw" else -1.0 for s in self.rotors])


@dataclass(frozen=True)
class WheelSlot:
    name: str              # link name prefix, e.g. "front_left" -> front_left_wheel
    x_per_wheelbase: float  # x = this * wheelbase (front +0.5, rear -0.5, axle-centred 0)
    side: int              # +1 left (y = +track/2), -1 right


@dataclass(frozen=True)
class GroundLayout:
    name: str
    title: str
    wheels: tuple[WheelSlot, ...]
    drive: str             # "diff_drive" | "skid_steer"
    caster: bool           # a passive rear caster ball (diff-drive)
    kind: str = "ground"

    @property
    def rotor_count(self) -> int:
        return 0


def _ring(names: list[str], bearings: list[float], dirs: list[str]) -> tuple[RotorSlot, ...]:
    return tuple(RotorSlot(n, i, b, d) for i, (n, b, d) in enumerate(zip(names, bearings, dirs)))


# PX4 airframe reference (quad/hexa/octo mixers), motor 1 first. Bearings in degrees.
FRAMES: dict[str, Airframe | GroundLayout] = {
    "quad-x": Airframe(
        "quad-x", "Quadrotor X",
        _ring(["front_right", "back_left", "front_left", "back_right"],
              [45.0, -135.0, -45.0, 135.0], ["ccw", "ccw", "cw", "cw"]),
        radial_per_arm_length=math.sqrt(2.0),
        reference="PX4 Quadrotor x (motor 1 front-right CCW) = the seed's reed_quad_x"),
    "quad-plus": Airframe(
        "quad-plus", "Quadrotor +",
        _ring(["right", "left", "front", "back"],
              [90.0, -90.0, 0.0, 180.0], ["ccw", "ccw", "cw", "cw"]),
        radial_per_arm_length=1.0,
        reference="PX4 Quadrotor + (motor 1 right CCW)"),
    "hex-x": Airframe(
        "hex-x", "Hexarotor X",
        _ring(["right", "left", "front_left", "back_right", "front_right", "back_left"],
              [90.0, -90.0, -30.0, 150.0, 30.0, -150.0],
              ["cw", "ccw", "cw", "ccw", "ccw", "cw"]),
        radial_per_arm_length=1.0,
        reference="PX4 Hexarotor x (motor 1 right CW)"),
    "hex-plus": Airframe(
        "hex-plus", "Hexarotor +",
        _ring(["front", "back", "back_left", "front_right", "front_left", "back_right"],
              [0.0, 180.0, -120.0, 60.0, -60.0, 120.0],
              ["cw", "ccw", "cw", "ccw", "ccw", "cw"]),
        radial_per_arm_length=1.0,
        reference="PX4 Hexarotor + (motor 1 front CW)"),
    "octo-x": Airframe(
        "octo-x", "Octorotor X",
        _ring(["front_right", "back_left", "right_front", "back_right",
               "front_left", "left_back", "left_front", "right_back"],
              [22.5, -157.5, 67.5, 157.5, -22.5, -112.5, -67.5, 112.5],
              ["ccw", "ccw", "cw", "cw", "cw", "cw", "ccw", "ccw"]),
        radial_per_arm_length=1.0,
        reference="PX4 Octorotor x (motor 1 front-right CCW)"),
    "y6": Airframe(
        "y6", "Coaxial hexarotor Y6",
        tuple(RotorSlot(n, i, b, d, level) for i, (n, b, d, level) in enumerate([
            ("front_right_top", 60.0, "cw", 1), ("front_right_bottom", 60.0, "ccw", -1),
            ("back_top", 180.0, "cw", 1), ("back_bottom", 180.0, "ccw", -1),
            ("front_left_top", -60.0, "cw", 1), ("front_left_bottom", -60.0, "ccw", -1)])),
        radial_per_arm_length=1.0,
        reference="PX4 Hexarotor Coaxial (MAIN1 front-right top CW, MAIN2 its lower CCW)"),
    "car-4w": GroundLayout(
        "car-4w", "Four-wheel skid-steer car",
        (WheelSlot("front_left", 0.5, 1), WheelSlot("front_right", 0.5, -1),
         WheelSlot("rear_left", -0.5, 1), WheelSlot("rear_right", -0.5, -1)),
        drive="skid_steer", caster=False),
    "diff-drive": GroundLayout(
        "diff-drive", "Differential drive with rear caster",
        (WheelSlot("left", 0.0, 1), WheelSlot("right", 0.0, -1)),
        drive="diff_drive", caster=True),
}

MULTIROTOR_FRAMES = tuple(n for n, f in FRAMES.items() if f.kind == "multirotor")
GROUND_FRAMES = tuple(n for n, f in FRAMES.items() if f.kind == "ground")


def get_frame(name: str) -> Airframe | GroundLayout:
    """The catalogue entry for `name`; an unknown name is a user error with a suggestion."""
    try:
        return FRAMES[name]
    except KeyError:
        close = difflib.get_close_matches(name, FRAMES, n=1)
        hint = f"did you mean '{close[0]}'?" if close else f"choose one of: {', '.join(FRAMES)}"
        raise ReedtoolError(f"unknown frame '{name}'", hint=hint) from None
