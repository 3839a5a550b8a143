"""PX4 parameters with their lines: airframe scripts and QGroundControl parameter files.

Two formats, recognised line by line so a file may mix them:

* an airframe script (PX4-Autopilot `ROMFS/px4fmu_common/init.d-posix/airframes/*`):
  `param set-default NAME VALUE` and `param set NAME VALUE`; `#` comments and every
  other shell line are ignored. A `param set` value beats a `set-default` one whatever
  their order (set-default only changes the default); otherwise the last line wins.
* a QGroundControl export: tab-separated `vehicle-id  component-id  NAME  VALUE  type`.

What the rotor table means (PX4 control allocation, v1.14+; src/modules/control_allocator
module.yaml and ActuatorEffectivenessRotors): `CA_ROTOR_COUNT` rotors, rotor i at
`CA_ROTORi_PX/PY/PZ` metres in the body frame FRD (x forward, y right, z down) relative to
the centre of gravity, thrust along `CA_ROTORi_AX/AY/AZ` (default 0, 0, -1: up), and
`CA_ROTORi_KM` the yaw moment per thrust, positive for a counter-clockwise rotor (seen
from above), negative for clockwise. For Gazebo SITL the gz bridge (src/modules/simulation/
gz_bridge module.yaml) sends ESC output k (1-based) as velocity k-1 of the motor command,
which the MulticopterMotorModel with that actuator number turns into rad/s; output k
carries CA rotor i when `SIM_GZ_EC_FUNCk` = 101 + i (function "Motor i+1"), and its
command range is `SIM_GZ_EC_MINk` .. `SIM_GZ_EC_MAXk` rad/s.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from reedtool.errors import ReedtoolError
from reedtool.model import SourceLoc

MOTOR_FUNCTION_BASE = 101          # PX4 output function "Motor 1"
# PX4's gz bridge: the link whose sensors it reads and the topic its ESC outputs go to,
# below the model instance (GZBridge.cpp, GZMixingInterfaceESC.cpp).
PX4_BRIDGE_LINK = "base_link"
PX4_MOTOR_TOPIC = "command/motor_speed"
MAX_GZ_OUTPUTS = 8                 # SIM_GZ_EC has 8 channels (gz_bridge module.yaml)
MAX_CLASSIC_OUTPUTS = 16           # PWM_MAIN outputs simulator_mavlink sends
MAX_CA_ROTORS = 12

# Documented ranges of the parameters reedtool reads or writes: (min, max, default, source).
_CA = "PX4-Autopilot src/modules/control_allocator/module.yaml"
_GZ = "PX4-Autopilot src/modules/simulation/gz_bridge/module.yaml"
PARAM_RANGES: dict[str, tuple[float, float, float | None, str]] = {
    "CA_ROTOR_COUNT": (0, MAX_CA_ROTORS, 0, _CA),
    "CA_ROTOR#_PX": (-100.0, 100.0, 0.0, _CA),
    "CA_ROTOR#_PY": (-100.0, 100.0, 0.0, _CA),
    "CA_ROTOR#_PZ": (-100.0, 100.0, 0.0, _CA),
    "CA_ROTOR#_AX": (-100.0, 100.0, 0.0, _CA),
    "CA_ROTOR#_AY": (-100.0, 100.0, 0.0, _CA),
    "CA_ROTOR#_AZ": (-100.0, 100.0, -1.0, _CA),
    "CA_ROTOR#_KM": (-1.0, 1.0, 0.05, _CA),
    # 0..1000 is what QGroundControl offers (module.yaml); PX4 itself takes up to
    # GZ_OUTPUT_CEILING (px4vision: 1100). C425 leaves these to C419/C420/C424.
    "SIM_GZ_EC_MIN#": (0.0, 1000.0, 0.0, _GZ),
    "SIM_GZ_EC_MAX#": (0.0, 1000.0, 1000.0, _GZ),
    "SIM_GZ_EC_DIS#": (0.0, 1000.0, 0.0, _GZ),
    "CA_AIRFRAME": (0, 14, 0, _CA),
    "CA_ROTOR#_TILT": (0, 4, 0, _CA),
    "CA_SV_TL_COUNT": (0, 4, 0, _CA),
    "CA_SV_TL#_MINA": (-90.0, 90.0, -45.0, _CA),
    "CA_SV_TL#_MAXA": (-90.0, 90.0, 45.0, _CA),
    "CA_SV_TL#_TD": (0, 359, 0, _CA),
    "CA_SV_TL#_CT": (0, 3, 1, _CA),
    "MPC_THR_HOVER": (0.1, 0.8, 0.5, "PX4-Autopilot src/modules/mc_pos_control "
                                     "(PARAM_DEFINE_FLOAT MPC_THR_HOVER: @min 0.1, @max 0.8)"),
    "THR_MDL_FAC": (0.0, 1.0, 0.0, "PX4 parameter reference, THR_MDL_FAC (0..1)"),
}

# The shell variables of a SITL airframe that say which simulator and model it is for.
_SHELL_VAR = re.compile(r"^\s*(PX4_SIMULATOR|PX4_SIM_MODEL|PX4_GZ_WORLD)=(?:\$\{\w+:=)?([^}\s]*)")
_QGC_LINE = re.compile(r"^\s*(\d+)\t(\d+)\t([A-Za-z0-9_]+)\t(\S+)\t(\d+)\s*$")
_PARAM_CMD = re.compile(r"^\s*param\s+(set-default|set)\s+([A-Za-z0-9_]+)\s+(\S+)")


def range_key(name: str) -> str:
    """CA_ROTOR3_KM -> CA_ROTOR#_KM, SIM_GZ_EC_MAX2 -> SIM_GZ_EC_MAX#: the PARAM_RANGES key."""
    return re.sub(r"\d+", "#", name) if re.search(r"(ROTOR\d+_|EC_(MIN|MAX|DIS)\d+$|SV_TL\d+_)", name) \
        else name


