"""ArduPilot (ArduCopter) motor tables and `.parm` files, read with lines.

ArduCopter fixes which motor sits where and which way it spins by `FRAME_CLASS` and
`FRAME_TYPE` (libraries/AP_Motors/AP_MotorsMatrix.cpp, `setup_quad_matrix`,
`setup_hexa_matrix`, `setup_octa_matrix`, `setup_octaquad_matrix`, `setup_y6_matrix`; the
enums in AP_Motors_Class.h). The tables below are reedtool's own transcription of those
facts: motor number (1-based), bearing in degrees clockwise from the nose seen from above
(AP's `add_motor` angle; for `add_motor_raw` entries atan2(-roll, pitch) of its factors),
spin (+1 counter-clockwise, -1 clockwise, 0 when the frame gives the motor no yaw factor)
and the testing order.

Outputs: motor m is sent on the servo output whose `SERVOn_FUNCTION` is 32 + m (33..40 =
Motor1..8; 82..85 = Motor9..12); without that parameter, ArduCopter assigns motor m to
output m. In Gazebo, the ArduPilotPlugin's `<control channel="c">` reads output c + 1
(channel 0 is SERVO1).
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from pathlib import Path

from reedtool.errors import ReedtoolError
from reedtool.model import SourceLoc

CCW, CW = 1, -1
FRAME_CLASSES = {1: "QUAD", 2: "HEXA", 3: "OCTA", 4: "OCTAQUAD", 5: "Y6"}
FRAME_TYPES = {0: "PLUS", 1: "X", 2: "V", 3: "H", 4: "VTAIL", 5: "ATAIL", 6: "PLUSREV",
               10: "Y6B", 11: "Y6F", 12: "BF_X", 13: "DJI_X", 14: "CW_X", 15: "I",
               16: "NYT_PLUS", 17: "NYT_X", 18: "BF_X_REV", 19: "Y4"}
SOURCE = "ArduPilot libraries/AP_Motors/AP_MotorsMatrix.cpp"


@dataclass(frozen=True)
class ApMotor:
    number: int            # 1-based motor number (AP_MOTORS_MOT_n + 1)
    bearing_deg: float     # clockwise from the nose, seen from above
    spin: int              # +1 ccw, -1 cw, 0 none (no yaw factor)
    test_order: int


def _angles(rows) -> tuple[ApMotor, ...]:
    """Rows (bearing, yaw factor, testing order), in motor-number order."""
    return tuple(ApMotor(i, float(b), int(math.copysign(1, y)) if y else 0, t)
                 for i, (b, y, t) in enumerate(rows, start=1))


def _raw(rows) -> tuple[ApMotor, ...]:
    """Rows (roll factor, pitch factor, yaw factor, testing order): add_motor_raw."""
    return _angles([(round(math.degrees(math.atan2(-r, p)), 1), y, t) for r, p, y, t in rows])


def _reversed(motors: tuple[ApMotor, ...]) -> tuple[ApMotor, ...]:
    return tuple(ApMotor(m.number, m.bearing_deg, -m.spin, m.test_order) for m in motors)


_QUAD_PLUS = _angles([(90, CCW, 2), (-90, CCW, 4), (0, CW, 1), (180, CW, 3)])
_QUAD_X = _angles([(45, CCW, 1), (-135, CCW, 3), (-45, CW, 4), (135, CW, 2)])
_QUAD_BF_X = _angles([(135, CW, 2), (45, CCW, 1), (-135, CCW, 3), (-45, CW, 4)])
# (frame class, frame type) -> motors in motor-number order. Type None: the class's default.
MOTOR_TABLES: dict[tuple[int, int | None], tuple[ApMotor, ...]] = {
    (1, 0): _QUAD_PLUS,
    (1, 1): _QUAD_X,
    (1, 2): _angles([(45, 0.7981, 1), (-135, 1.0, 3), (-45, -0.7981, 4), (135, -1.0, 2)]),
    (1, 3): _reversed(_QUAD_X),
    # V-tail / A-tail: add_motor(roll angle, pitch angle): front motors (60, 60) and
    # (-60, -60) carry no yaw; the rear ones (0, +-160) sit on the centre line.
    (1, 4): _angles([(60, 0, 1), (180, CW, 3), (-60, 0, 4), (180, CCW, 2)]),
    (1, 5): _angles([(60, 0, 1), (180, CCW, 3), (-60, 0, 4), (180, CW, 2)]),
    (1, 6): _reversed(_QUAD_PLUS),
    (1, 12): _QUAD_BF_X,
    (1, 13): _angles([(45, CCW, 1), (-45, CW, 4), (-135, CCW, 3), (135, CW, 2)]),
    (1, 14): _angles([(45, CCW, 1), (135, CW, 2), (-135, CCW, 3), (-45, CW, 4)]),
    (1, 16): _angles([(90, 0, 2), (-90, 0, 4), (0, 0, 1), (180, 0, 3)]),
    (1, 17): _angles([(45, 0, 1), (-135, 0, 3), (-45, 0, 4), (135, 0, 2)]),
    (1, 18): _reversed(_QUAD_BF_X),
    (2, 0): _angles([(0, CW, 1), (180, CCW, 4), (-120, CW, 5), (60, CCW, 2), (-60, CCW, 6),
                     (120, CW, 3)]),
    (2, 1): _angles([(90, CW, 2), (-90, CCW, 5), (-30, CW, 6), (150, CCW, 3), (30, CCW, 1),
                     (-150, CW, 4)]),
    (3, 0): _angles([(0, CW, 1), (180, CW, 5), (45, CCW, 2), (135, CCW, 4), (-45, CCW, 8),
                     (-135, CCW, 6), (-90, CW, 7), (90, CW, 3)]),
    (3, 1): _angles([(22.5, CW, 1), (-157.5, CW, 5), (67.5, CCW, 2), (157.5, CCW, 4),
                     (-22.5, CCW, 8), (-112.5, CCW, 6), (-67.5, CW, 7), (112.5, CW, 3)]),
    (4, 0): _angles([(0, CCW, 1), (-90, CW, 7), (180, CCW, 5), (90, CW, 3), (-90, CCW, 8),
                     (0, CW, 2), (90, CCW, 4), (180, CW, 6)]),
    (4, 1): _angles([(45, CCW, 1), (-45, CW, 7), (-135, CCW, 5), (135, CW, 3), (-45, CCW, 8),
                     (45, CW, 2), (135, CCW, 4), (-135, CW, 6)]),
    (4, 3): _angles([(45, CW, 1), (-45, CCW, 7), (-135, CW, 5), (135, CCW, 3), (-45, CW, 8),
                     (45, CCW, 2), (135, CW, 4), (-135, CCW, 6)]),
    (5, 10): _raw([(-1.0, 0.5, CW, 1), (-1.0, 0.5, CCW, 2), (0.0, -1.0, CW, 3),
                   (0.0, -1.0, CCW, 4), (1.0, 0.5, CW, 5), (1.0, 0.5, CCW, 6)]),
    (5, 11): _raw([(0.0, -1.0, CCW, 3), (-1.0, 0.5, CCW, 1), (1.0, 0.5, CCW, 5),
                   (0.0, -1.0, CW, 4), (-1.0, 0.5, CW, 2), (1.0, 0.5, CW, 6)]),
    (5, None): _raw([(-1.0, 0.666, CCW, 2), (1.0, 0.666, CW, 5), (1.0, 0.666, CCW, 6),
                     (0.0, -1.333, CW, 4), (-1.0, 0.666, CW, 1), (0.0, -1.333, CCW, 3)]),
}
# Functions behind the SERVOn_FUNCTION values for motors: 33..40 Motor1..8, 82..85 Motor9..12.
MOTOR_FUNCTIONS = {**{32 + m: m for m in range(1, 9)}, **{73 + m: m for m in range(9, 13)}}


def motor_function(motor: int) -> int:
    return 32 + motor if motor <= 8 else 73 + motor


def frame_name(frame_class: int, frame_type: int | None) -> str:
    type_name = FRAME_TYPES.get(frame_type, str(frame_type)) if frame_type is not None else "?"
    return f"{FRAME_CLASSES.get(frame_class, str(frame_class))}/{type_name}"


def motor_table(frame_class: int, frame_type: int) -> tuple[ApMotor, ...] | None:
    """The motors of a frame, or None when reedtool does not know it."""
    if (frame_class, frame_type) in MOTOR_TABLES:
        return MOTOR_TABLES[(frame_class, frame_type)]
    return MOTOR_TABLES.get((frame_class, None))


@dataclass
class ParmValue:
    name: str
    value: float
    loc: SourceLoc
    explicit: bool = True


@dataclass
class ArduPilotParams:
    file: str
    values: dict[str, ParmValue] = field(default_factory=dict)
    kind: str = "ardupilot"

    @property
    def label(self) -> str:
        return f"ArduPilot parameters {Path(self.file).name}"

    @property
    def loc(self) -> SourceLoc:
        """The file, without a line: where a finding about an unset parameter points."""
        return SourceLoc(self.file)

    def get(self, name: str, default: float | None = None) -> ParmValue | None:
        if name in self.values:
            return self.values[name]
        return None if default is None else ParmValue(name, default, self.loc, explicit=False)

    def frame(self) -> tuple[ParmValue | None, ParmValue]:
        """FRAME_CLASS (None if unset: ArduCopter's default 0 is 'undefined') and FRAME_TYPE
        (default 1, X)."""
        return self.get("FRAME_CLASS"), self.get("FRAME_TYPE", 1.0)

    def output_of_motor(self, motor: int) -> tuple[int, ParmValue | None]:
        """The 1-based servo output carrying `motor`, and the SERVOn_FUNCTION line that says
        so (None: ArduCopter's default, output = motor number). 0 when no output carries it."""
        function = motor_function(motor)
        servo_functions = {int(m.group(1)): v for name, v in self.values.items()
                           if (m := re.fullmatch(r"SERVO(\d+)_FUNCTION", name))}
        for output, value in sorted(servo_functions.items()):
            if int(value.value) == function:
                return output, value
        if motor in servo_functions and MOTOR_FUNCTIONS.get(int(servo_functions[motor].value)) \
                != motor:
            return 0, servo_functions[motor]      # its default output was given another job
        return motor, None


_LINE = re.compile(r"^\s*([A-Za-z][A-Za-z0-9_]*)[\s,=]+([-+0-9.eE]+)\s*(#.*)?$")
# A QGroundControl export of ArduPilot parameters: vehicle, component, NAME, VALUE, type.
_QGC_LINE = re.compile(r"^\s*\d+\t\d+\t([A-Za-z][A-Za-z0-9_]*)\t(\S+)\t\d+\s*$")


def parse_parm(text: str, file: str) -> ArduPilotParams:
    params = ArduPilotParams(file)
    for number, line in enumerate(text.splitlines(), start=1):
        stripped = line.strip()
        if not stripped or stripped.startswith("#"):
            continue
        match = _QGC_LINE.match(line) or _LINE.match(line)
        loc = SourceLoc(file, number)
        if not match:
            raise ReedtoolError(f"cannot read '{stripped}' as `NAME VALUE`", file=file,
                                line=number, hint="an ArduPilot .parm line is NAME VALUE")
        try:
            value = float(match.group(2))
        except ValueError:
            raise ReedtoolError(f"{match.group(1)}: '{match.group(2)}' is not a number",
                                file=file, line=number) from None
        params.values[match.group(1).upper()] = ParmValue(match.group(1).upper(), value, loc)
    return params


def load_parm(path: Path) -> ArduPilotParams:
    from reedtool.io.fileio import read_text_file

    path = Path(path)
    return parse_parm(read_text_file(path, what="ArduPilot parameter file"), str(path))


# ------------------------------------------------------------------ choosing a frame

def angle_gap_deg(a: float, b: float) -> float:
    return abs((a - b + 180.0) % 360.0 - 180.0)


def match_frame(bearings_deg: list[float], spins: list[int], tolerance_deg: float = 1.0
                ) -> tuple[int, int, list[int]] | None:
    """The first known frame whose motors sit at these bearings with these spins.

    Returns (class, type, motor number for each input rotor), or None.
    """
    for (frame_class, frame_type), motors in MOTOR_TABLES.items():
        if frame_type is None or len(motors) != len(bearings_deg):
            continue
        free = list(motors)
        numbers = []
        for bearing, spin in zip(bearings_deg, spins):
            found = next((m for m in free if m.spin == spin
                          and angle_gap_deg(m.bearing_deg, bearing) <= tolerance_deg), None)
            if found is None:
                break
            free.remove(found)
            numbers.append(found.number)
        else:
            return frame_class, frame_type, numbers
    return None


def parm_text(name: str, frame_class: int, frame_type: int, motor_of_output: dict[int, int]
              ) -> str:
    """A SITL .parm for a frame; `motor_of_output`: 1-based output -> motor number."""
    lines = [f"# {name}: ArduCopter SITL parameters generated by reedtool new-package",
             f"# frame {frame_name(frame_class, frame_type)} ({SOURCE})",
             f"FRAME_CLASS {frame_class}", f"FRAME_TYPE {frame_type}"]
    for output, motor in sorted(motor_of_output.items()):
        lines.append(f"SERVO{output}_FUNCTION {motor_function(motor)}")
    return "\n".join(lines) + "\n"
