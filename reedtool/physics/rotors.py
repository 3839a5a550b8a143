"""Rotor discovery: one Rotor type from every way a Gazebo model spins a propeller.

Four families are read:

- RotorS and PX4 gazebo-classic motor models (`gazebo_motor_model`): jointName, linkName,
  turningDirection, motorConstant, ... A `<motorType>` of `position` or `force` (exactly;
  `velocity` is the default) is a servo (RotorS omav's tilt arms), not a rotor.
- gz-sim's MulticopterMotorModel: the same elements, numbered by `<actuator_number>`
  (`<motorNumber>` is its deprecated alias, read when the new one is absent), and
  `<reversible>` motors that may spin both ways (PX4's omnicopter).
- ArduPilot's ArduPilotPlugin: one `<control channel="N">` per servo output. A VELOCITY
  control spinning a rotor joint is a rotor; its spin direction is the sign of
  `<multiplier>` (the joint turns at multiplier x command about its axis), its number
  the channel. Thrust comes from LiftDrag plugins on the blades, so the constants here
  are an estimate from them (`constants_estimated`).

Thrust acts along the rotor link's z axis in the motor-model plugins (for ArduPilot
rotors: along the blades' LiftDrag `<upward>`); that axis in the base frame is the
rotor's thrust axis. Every rotor gets a role: `lift`, or `propulsion` when its thrust is
nearly horizontal on a vehicle that lifts otherwise (a fixed-wing puller, a VTOL pusher).
Discovery never raises on odd input: whatever cannot be read becomes NaN/None and a
rule says what is wrong.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from reedtool.io.fileio import MAX_MAGNITUDE
from reedtool.model import Plugin, Robot, SourceLoc, XmlNode, motor_plugin_family
from reedtool.physics.kinematics import link_poses

ARDUPILOT_PLUGINS = {"ArduPilotPlugin"}        # libArduPilotPlugin.so (classic) and gz
LIFT_DRAG_PLUGINS = {"LiftDragPlugin", "gz-sim-lift-drag-system",
                     "ignition-gazebo-lift-drag-system"}
LIFT_DRAG_NAMES = {"gz::sim::systems::LiftDrag", "ignition::gazebo::systems::LiftDrag"}
# gz-sim's AdvancedLiftDrag (and PX4 classic's libAdvancedLiftDragPlugin.so, which it was
# ported from) models a whole airframe (PX4's advanced_plane): a wing, never a propeller
# blade, so it only tells the roles a wing is there.
ADVANCED_LIFT_DRAG_PLUGINS = {"gz-sim-advanced-lift-drag-system", "AdvancedLiftDragPlugin"}
ADVANCED_LIFT_DRAG_NAMES = {"gz::sim::systems::AdvancedLiftDrag"}

MAVLINK_PLUGINS = {"rotors_gazebo_mavlink_interface", "gazebo_mavlink_interface"}

TURNING_SIGN = {"ccw": 1, "cw": -1}

# A thrust axis further than this from body z is not lifting (the role 'propulsion').
PROPULSION_MIN_ANGLE_DEG = 60.0
# ... and, on a wingless vehicle, within this of body x (a pusher or a puller).
PROPULSION_MAX_OFF_X_DEG = 30.0
# The rotors' axes span every direction when the 3 x n matrix of unit axes has its
# smallest singular value above this fraction of its largest: an omnidirectional frame.
OMNI_MIN_SINGULAR_RATIO = 0.3

# LiftDrag defaults (gz-sim LiftDrag / gazebo-classic LiftDragPlugin) when an element
# is absent.
LIFT_DRAG_DEFAULTS = {"a0": 0.0, "cla": 1.0, "cda": 0.01, "area": 1.0,
                      "air_density": 1.2041, "alpha_stall": 0.5 * math.pi}


@dataclass
class Blade:
    """One LiftDrag plugin on a rotor link, in the rotor link's frame."""

    plugin: Plugin
    cp_m: np.ndarray
    forward: np.ndarray
    upward: np.ndarray
    a0_rad: float
    cla: float
    cda: float
    area_m2: float
    air_density_kg_m3: float
    alpha_stall_rad: float