@dataclass
class ParamValue:
    name: str
    value: float
    text: str
    loc: SourceLoc                 # the line that sets it; the file alone for a default
    explicit: bool = True          # False: the documented default, no line in the file

    def describe(self) -> str:
        """'NAME V (file:line)', or 'NAME not set: PX4's default V (file)'."""
        if self.explicit:
            return f"{self.name} {self.value:g} ({self.loc})"
        return f"{self.name} not set: PX4's default {self.value:g} ({self.loc})"


@dataclass
class Px4Rotor:
    """One CA_ROTOR entry, in PX4's body frame FRD relative to the centre of gravity."""

    index: int                     # i in CA_ROTORi_*
    position_frd_m: np.ndarray
    axis_frd: np.ndarray           # as written (not normalised)
    km: float
    params: dict[str, ParamValue]  # 'PX', 'PY', ... -> the value and its line

    def loc_of(self, suffix: str) -> SourceLoc:
        return self.params[suffix].loc

    def where(self, *suffixes: str) -> str:
        return ", ".join(self.params[s].describe() for s in suffixes)


@dataclass
class Px4Params:
    file: str
    values: dict[str, ParamValue] = field(default_factory=dict)
    problems: list[tuple[str, SourceLoc]] = field(default_factory=list)
    kind: str = "px4"
    shell: dict[str, tuple[str, SourceLoc]] = field(default_factory=dict)   # PX4_SIMULATOR=...

    @property
    def label(self) -> str:
        return f"PX4 parameters {Path(self.file).name}"

    @property
    def loc(self) -> SourceLoc:
        """The file, without a line: where a finding about an unset parameter points."""
        return SourceLoc(self.file)

    def get(self, name: str) -> ParamValue:
        """The value set in the file, else PX4's documented default (explicit=False)."""
        if name in self.values:
            return self.values[name]
        default = PARAM_RANGES.get(range_key(name), (0, 0, None, ""))[2]
        return ParamValue(name, math.nan if default is None else float(default),
                          "", self.loc, explicit=False)

    def has(self, name: str) -> bool:
        return name in self.values

    @property
    def rotor_count(self) -> int | None:
        value = self.values.get("CA_ROTOR_COUNT")
        return int(value.value) if value is not None and value.value.is_integer() else None

    def rotors(self) -> list[Px4Rotor]:
        out = []
        for i in range(min(self.rotor_count or 0, MAX_CA_ROTORS)):
            params = {s: self.get(f"CA_ROTOR{i}_{s}")
                      for s in ("PX", "PY", "PZ", "AX", "AY", "AZ", "KM")}
            out.append(Px4Rotor(
                i, np.array([params[s].value for s in ("PX", "PY", "PZ")]),
                np.array([params[s].value for s in ("AX", "AY", "AZ")]),
                params["KM"].value, params))
        return out

    def outputs_of(self, ca_index: int) -> list[int]:
        """The gz ESC outputs k (1-based) whose function is CA rotor `ca_index`."""
        return [k for k in range(1, MAX_GZ_OUTPUTS + 1)
                if self.get(f"SIM_GZ_EC_FUNC{k}").value == MOTOR_FUNCTION_BASE + ca_index]

    @property
    def uses_gz_outputs(self) -> bool:
        return any(self.has(f"SIM_GZ_EC_FUNC{k}") for k in range(1, MAX_GZ_OUTPUTS + 1))

    def classic_outputs_of(self, ca_index: int) -> list[int]:
        """The simulator_mavlink outputs k (PWM_MAIN, 1-based) whose function is CA rotor
        `ca_index`; output i+1 for rotor i when the file sets no PWM_MAIN_FUNC."""
        if not any(name.startswith("PWM_MAIN_FUNC") for name in self.values):
            return [ca_index + 1]
        return [k for k in range(1, MAX_CLASSIC_OUTPUTS + 1)
                if self.get(f"PWM_MAIN_FUNC{k}").value == MOTOR_FUNCTION_BASE + ca_index]

    def simulator(self) -> "SimulatorEvidence | None":
        """Which Gazebo the airframe is for, and what says so; None when it does not say."""
        return airframe_simulator(self)