@dataclass
class Rotor:
    name: str
    joint: str | None
    link: str | None
    position_m: np.ndarray          # rotor link origin in the base frame (NaN if the link is unknown)
    axis: np.ndarray                # unit thrust axis in the base frame
    direction: str                  # as written: 'ccw', 'cw', or anything else (a finding)
    turning_sign: int               # +1 ccw, -1 cw about `axis`, 0 unknown
    motor_number: int | None        # the index the flight stack commands (ArduPilot: channel)
    motor_constant: float           # thrust = motor_constant * omega^2 [N/(rad/s)^2]
    moment_constant: float          # yaw drag torque = moment_constant * thrust [m]
    max_rot_velocity_rad_s: float
    time_constant_up_s: float
    time_constant_down_s: float
    rotor_drag_coefficient: float
    rolling_moment_coefficient: float
    kind: str                       # 'rotors' | 'px4' | 'gz' | 'ardupilot'
    plugin: Plugin
    loc: SourceLoc
    node: XmlNode | None = None     # element holding the parameters (plugin, or <control>)
    number_tag: str = "motorNumber"  # element (or attribute) the number was read from
    direction_tag: str = "turningDirection"
    channel: int | None = None      # ArduPilot: the SDF channel attribute as written (0-based)
    reversible: bool = False        # gz, PX4 classic: may spin (and push) both ways
    role: str = "lift"              # 'lift' | 'propulsion'
    constants_estimated: bool = False  # constants derived from LiftDrag blades, not written
    blades: list[Blade] = field(default_factory=list)
    blade_turning_sign: int = 0     # spin (about `axis`) the blades lift with; 0 unknown/none

    @property
    def max_thrust_N(self) -> float:
        return self.motor_constant * self.max_rot_velocity_rad_s ** 2

    def param(self, tag: str) -> str | None:
        return (self.node if self.node is not None else self.plugin.node).findtext(tag)

    def param_loc(self, tag: str) -> SourceLoc:
        node = self.node if self.node is not None else self.plugin.node
        child = node.find(tag)
        return child.loc if child is not None else node.loc

    @property
    def tilt_deg(self) -> float:
        norm = float(np.linalg.norm(self.axis))
        if not (np.all(np.isfinite(self.axis)) and norm > 0):
            return math.nan
        return math.degrees(math.acos(float(np.clip(self.axis[2] / norm, -1.0, 1.0))))


@dataclass
class RotorCountDeclaration:
    """A rotor count an autopilot interface plugin (MAVLink/PX4) declares."""

    rotor_count: int | None         # None: written, but not a whole number (see `text`)
    plugin: Plugin
    loc: SourceLoc
    text: str = ""                  # as written


def motor_plugin_kind(plugin: Plugin) -> str | None:
    """The rotor family of a motor-model plugin (model.MOTOR_PLUGINS), else None."""
    return motor_plugin_family(plugin.filename, plugin.name)


def is_ardupilot_plugin(plugin: Plugin) -> bool:
    return plugin.library in ARDUPILOT_PLUGINS or (plugin.name or "").endswith("ArduPilotPlugin")


def is_lift_drag_plugin(plugin: Plugin) -> bool:
    return plugin.library in LIFT_DRAG_PLUGINS or (plugin.name or "") in LIFT_DRAG_NAMES


# What every motor-model family (RotorS, PX4 classic, gz-sim MulticopterMotorModel) uses
# when <timeConstantUp>/<timeConstantDown> is not written: its kDefaultTimeConstantUp/Down.
DEFAULT_TIME_CONSTANT_UP_S = 1.0 / 80.0
DEFAULT_TIME_CONSTANT_DOWN_S = 1.0 / 40.0


def _float(text: str | None, absent: float = math.nan) -> float:
    """The number; `absent` when not written (NaN unless the plugin has a default), NaN
    when unreadable, inf beyond any physical quantity (MAX_MAGNITUDE: 1e300 squared
    overflows); R316 names what is not a usable constant."""
    try:
        value = float(text) if text is not None else absent
    except ValueError:
        return math.nan
    return value if not abs(value) > MAX_MAGNITUDE else math.copysign(math.inf, value)


def _int(text: str | None) -> int | None:
    try:
        return int(text.strip()) if text is not None else None
    except ValueError:
        return None


def _vector(text: str | None, default: tuple[float, float, float]) -> np.ndarray:
    if text is None:
        return np.array(default, dtype=float)
    try:
        values = [float(v) for v in text.split()]
    except ValueError:
        return np.full(3, math.nan)
    if len(values) != 3 or not all(abs(v) <= MAX_MAGNITUDE for v in values):
        return np.full(3, math.nan)
    return np.array(values, dtype=float)


def _bool(text: str | None) -> bool:
    return (text or "").strip().lower() in ("1", "true")


def resolve_name(name: str | None, table) -> str | None:
    """`name` as the model spells it: exact, else without leading `model::` scopes, else
    the one entry that ends with `::name` (Gazebo resolves scoped names both ways)."""
    if name is None:
        return None
    name = name.strip()
    if name in table:
        return name
    parts = name.split("::")
    for i in range(1, len(parts)):
        candidate = "::".join(parts[i:])
        if candidate in table:
            return candidate
    matches = [key for key in table if key.endswith("::" + name)]
    return matches[0] if len(matches) == 1 else None


def inertia_about_joint_kg_m2(inertial, axis) -> float:
    """A rotor link's moment of inertia about its joint axis through the link origin (the
    COM tensor plus the parallel-axis term), or NaN where `axis` is no direction."""
    axis = _unit(np.asarray(axis, dtype=float))
    r = np.asarray(inertial.com_m, dtype=float)
    I_link = inertial.inertia_in_link_axes() + inertial.mass_kg * (
        float(r @ r) * np.eye(3) - np.outer(r, r))
    return float(axis @ I_link @ axis) if np.all(np.isfinite(axis)) else math.nan


def _unit(v: np.ndarray) -> np.ndarray:
    norm = float(np.linalg.norm(v))
    return v / norm if np.all(np.isfinite(v)) and norm > 0 else np.full(3, math.nan)


# ------------------------------------------------------------------ discovery

def discover_rotors(robot: Robot) -> list[Rotor]:
    """Every rotor in the model, in the base frame, each with its role."""
    poses = link_poses(robot)
    rotors: list[Rotor] = []
    blades = _blades_by_link(robot)
    for _block, plugin in robot.plugins():
        kind = motor_plugin_kind(plugin)
        if kind is not None:
            rotor = _motor_model_rotor(robot, plugin, kind, poses, len(rotors))
            if rotor is not None:
                rotors.append(rotor)
        elif is_ardupilot_plugin(plugin):
            rotors.extend(_ardupilot_rotors(robot, plugin, poses, blades))
    assign_roles(rotors, has_wing=_has_wing(robot, rotors, blades))
    return rotors


def motor_type(plugin: Plugin, kind: str | None = None) -> str:
    """What a motor plugin runs as: "velocity" (a propeller), "position" or "force" (a servo).

    RotorS' gazebo_motor_model and gz-sim's MulticopterMotorModel compare the trimmed
    word exactly: "position" or "force" is a servo (a tilt arm), not a propeller; any other
    word ("POSITION") leaves their default, a velocity motor, with an error in Gazebo's
    log. PX4 classic's gazebo_motor_model does not read <motorType> at all."""
    kind = kind or motor_plugin_kind(plugin)
    word = (plugin.param("motorType") or "velocity").strip()
    return word if kind != "px4" and word in ("position", "force") else "velocity"