@dataclass
class SimulatorEvidence:
    simulator: str                 # "gz" (Gazebo Sim, gz_bridge) | "classic" (simulator_mavlink)
    what: str                      # the line or name that says so
    loc: SourceLoc


def airframe_simulator(params: Px4Params) -> SimulatorEvidence | None:
    """gz: SIM_GZ_EN 1, PX4_SIMULATOR=gz or SIM_GZ_EC_* parameters (px4-rc.simulator starts
    the gz bridge on SIM_GZ_EN 1 or PX4_SIMULATOR=gz). Classic: PX4_SIMULATOR=gazebo-classic,
    a gazebo-classic airframe name (PX4's NNNN_gazebo-classic_*), or PWM_MAIN_FUNC outputs
    without any SIM_GZ parameter (simulator_mavlink sends PWM_MAIN as HIL_ACTUATOR_CONTROLS)."""
    enabled = params.values.get("SIM_GZ_EN")
    if enabled is not None and enabled.value == 1:
        return SimulatorEvidence("gz", enabled.describe(), enabled.loc)
    simulator = params.shell.get("PX4_SIMULATOR")
    if simulator is not None and simulator[0] == "gz":
        return SimulatorEvidence("gz", f"PX4_SIMULATOR={simulator[0]} ({simulator[1]})",
                                 simulator[1])
    gz = [v for v in params.values.values() if v.name.startswith("SIM_GZ_")]
    if gz:
        return SimulatorEvidence("gz", gz[0].describe(), gz[0].loc)
    if simulator is not None and simulator[0] == "gazebo-classic":
        return SimulatorEvidence("classic", f"PX4_SIMULATOR={simulator[0]} ({simulator[1]})",
                                 simulator[1])
    if "gazebo-classic" in Path(params.file).name:
        return SimulatorEvidence("classic", f"the airframe name {Path(params.file).name}",
                                 params.loc)
    outputs = [v for v in params.values.values() if v.name.startswith("PWM_MAIN_FUNC")]
    if outputs:
        return SimulatorEvidence("classic", f"{outputs[0].describe()}, no SIM_GZ parameter",
                                 outputs[0].loc)
    return None


# ------------------------------------------------------------ Classic SITL

@dataclass
class MavlinkChannel:
    """One control channel of PX4-SITL_gazebo-classic's gazebo_mavlink_interface: while
    armed it commands input_reference = (u + input_offset) * input_scaling +
    zero_position_armed from actuator_controls[input_index] (gazebo_mavlink_interface.cpp),
    u in 0..1 for a motor; the motor with motorNumber n reads the entry of channel n (the
    n-th <channel>)."""

    position: int                  # n: the motor number that reads it
    input_index: int | None        # PWM_MAIN output input_index + 1 feeds it
    offset: float
    scaling: float
    zero_armed: float
    velocity: bool
    loc: SourceLoc

    def range_rad_s(self) -> tuple[float, float]:
        """(speed at u = 0, speed at u = 1) while armed."""
        return (self.offset * self.scaling + self.zero_armed,
                (1.0 + self.offset) * self.scaling + self.zero_armed)

    def describe(self) -> str:
        return (f"mavlink channel {self.position} ({self.loc}): (u + {self.offset:g}) x "
                f"{self.scaling:g} + {self.zero_armed:g}")


def mavlink_channels(robot) -> list[MavlinkChannel]:
    """The control channels of the model's gazebo_mavlink_interface, in order ([] when it
    has none: RotorS' interface, or no interface)."""
    from reedtool.physics.rotors import MAVLINK_PLUGINS

    def number(node, tag: str, default: float) -> float:
        text = node.findtext(tag)
        try:
            return float(text) if text is not None and text.strip() else default
        except ValueError:
            return math.nan

    for _block, plugin in robot.plugins():
        if plugin.library not in MAVLINK_PLUGINS:
            continue
        channels = plugin.node.find("control_channels")
        if channels is None:
            continue
        out = []
        for position, channel in enumerate(channels.findall("channel")):
            index_text = (channel.findtext("input_index") or "").strip()
            kind = (channel.findtext("joint_control_type") or "velocity").strip()
            out.append(MavlinkChannel(position, int(index_text) if index_text.isdigit() else None,
                                      number(channel, "input_offset", 0.0),
                                      number(channel, "input_scaling", 1.0),
                                      number(channel, "zero_position_armed", 0.0),
                                      kind == "velocity", channel.loc))
        return out
    return []


# ------------------------------------------------------------ CA_AIRFRAME

@dataclass(frozen=True)
class Effectiveness:
    """How PX4's control allocation reads the CA_ROTOR table for one CA_AIRFRAME value
    (PX4-Autopilot src/modules/control_allocator: ControlAllocator::
    update_effectiveness_source, VehicleActuatorEffectiveness/ActuatorEffectiveness*)."""

    value: int
    name: str
    rotor_table: bool = True       # False: no CA_ROTOR geometry (rovers, helicopters)
    # ActuatorEffectivenessRotors::AxisConfiguration: "configurable" reads CA_ROTORi_AX/AY/AZ,
    # "forward" fixes (1, 0, 0), "upward" fixes (0, 0, -1), whatever the parameters say.
    axes: str = "configurable"
    tilts: bool = False            # CA_ROTORi_TILT makes a rotor's axis follow a tilt servo
    # Fixed-wing: enablePropellerTorque(false), no rotor's KM is used; standard VTOL:
    # enablePropellerTorqueNonUpwards(false), a pusher's KM is not used.
    propeller_torque: bool = True
    torque_upward_only: bool = False
    # Tailsitter: yaw by differential thrust only with more than 3 rotors; tiltrotor: not
    # when a tilt servo controls yaw (CA_SV_TLk_CT 1 or 3).
    yaw_rule: str = "always"       # "always" | "more-than-3" | "unless-tilt-yaw"