def _motor_model_rotor(robot: Robot, plugin: Plugin, kind: str, poses, index: int):
    if motor_type(plugin, kind) != "velocity":
        return None
    link = plugin.param("linkName")
    joint = plugin.param("jointName")
    if link is None and joint in robot.joint_map:
        link = robot.joint_map[joint].child
    T_base_link = poses.get(link or "")
    if T_base_link is None:
        position, axis = np.full(3, math.nan), np.full(3, math.nan)
    else:
        position, axis = T_base_link[:3, 3].copy(), T_base_link[:3, 2].copy()
    direction = (plugin.param("turningDirection") or "").strip()
    number_tag = "motorNumber"
    if kind == "gz" and (plugin.node.find("actuator_number") is not None
                         or plugin.node.find("motorNumber") is None):
        number_tag = "actuator_number"  # gz's own element; motorNumber is the old alias
    return Rotor(
        name=link or joint or plugin.name or f"rotor{index}",
        joint=joint, link=link, position_m=position, axis=axis,
        direction=direction, turning_sign=TURNING_SIGN.get(direction.lower(), 0),
        motor_number=_int(plugin.param(number_tag)),
        motor_constant=_float(plugin.param("motorConstant")),
        moment_constant=_float(plugin.param("momentConstant")),
        max_rot_velocity_rad_s=_float(plugin.param("maxRotVelocity")),
        time_constant_up_s=_float(plugin.param("timeConstantUp"), DEFAULT_TIME_CONSTANT_UP_S),
        time_constant_down_s=_float(plugin.param("timeConstantDown"),
                                    DEFAULT_TIME_CONSTANT_DOWN_S),
        rotor_drag_coefficient=_float(plugin.param("rotorDragCoefficient")),
        rolling_moment_coefficient=_float(plugin.param("rollingMomentCoefficient")),
        kind=kind, plugin=plugin, loc=plugin.loc, node=plugin.node, number_tag=number_tag,
        reversible=_bool(plugin.param("reversible")))  # gz and PX4 classic read it


def _blades_by_link(robot: Robot) -> dict[str, list[Blade]]:
    out: dict[str, list[Blade]] = {}
    for block, plugin in robot.plugins():
        if not is_lift_drag_plugin(plugin):
            continue
        link = resolve_name(plugin.param("link_name") or block.reference, robot.link_map)
        if link is None:
            continue
        values = {tag: _float(plugin.param(tag)) if plugin.param(tag) is not None else default
                  for tag, default in LIFT_DRAG_DEFAULTS.items()}
        out.setdefault(link, []).append(Blade(
            plugin=plugin, cp_m=_vector(plugin.param("cp"), (0.0, 0.0, 0.0)),
            forward=_vector(plugin.param("forward"), (1.0, 0.0, 0.0)),
            upward=_vector(plugin.param("upward"), (0.0, 0.0, 1.0)),
            a0_rad=values["a0"], cla=values["cla"], cda=values["cda"],
            area_m2=values["area"], air_density_kg_m3=values["air_density"],
            alpha_stall_rad=values["alpha_stall"]))
    return out