AIRFRAMES: dict[int, Effectiveness] = {e.value: e for e in (
    Effectiveness(0, "multirotor"),
    Effectiveness(1, "fixed-wing", axes="forward", propeller_torque=False),
    Effectiveness(2, "standard VTOL", torque_upward_only=True),
    Effectiveness(3, "tiltrotor VTOL", tilts=True, yaw_rule="unless-tilt-yaw"),
    # ActuatorEffectivenessTailsitterVTOL: _mc_rotors(this), the default (configurable)
    # axes; QGroundControl shows no axis for it, so they stay at PX4's default, upward.
    Effectiveness(4, "tailsitter VTOL", yaw_rule="more-than-3"),
    Effectiveness(5, "rover (Ackermann)", rotor_table=False),
    Effectiveness(6, "rover (differential)", rotor_table=False),
    Effectiveness(7, "motors 6DOF"),
    Effectiveness(8, "multirotor with tilt", axes="upward", tilts=True),
    Effectiveness(9, "custom"),
    Effectiveness(10, "helicopter (tail ESC)", rotor_table=False),
    Effectiveness(11, "helicopter (tail servo)", rotor_table=False),
    Effectiveness(12, "helicopter (coaxial)", rotor_table=False),
    Effectiveness(13, "spacecraft 2D", rotor_table=False),
    Effectiveness(14, "spacecraft 3D", rotor_table=False),
)}
UPWARD_FRD = np.array([0.0, 0.0, -1.0])
FORWARD_FRD = np.array([1.0, 0.0, 0.0])


def effectiveness(params: "Px4Params") -> Effectiveness | None:
    """The effectiveness class CA_AIRFRAME selects (default 0, multirotor); None for a value
    PX4 does not know (it then allocates nothing: 'Unknown airframe')."""
    value = params.get("CA_AIRFRAME").value
    return AIRFRAMES.get(int(value)) if math.isfinite(value) and value.is_integer() else None


def tilted_axis(tilt_rad: float, direction_rad: float) -> np.ndarray:
    """ActuatorEffectivenessRotors::tiltedAxis: (0, 0, -1) rotated by -tilt about y, then
    by the tilt direction about z (FRD)."""
    return np.array([math.sin(tilt_rad) * math.cos(direction_rad),
                     math.sin(tilt_rad) * math.sin(direction_rad), -math.cos(tilt_rad)])


def is_upward(axis_frd: np.ndarray) -> bool:
    """ActuatorEffectivenessRotors::getUpwardsMotors' test on a normalised axis."""
    return abs(axis_frd[0]) < 0.1 and abs(axis_frd[1]) < 0.1 and axis_frd[2] < -0.5


@dataclass
class RotorAxis:
    """The thrust axis PX4 allocates CA rotor i with (FRD, unit), and where it comes from."""

    axis_frd: np.ndarray
    source: str                    # "parameters", "fixed", "tilt"
    text: str                      # for messages: the parameters or the rule that fix it