def _ardupilot_rotors(robot: Robot, plugin: Plugin, poses, blades) -> list[Rotor]:
    """The VELOCITY controls of an ArduPilotPlugin that spin a rotor."""
    out = []
    controls = plugin.node.findall("control") or plugin.node.findall("rotor")
    for order, control in enumerate(controls):
        control_type = (control.findtext("type") or "VELOCITY").strip()
        if control_type not in ("POSITION", "EFFORT", "COMMAND"):
            control_type = "VELOCITY"  # the plugin's default, also for a type it does not know
        if control_type != "VELOCITY":
            continue  # POSITION/EFFORT/COMMAND: a servo or a relayed command
        channel_text = control.attrib.get("channel", control.attrib.get("id"))
        channel = _int(channel_text) if channel_text is not None else order
        joint_name = resolve_name(control.findtext("jointName"), robot.joint_map)
        joint = robot.joint_map.get(joint_name or "")
        link = joint.child if joint is not None else None
        link_blades = blades.get(link or "", [])
        T_base_link = poses.get(link or "")
        axis_link = _unit(np.asarray(joint.axis, dtype=float)) if joint is not None \
            else np.full(3, math.nan)
        if joint is not None and not link_blades and not _vertical(T_base_link, axis_link):
            continue  # a wheel or another spinning joint: no blades, not a lift axis
        thrust_link = _unit(np.mean([b.upward for b in link_blades], axis=0)) if link_blades \
            else np.array([0.0, 0.0, 1.0])
        if not np.all(np.isfinite(thrust_link)):
            thrust_link = np.array([0.0, 0.0, 1.0])  # blades without a usable <upward>
        if T_base_link is None:
            position, axis = np.full(3, math.nan), np.full(3, math.nan)
        else:
            position, axis = T_base_link[:3, 3].copy(), T_base_link[:3, :3] @ thrust_link
        multiplier = _float(control.findtext("multiplier")) \
            if control.find("multiplier") is not None else 1.0  # the plugin's default
        along = float(np.dot(axis_link, thrust_link))
        sign = int(np.sign(multiplier) * np.sign(along)) if math.isfinite(multiplier) \
            and math.isfinite(along) else 0
        offset = _float(control.findtext("offset")) if control.find("offset") is not None else 0.0
        slowdown = _float(control.findtext("rotorVelocitySlowdownSim")
                          or control.findtext("controlVelocitySlowdownSim") or "1")
        if not (math.isfinite(slowdown) and slowdown > 0):
            slowdown = 1.0  # the plugin ignores a zero slowdown too
        # Commands arrive normalised to [0, 1]; the joint target is multiplier*(cmd+offset).
        omega_max = abs(multiplier) * max(abs(offset), abs(1.0 + offset)) / slowdown
        k_f, k_m, blade_sign = lift_drag_constants(link_blades, axis_link, thrust_link)
        out.append(Rotor(
            name=link or joint_name or f"channel{channel}",
            joint=joint_name or control.findtext("jointName"), link=link,
            position_m=position, axis=axis,
            direction={1: "ccw", -1: "cw"}.get(sign, ""), turning_sign=sign,
            motor_number=channel, motor_constant=k_f, moment_constant=k_m,
            max_rot_velocity_rad_s=omega_max, time_constant_up_s=math.nan,
            time_constant_down_s=math.nan, rotor_drag_coefficient=math.nan,
            rolling_moment_coefficient=math.nan, kind="ardupilot", plugin=plugin,
            loc=control.loc, node=control, number_tag="channel", direction_tag="multiplier",
            channel=channel, constants_estimated=bool(link_blades), blades=link_blades,
            blade_turning_sign=blade_sign))
    return out


def _vertical(T_base_link, axis_link: np.ndarray) -> bool:
    if T_base_link is None or not np.all(np.isfinite(axis_link)):
        return False
    axis = T_base_link[:3, :3] @ axis_link
    return abs(float(axis[2])) >= math.cos(math.radians(PROPULSION_MIN_ANGLE_DEG))


def lift_drag_constants(blades: list[Blade], spin_axis: np.ndarray,
                        thrust_axis: np.ndarray) -> tuple[float, float, int]:
    """(k_f [N/(rad/s)^2], moment constant [m], blade turning sign) from LiftDrag blades.

    In hover without inflow each blade's centre of pressure moves at omega * r (r its
    distance from the spin axis) along `forward` when the rotor turns the way the blade
    is built for, so its angle of attack is a0 and (below stall) its lift
    0.5 * rho * (omega r)^2 * area * cla * a0 along `upward`: k_f is the sum of
    0.5 * rho * r^2 * area * cla * a0 over the blades. Their drag (cda * a0) acting at r
    gives the yaw torque, hence moment constant = sum(drag r) / sum(lift). An estimate:
    real LiftDrag also sees the induced inflow, which lowers the angle of attack.
    The sign is the spin about `thrust_axis` (+1 ccw) that moves the blades along
    `forward`; 0 when there are no blades or they disagree.
    """
    if not blades or not np.all(np.isfinite(spin_axis)):
        return math.nan, math.nan, 0
    k_f = k_drag = 0.0
    signs = set()
    for blade in blades:
        tangent = np.cross(spin_axis, blade.cp_m)       # velocity direction of +spin
        r_m = float(np.linalg.norm(tangent))
        along_forward = float(np.dot(tangent, _unit(blade.forward)))
        if not (math.isfinite(r_m) and r_m > 0 and math.isfinite(along_forward)):
            return math.nan, math.nan, 0
        signs.add(int(np.sign(along_forward)))
        alpha = blade.a0_rad
        cl = blade.cla * alpha if abs(alpha) <= blade.alpha_stall_rad else math.nan
        q_per_w2 = 0.5 * blade.air_density_kg_m3 * r_m ** 2 * blade.area_m2
        k_f += q_per_w2 * cl * float(np.dot(_unit(blade.upward), thrust_axis))
        k_drag += q_per_w2 * abs(blade.cda * alpha) * r_m
    about_joint = signs.pop() if len(signs) == 1 else 0
    along = float(np.dot(spin_axis, thrust_axis))
    sign = int(about_joint * np.sign(along)) if math.isfinite(along) else 0
    return k_f, (k_drag / k_f if k_f > 0 else math.nan), sign