def rotor_axis(params: "Px4Params", rotor: Px4Rotor, kind: Effectiveness) -> RotorAxis | None:
    """The axis PX4 uses for the rotor in hover (tilts at their minimum angle: collective
    tilt -1 while disarmed and hovering); None when the written axis is zero (PX4 ignores
    the rotor)."""
    if kind.tilts:
        tilt = params.get(f"CA_ROTOR{rotor.index}_TILT")
        index = int(tilt.value) - 1 if math.isfinite(tilt.value) else -1
        count = params.get("CA_SV_TL_COUNT").value
        if 0 <= index < count:
            low = params.get(f"CA_SV_TL{index}_MINA").value
            direction = params.get(f"CA_SV_TL{index}_TD").value
            return RotorAxis(tilted_axis(math.radians(low), math.radians(direction)), "tilt",
                             f"{tilt.describe()}: tilt servo {index} at its minimum angle "
                             f"{low:g}° (hover), direction {direction:g}°")
    if kind.axes == "forward":
        return RotorAxis(FORWARD_FRD.copy(), "fixed",
                         f"CA_AIRFRAME {kind.value} ({kind.name}) fixes every rotor forward")
    if kind.axes == "upward":
        return RotorAxis(UPWARD_FRD.copy(), "fixed",
                         f"CA_AIRFRAME {kind.value} ({kind.name}) fixes every rotor upward")
    norm = float(np.linalg.norm(rotor.axis_frd))
    if not math.isfinite(norm) or norm <= 1e-7:
        return None
    return RotorAxis(rotor.axis_frd / norm, "parameters", rotor.where("AX", "AY", "AZ"))


def uses_yaw_moment(params: "Px4Params", kind: Effectiveness, axis: RotorAxis) -> bool:
    """Whether PX4 uses rotor i's KM (its yaw reaction torque) for yaw control."""
    if not kind.propeller_torque:
        return False
    if kind.torque_upward_only and not is_upward(axis.axis_frd):
        return False
    if kind.yaw_rule == "more-than-3":
        return (params.rotor_count or 0) > 3
    if kind.yaw_rule == "unless-tilt-yaw":
        count = int(params.get("CA_SV_TL_COUNT").value)
        return not any(int(params.get(f"CA_SV_TL{k}_CT").value) in (1, 3)
                       for k in range(max(0, min(count, 4))))
    return True


def _number(text: str, name: str, loc: SourceLoc) -> float:
    try:
        return float(text)
    except ValueError:
        raise ReedtoolError(f"{name}: '{text}' is not a number", file=loc.file, line=loc.line,
                            hint="PX4 parameter values are plain numbers") from None


def parse_px4_params(text: str, file: str) -> Px4Params:
    """Read an airframe script or a QGC parameter file; a value that is no number is an error."""
    params = Px4Params(file)
    from_set: set[str] = set()
    for number, line in enumerate(text.splitlines(), start=1):
        loc = SourceLoc(file, number)
        stripped = line.strip()
        if not stripped or stripped.startswith("#"):
            continue
        qgc = _QGC_LINE.match(line)
        if qgc:
            name, value_text = qgc.group(3), qgc.group(4)
            params.values[name] = ParamValue(name, _number(value_text, name, loc), value_text, loc)
            continue
        var = _SHELL_VAR.match(line)
        if var:
            params.shell[var.group(1)] = (var.group(2), loc)
            continue
        cmd = _PARAM_CMD.match(line)
        if cmd:
            verb, name, value_text = cmd.groups()
            value_text = value_text.split("#", 1)[0]
            if verb == "set-default" and name in from_set:
                continue
            if verb == "set":
                from_set.add(name)
            params.values[name] = ParamValue(name, _number(value_text, name, loc), value_text, loc)
    return params


def load_px4_params(path: Path) -> Px4Params:
    from reedtool.io.fileio import read_text_file

    path = Path(path)
    params = parse_px4_params(read_text_file(path, what="PX4 parameter file"), str(path))
    if not params.values:
        raise ReedtoolError("no PX4 parameter found (expected `param set-default NAME VALUE` "
                            "lines or a QGroundControl tab-separated export)", file=str(path),
                            hint="--airframe takes a PX4 airframe script or .params file")
    return params


def out_of_range(params: Px4Params) -> list[tuple[ParamValue, tuple]]:
    """Every value set in the file outside PX4's documented range."""
    bad = []
    for value in params.values.values():
        limits = PARAM_RANGES.get(range_key(value.name))
        if limits and not (limits[0] <= value.value <= limits[1]):
            bad.append((value, limits))
    return bad


def frd_from_flu(vector: np.ndarray) -> np.ndarray:
    """A vector in the ROS body frame (x forward, y left, z up) in PX4's FRD."""
    return np.array([vector[0], -vector[1], -vector[2]], dtype=float)


def bearing_deg(x_forward: float, y_right: float) -> float:
    """Bearing in the horizontal plane, degrees clockwise from the nose seen from above."""
    return math.degrees(math.atan2(y_right, x_forward))


def thrust_fraction(u: float, thr_mdl_fac: float) -> float:
    """PX4's thrust model: relative thrust for a relative motor command u (THR_MDL_FAC)."""
    return thr_mdl_fac * u * u + (1.0 - thr_mdl_fac) * u


# ------------------------------------------------------------------ writing

@dataclass
class RotorSpec:
    """What new-package knows about one rotor, in the ROS body frame (FLU, about the COM)."""

    actuator_index: int
    position_flu_m: np.ndarray
    turning_sign: int              # +1 ccw, -1 cw
    moment_constant: float
    max_rot_velocity_rad_s: float
    axis_flu: np.ndarray | None = None   # thrust direction; None: straight up


# The hard ceiling of a SIM_GZ_EC_MIN/MAX value: the mixer keeps output limits as
# uint16_t (PX4-Autopilot src/lib/mixer_module/mixer_module.hpp, _min_value/_max_value),
# and the gz bridge sends the output as the rad/s of the motor command. The 0..1000 of
# gz_bridge module.yaml is only the range QGroundControl offers: PX4's own
# 4006_gz_px4vision airframe sets SIM_GZ_EC_MAX 1100.
GZ_OUTPUT_CEILING = 65535
# The idle (SIM_GZ_EC_MINk) PX4's gz multicopter airframes arm with: 150 rad/s
# (4001_gz_x500, 4006_gz_px4vision), used when it is below the rotor's maximum / 4.
PX4_GZ_IDLE_RAD_S = 150


def px4_idle_rad_s(max_rad_s: float) -> int:
    """PX4's gz idle for a rotor of this top speed: 150 rad/s, or 0 for a rotor so slow
    that 150 would be a quarter of its range or more."""
    return PX4_GZ_IDLE_RAD_S if PX4_GZ_IDLE_RAD_S < max_rad_s / 4 else 0


def _axis_frd(axis_flu) -> np.ndarray | None:
    """The unit thrust axis in FRD, None when it is PX4's default, straight up (0, 0, -1)."""
    if axis_flu is None:
        return None
    axis = frd_from_flu(np.asarray(axis_flu, dtype=float))
    norm = float(np.linalg.norm(axis))
    if not math.isfinite(norm) or norm <= 0:
        return None
    axis = np.round(axis / norm, 9) + 0.0
    return None if np.allclose(axis, UPWARD_FRD, rtol=0, atol=1e-9) else axis


def px4_hover_throttle(omega_hover_rad_s, max_rad_s) -> float:
    """MPC_THR_HOVER for rotors hovering at these speeds, as px4_airframe_text commands
    them (idle px4_idle_rad_s, THR_MDL_FAC 0: u = (ω - MIN) / (MAX - MIN)), averaged, in
    PX4's 0.1..0.8."""
    us = [(w - px4_idle_rad_s(top)) / (round(top) - px4_idle_rad_s(top))
          for w, top in zip(omega_hover_rad_s, max_rad_s)]
    return float(np.clip(np.mean(us), 0.1, 0.8)) if us else 0.5