# ---------------------------------------------------------------------- roles

def assign_roles(rotors: list[Rotor], has_wing: bool = False) -> None:
    """Mark pushers and pullers as propulsion (see the module docstring).

    Propulsion: a thrust axis between 60° and 120° from body z (horizontal or nearly; a
    rotor pointing down stays 'lift' so the tilt rule can say it points down) on a
    vehicle that lifts otherwise, and either along body ±x (within 30°: a pusher or a
    puller) or on a vehicle with a wing (a LiftDrag surface not on a rotor, or an
    AdvancedLiftDrag airframe; frames such as ardupilot_gazebo's zephyr fly along their
    y axis). A sideways rotor on a wingless
    multirotor is a mistake, not propulsion: it stays 'lift' and R311 reports it. An
    omnidirectional frame (reversible motors, or axes spanning every direction) keeps
    every rotor as lift: it hovers with all of them through the 6-DoF allocation. A
    vehicle whose rotors are all horizontal is a fixed-wing aircraft only with a wing.
    """
    if is_omnidirectional(rotors):
        return
    cos_max = math.cos(math.radians(PROPULSION_MIN_ANGLE_DEG))
    cos_along_x = math.cos(math.radians(PROPULSION_MAX_OFF_X_DEG))
    horizontal = [r for r in rotors if np.all(np.isfinite(_unit(r.axis)))
                  and abs(float(_unit(r.axis)[2])) < cos_max]
    if len(horizontal) == len(rotors) and not has_wing:
        return
    for rotor in horizontal:
        if has_wing or abs(float(_unit(rotor.axis)[0])) >= cos_along_x:
            rotor.role = "propulsion"


def is_omnidirectional(rotors: list[Rotor]) -> bool:
    """Reversible motors, or thrust axes that span every direction (3 x n well conditioned)."""
    if any(r.reversible for r in rotors):
        return True
    axes = [_unit(r.axis) for r in rotors]
    axes = [a for a in axes if np.all(np.isfinite(a))]
    if len(axes) < 6:
        return False
    singular = np.linalg.svd(np.array(axes).T, compute_uv=False)
    return bool(singular[-1] > OMNI_MIN_SINGULAR_RATIO * singular[0])


def lift_rotors(rotors: list[Rotor]) -> list[Rotor]:
    return [r for r in rotors if r.role == "lift"]


def _has_wing(robot: Robot, rotors: list[Rotor], blades: dict[str, list[Blade]]) -> bool:
    rotor_links = {r.link for r in rotors}
    if any(link not in rotor_links for link in blades):
        return True
    return any(plugin.library in ADVANCED_LIFT_DRAG_PLUGINS
               or (plugin.name or "") in ADVANCED_LIFT_DRAG_NAMES
               for _, plugin in robot.plugins())