def px4_airframe_text(name: str, rotors: list[RotorSpec], *, hover_throttle: float,
                      idle_rad_s: float | None = None, world: str | None = None,
                      tool: str = "new-package", simulator: str = "gz") -> str:
    """A PX4 SITL airframe script for the rotors (numbered by actuator index).

    gz: SIM_GZ_EC_MIN/MAX/DIS are integer parameters (PX4 stores them as int32): MAX is
    maxRotVelocity rounded to the nearest integer, MIN PX4's gz idle (px4_idle_rad_s)
    unless `idle_rad_s` is given, DIS 0 (stopped while disarmed, as PX4's default).
    classic (Gazebo Classic, simulator_mavlink): PWM_MAIN_FUNCk outputs and no SIM_GZ
    parameter; the speed range is the model's mavlink interface's.
    """
    order = sorted(rotors, key=lambda r: r.actuator_index)
    max_rad_s = max(r.max_rot_velocity_rad_s for r in order)
    if simulator == "gz" and (not math.isfinite(max_rad_s) or round(max_rad_s) > GZ_OUTPUT_CEILING):
        raise ReedtoolError(f"max_rot_velocity {max_rad_s:g} rad/s is above what PX4 can "
                            f"command through SIM_GZ_EC_MAX (an unsigned 16-bit output, at "
                            f"most {GZ_OUTPUT_CEILING} rad/s)",
                            hint="check maxRotVelocity: it is in rad/s")
    lines = ["#!/bin/sh", "#", f"# @name {name} (generated by reedtool {tool})", "#",
             "# @type Quadrotor" if len(order) == 4 else "# @type Multicopter", "#", "",
             ". ${R}etc/init.d/rc.mc_defaults", "",
             f"PX4_SIMULATOR=${{PX4_SIMULATOR:={'gz' if simulator == 'gz' else 'gazebo-classic'}}}"]
    if world is not None:
        lines.append(f"PX4_GZ_WORLD=${{PX4_GZ_WORLD:={world}}}")
    lines += [f"PX4_SIM_MODEL=${{PX4_SIM_MODEL:={name}}}", ""]
    if simulator == "gz":
        lines += ["param set-default SIM_GZ_EN 1", ""]
    lines += ["param set-default CA_AIRFRAME 0", f"param set-default CA_ROTOR_COUNT {len(order)}", ""]
    for i, rotor in enumerate(order):
        p = np.round(frd_from_flu(rotor.position_flu_m), 9) + 0.0   # no "-0" in the file
        km = rotor.turning_sign * min(abs(rotor.moment_constant), 1.0)
        lines += [f"param set-default CA_ROTOR{i}_PX {p[0]:.6g}",
                  f"param set-default CA_ROTOR{i}_PY {p[1]:.6g}",
                  f"param set-default CA_ROTOR{i}_PZ {p[2]:.6g}",
                  f"param set-default CA_ROTOR{i}_KM {km:.6g}"]
        axis = _axis_frd(rotor.axis_flu)
        if axis is not None:     # PX4's default is (0, 0, -1): up
            lines += [f"param set-default CA_ROTOR{i}_A{c} {v:.6g}" for c, v in zip("XYZ", axis)]
        lines.append("")
    outputs = "SIM_GZ_EC_FUNC" if simulator == "gz" else "PWM_MAIN_FUNC"
    for k, rotor in enumerate(order, start=1):
        lines.append(f"param set-default {outputs}{rotor.actuator_index + 1} "
                     f"{MOTOR_FUNCTION_BASE + k - 1}")
    ranges = [] if simulator != "gz" else [
        ("DIS", lambda r: 0),
        ("MIN", lambda r: round(idle_rad_s) if idle_rad_s is not None
         else px4_idle_rad_s(r.max_rot_velocity_rad_s)),
        ("MAX", lambda r: round(r.max_rot_velocity_rad_s))]
    for tag, value in ranges:
        lines.append("")
        for rotor in order:
            lines.append(f"param set-default SIM_GZ_EC_{tag}{rotor.actuator_index + 1} "
                         f"{value(rotor)}")
    lines += ["", f"param set-default MPC_THR_HOVER {hover_throttle:.2f}",
              "param set-default THR_MDL_FAC 0", ""]
    return "\n".join(lines)