def rotor_table(rotors: list[Rotor]) -> list[dict]:
    """Every rotor as a JSON-ready row: number, role, geometry, constants (and whether
    they are estimated), in discovery order."""
    def number(v):
        return float(v) if math.isfinite(v) else None

    return [{"name": r.name, "kind": r.kind, "role": r.role, "motor_number": r.motor_number,
             "number_from": r.number_tag, "channel": r.channel, "direction": r.direction,
             "reversible": r.reversible,
             "position_m": [number(v) for v in r.position_m],
             "axis": [number(v) for v in r.axis],
             "motor_constant": number(r.motor_constant),
             "moment_constant": number(r.moment_constant),
             "max_rot_velocity_rad_s": number(r.max_rot_velocity_rad_s),
             "constants_estimated": r.constants_estimated} for r in rotors]


def declared_rotor_counts(robot: Robot) -> list[RotorCountDeclaration]:
    """Rotor counts declared by MAVLink/PX4 interface plugins: an explicit
    <rotorCount>/<rotor_count> (RotorS's interface sends that many motor commands).

    PX4 classic's control channels declare no count: a channel no motor reads is an unused
    output (the MRS models list eight for every frame, PX4's iris template channels for
    another model's joints), and a motor that no channel fills is R302's finding.
    """
    out = []
    for _block, plugin in robot.plugins():
        declared = _rotor_count_node(plugin)
        if declared is not None:
            _tag, node, text = declared
            count = int(text) if text.isdigit() else None
            out.append(RotorCountDeclaration(count, plugin, node.loc, text))
    return out


def _rotor_count_node(plugin):
    """(tag, element, text) of an autopilot interface's <rotorCount>/<rotor_count>, or
    None when the plugin is no such interface or declares no count."""
    if plugin.library not in MAVLINK_PLUGINS:
        return None
    for tag in ("rotorCount", "rotor_count"):
        node = plugin.node.find(tag)
        if node is not None:
            return tag, node, (node.text or "").strip()
    return None


@dataclass
class CommandVector:
    """The motor command indices an autopilot interface plugin fills (a motor plugin reads
    the entry of its own number), or None when the model says nothing about them."""

    indices: set[int]
    what: str                       # how they are declared, for messages
    loc: SourceLoc | None
    sender: str = "the autopilot interface fills"   # who fills them, for messages


def command_vector(robot: Robot) -> CommandVector | None:
    """RotorS's interface sends `rotor_count` commands (indices 0..count-1); PX4 classic's
    gazebo_mavlink_interface fills entry `input_index` of each velocity control channel. Without such
    a plugin (gz-sim, where PX4's gz bridge or another node sends the commands) None."""
    for _block, plugin in robot.plugins():
        if plugin.library not in MAVLINK_PLUGINS:
            continue
        declared = _rotor_count_node(plugin)
        if declared is not None:
            tag, node, text = declared
            if not text.isdigit():
                return None                     # R312 reports the count itself
            return CommandVector(set(range(int(text))), f"<{tag}> {text}", node.loc)
        channels = plugin.node.find("control_channels")
        if channels is not None:
            # Every channel's entry is published, but only a velocity channel's is a
            # speed: a motor on a servo channel's entry spins with a surface's angle.
            indices = set()
            for channel in channels.findall("channel"):
                index = channel.find("input_index")
                kind = channel.find("joint_control_type")
                text = (index.text or "").strip() if index is not None else ""
                if text.isdigit() and (kind is None or (kind.text or "").strip() == "velocity"):
                    indices.add(int(text))
            if indices:
                return CommandVector(indices, "the input_index of its velocity control "
                                              "channels", channels.loc)
    return None


# The motor plugins that read their command as entry `motorNumber` of the vector the
# controller publishes, whoever publishes it: RotorS' gazebo_motor_model.cpp and its PX4
# classic copy (`angular_velocities(motor_number_)`, an index beyond the vector's size is
# refused with "You tried to access index ..." and the motor keeps its last command, none).
INDEXED_MOTOR_KINDS = ("rotors", "px4")


def controller_command_vector(rotors) -> CommandVector | None:
    """Without an autopilot interface, what the controller sends RotorS-style motors: one
    entry per rotor (RotorS' controllers publish `rotor_configuration`'s count, 0..n-1),
    so a motor numbered beyond n-1 never receives a command. None when any rotor is of
    another family (gz-sim: the flight stack's outputs, compared by --airframe)."""
    rotors = list(rotors)
    if not rotors or any(r.kind not in INDEXED_MOTOR_KINDS for r in rotors):
        return None
    count = len(rotors)
    return CommandVector(set(range(count)), f"one per rotor, {count} rotors", None,
                         sender="the controller sends")


# ------------------------------------------------- ArduPilot motor response

@dataclass
class DerivedTimeConstant:
    """A motor time constant derived from an ArduPilotPlugin velocity PID (or why not)."""
    time_constant_s: float          # nan when it cannot be derived
    explanation: str                # how it was derived, or why it was not


def ardupilot_time_constant(robot: Robot, rotor: Rotor) -> DerivedTimeConstant:
    """The rotor's speed response under the ArduPilotPlugin's joint velocity PID.

    With `useForce` (the default) the plugin applies the joint torque
    PID(joint speed - target) every step, gz::math::PID giving -(p*e + i*∫e + d*de/dt)
    clamped to [cmd_min, cmd_max]. For a P or PD controller (i_gain 0) the joint obeys
    (I + d) * de/dt = -p * e, a first-order lag with tau = (I + d) / p, I the rotor
    link's moment of inertia about the joint axis. That holds while p*|e| <= cmd_max;
    beyond it the torque saturates and the speed ramps at cmd_max / I (a larger step
    takes longer than tau says). Aerodynamic drag torque from the blades is left out, and
    so is joint damping b (it would give I / (p + b); ardupilot_gazebo's iris has
    b = 1e-4 against p = 0.2, a 0.05 % change).
    An integral term makes the response second order, and `useForce` false sets the
    joint speed directly: neither has one time constant, so none is derived.
    """
    def gain(tag: str, default: float) -> float:
        text = rotor.param(tag)
        return _float(text) if text is not None else default

    # Defaults as the plugin's Control constructor: PID(0.1, 0, 0, ..., 1.0, -1.0).
    p, i, d = gain("p_gain", 0.1), gain("i_gain", 0.0), gain("d_gain", 0.0)
    cmd_max = gain("cmd_max", 1.0)
    use_force = (rotor.param("useForce") or "1").strip().lower() not in ("0", "false")
    joint = robot.joint_map.get(rotor.joint or "")
    link = robot.link_map.get(rotor.link or "")
    if not use_force:
        return DerivedTimeConstant(math.nan, "<useForce> is off: the plugin sets the joint "
                                             "speed directly, with no motor lag to derive")
    if not (math.isfinite(p) and p > 0 and math.isfinite(d) and d >= 0):
        return DerivedTimeConstant(math.nan, f"the velocity PID's p_gain {p:g} (d_gain {d:g}) "
                                             "gives no first-order response")
    if not (math.isfinite(i) and i == 0):
        return DerivedTimeConstant(math.nan, f"the velocity PID has an integral term "
                                             f"(i_gain {i:g}): its response is second order")
    if joint is None or link is None or link.inertial is None:
        return DerivedTimeConstant(math.nan, "the rotor joint or its link's <inertial> is "
                                             "missing")
    I_axis = inertia_about_joint_kg_m2(link.inertial, joint.axis)
    if not (math.isfinite(I_axis) and I_axis > 0):
        return DerivedTimeConstant(math.nan, "the rotor link has no positive moment of "
                                             "inertia about its joint axis")
    tau = (I_axis + d) / p
    limit = f"; linear while the speed error stays below cmd_max/p_gain = {cmd_max / p:.4g} " \
            "rad/s" if math.isfinite(cmd_max) and cmd_max > 0 else ""
    return DerivedTimeConstant(tau, (
        f"motor time constant {tau:.4g} s derived from the ArduPilotPlugin velocity PID: "
        f"(I_axis {I_axis:.4g} kg·m² + d_gain {d:g}) / p_gain {p:g}{limit}"))
