"""ArduPilot SITL on Gazebo Sim: the ArduPilotPlugin block, its LiftDrag blades and the .parm.

In the shape of ardupilot_gazebo's iris_with_ardupilot (read, not copied): ArduPilot's
plugin turns each rotor joint with a velocity PID (`<control channel="N">`, type VELOCITY,
`useForce` 1, `multiplier` = the top speed whose sign is the spin), an ApplyJointForce
system per joint, and two gz-sim LiftDrag blades per rotor make the thrust and the drag
torque. The blades are sized so that, in hover without inflow, they give exactly the motor
model's constants (physics.rotors.lift_drag_constants reads them back):

    thrust = 2 * 0.5 rho r^2 area cla a0 * w^2   ->  area = k_f / (rho r^2 cla a0)
    torque / thrust = cda r / cla                ->  cda  = k_m cla / r

with r = 0.7 of the propeller radius (ardupilot_gazebo's iris: cp 0.084 m on 0.12 m
blades), a0 0.3 rad and cla 4.25 as that model sets them. The PID has one time constant,
tau = I_axis / p_gain (physics.rotors.ardupilot_time_constant): p_gain = I_axis / tau_up;
cmd_max = p_gain * top speed keeps it linear over the whole speed range.

Channel N is the flight stack's output N+1; the .parm's SERVO(N+1)_FUNCTION names the
AP_MotorsMatrix motor at that rotor's bearing with its spin (flightstack.ardupilot
.match_frame), so `validate --autopilot-params` reads the same rotors from both sides.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from reedtool.errors import ReedtoolError
from reedtool.io.xml_numbers import float_text
from reedtool.port.gz_port import Element, GzPort

ARDUPILOT_PLUGIN = ("ArduPilotPlugin", "ArduPilotPlugin")
LIFT_DRAG = ("gz-sim-lift-drag-system", "gz::sim::systems::LiftDrag")
APPLY_JOINT_FORCE = ("gz-sim-apply-joint-force-system", "gz::sim::systems::ApplyJointForce")
# ardupilot_gazebo iris_with_ardupilot's blades.
BLADE_A0_RAD = 0.3
BLADE_CLA = 4.25
BLADE_ALPHA_STALL_RAD = 1.4
BLADE_CLA_STALL = -0.025
AIR_DENSITY_KG_M3 = 1.2041
BLADE_CP_FRACTION = 0.7          # centre of pressure at 70 % of the propeller radius
DEFAULT_PROP_RADIUS_M = 0.1      # when the rotor link has no cylinder to read it from
# A rotor is at an AP motor's place within this bearing: what validate's C432 accepts (the
# mixer's roll and pitch signs survive it); an iris-shaped quad's 59° arms fly QUAD/X's 45°.
AP_BEARING_TOL_DEG = 20.0


@dataclass
class ApRotor:
    """One rotor as ArduPilot drives it."""

    joint: str
    link: str
    channel: int                   # 0-based: flight-stack output channel + 1
    turning_sign: int              # +1 ccw about the thrust axis (seen from above)
    position_com_flu_m: np.ndarray  # about the whole vehicle's COM, body FLU
    joint_axis_link: np.ndarray    # the joint axis in the rotor link's frame
    thrust_axis_link: np.ndarray   # thrust direction in the rotor link's frame
    motor_constant: float          # [N/(rad/s)^2]
    moment_constant: float         # [m]
    max_rot_velocity_rad_s: float
    prop_radius_m: float
    inertia_axis_kg_m2: float      # rotor link about its joint axis
    time_constant_s: float


def _unit(v) -> np.ndarray:
    v = np.asarray(v, dtype=float)
    return v / np.linalg.norm(v)


def _vec(v) -> str:
    return " ".join(float_text(x) for x in v)


def frame_match(rotors: list[ApRotor]) -> tuple[int, int, dict[int, int]]:
    """(FRAME_CLASS, FRAME_TYPE, {1-based output: AP motor number})."""
    from reedtool.flightstack.ardupilot import match_frame
    from reedtool.flightstack.px4 import bearing_deg, frd_from_flu

    bearings = [bearing_deg(*frd_from_flu(r.position_com_flu_m)[:2]) for r in rotors]
    found = match_frame(bearings, [r.turning_sign for r in rotors], AP_BEARING_TOL_DEG)
    if found is None:
        layout = ", ".join(f"{b:.0f}° {'ccw' if r.turning_sign > 0 else 'cw'}"
                           for b, r in zip(bearings, rotors))
        raise ReedtoolError(f"no ArduPilot frame has this rotor layout ({layout})",
                            hint="ArduPilot flies the AP_MotorsMatrix frames; use --autopilot "
                                 "px4 or none")
    frame_class, frame_type, motors = found
    return frame_class, frame_type, {r.channel + 1: m for r, m in zip(rotors, motors)}


def blades(rotor: ApRotor, multiplier_sign: int) -> list[Element]:
    """Two LiftDrag blades on opposite sides of the hub, sized to the rotor's constants."""
    axis = _unit(rotor.joint_axis_link)
    thrust = _unit(rotor.thrust_axis_link)
    x = np.array([1.0, 0.0, 0.0]) if abs(axis[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    e1 = _unit(x - float(x @ axis) * axis)
    r = BLADE_CP_FRACTION * rotor.prop_radius_m
    area = rotor.motor_constant / (AIR_DENSITY_KG_M3 * r * r * BLADE_CLA * BLADE_A0_RAD)
    cda = rotor.moment_constant * BLADE_CLA / r
    out = []
    for side in (1.0, -1.0):
        cp = side * r * e1
        # Where the blade moves when the joint turns the way the multiplier drives it.
        forward = multiplier_sign * _unit(np.cross(axis, cp))
        plugin = Element("plugin", {"filename": LIFT_DRAG[0], "name": LIFT_DRAG[1]})
        for tag, value in (("a0", float_text(BLADE_A0_RAD)), ("alpha_stall", float_text(BLADE_ALPHA_STALL_RAD)),
                           ("cla", float_text(BLADE_CLA)), ("cda", float_text(cda)), ("cma", "0"),
                           ("cla_stall", float_text(BLADE_CLA_STALL)), ("cda_stall", "0"),
                           ("cma_stall", "0"), ("area", float_text(area)),
                           ("air_density", float_text(AIR_DENSITY_KG_M3)), ("cp", _vec(cp)),
                           ("forward", _vec(forward)), ("upward", _vec(thrust)),
                           ("link_name", rotor.link)):
            plugin.add(tag, value)
        out.append(plugin)
    return out


def control(rotor: ApRotor) -> tuple[Element, int]:
    """The rotor's <control channel="N"> and the sign of its multiplier."""
    along = float(_unit(rotor.joint_axis_link) @ _unit(rotor.thrust_axis_link))
    if abs(along) < 1e-9:
        raise ReedtoolError(f"rotor joint '{rotor.joint}' turns about an axis across its thrust",
                            hint="the rotor joint axis must be the propeller's spin axis")
    sign = int(rotor.turning_sign * np.sign(along))
    p_gain = rotor.inertia_axis_kg_m2 / rotor.time_constant_s
    node = Element("control", {"channel": str(rotor.channel)})
    for tag, value in (("jointName", rotor.joint), ("useForce", "1"),
                       ("multiplier", float_text(sign * rotor.max_rot_velocity_rad_s)),
                       ("offset", "0"), ("servo_min", "1100"), ("servo_max", "1900"),
                       ("type", "VELOCITY"), ("p_gain", float_text(p_gain)), ("i_gain", "0"),
                       ("d_gain", "0"), ("i_max", "0"), ("i_min", "0"),
                       ("cmd_max", float_text(p_gain * rotor.max_rot_velocity_rad_s)),
                       ("cmd_min", float_text(-p_gain * rotor.max_rot_velocity_rad_s)),
                       ("controlVelocitySlowdownSim", "1")):
        node.add(tag, value)
    return node, sign


def ardupilot_elements(rotors: list[ApRotor], imu_name: str) -> tuple[list[Element],
                                                                      dict[str, Element]]:
    """The model's plugins (blades, ApplyJointForce per joint, ArduPilotPlugin) and each
    rotor joint's <control>."""
    plugin = Element("plugin", {"name": ARDUPILOT_PLUGIN[1], "filename": ARDUPILOT_PLUGIN[0]})
    for tag, value in (("fdm_addr", "127.0.0.1"), ("fdm_port_in", "9002"),
                       ("connectionTimeoutMaxCount", "5"), ("lock_step", "1")):
        plugin.add(tag, value)
    # Model FLU -> ArduPilot's body FRD, and gz's ENU world -> NED (iris_with_ardupilot).
    plugin.add("modelXYZToAirplaneXForwardZDown", "0 0 0 180 0 0", degrees="true")
    plugin.add("gazeboXYZToNED", "0 0 0 180 0 90", degrees="true")
    plugin.add("imuName", imu_name)
    out, controls = [], {}
    for rotor in sorted(rotors, key=lambda r: r.channel):
        node, sign = control(rotor)
        plugin.children.append(node)
        controls[rotor.joint] = node
        out += blades(rotor, sign)
        joint_force = Element("plugin", {"filename": APPLY_JOINT_FORCE[0],
                                         "name": APPLY_JOINT_FORCE[1]})
        joint_force.add("joint_name", rotor.joint)
        out.append(joint_force)
    out.append(plugin)
    return out, controls


# ------------------------------------------------------------------ a port's rotors

def _prop_radius_m(link) -> float:
    from reedtool.model import Cylinder

    for shape in [*link.collisions, *link.visuals]:
        if isinstance(shape.geometry, Cylinder) and shape.geometry.radius_m > 0:
            return float(shape.geometry.radius_m)
    return DEFAULT_PROP_RADIUS_M


def ardupilot_port(robot, port: GzPort) -> tuple[list[Element], str]:
    """migrate --autopilot ardupilot: the plugins to add to the port and the .parm text.
    Each velocity motor plugin of the source becomes an ArduPilot rotor (port.ardupilot_rotors)."""
    from reedtool.flightstack.ardupilot import parm_text
    from reedtool.physics.pinocchio_bridge import whole_robot_pinocchio
    from reedtool.physics.rotors import discover_rotors, inertia_about_joint_kg_m2

    props = whole_robot_pinocchio(robot)
    by_plugin = {id(r.plugin): r for r in discover_rotors(robot)}
    rotors, rows = [], {}
    for plugin, row in port.ardupilot_rotors:
        rotor = by_plugin.get(id(plugin))
        joint = robot.joint_map.get(rotor.joint or "") if rotor else None
        link = robot.link_map.get(rotor.link or "") if rotor else None
        if rotor is None or joint is None or link is None or link.inertial is None \
                or rotor.motor_number is None or rotor.turning_sign == 0 \
                or rotor.role != "lift":
            raise ReedtoolError(f"{row.element}: ArduPilot needs a lift rotor with a joint, a "
                                "link with <inertial>, a motorNumber and a spin direction",
                                file=plugin.loc.file, line=plugin.loc.line,
                                hint="`reedtool validate` says what is missing")
        tau = rotor.time_constant_up_s
        if not (math.isfinite(tau) and tau > 0):
            raise ReedtoolError(f"{row.element}: no timeConstantUp to set ArduPilot's joint "
                                "PID from", file=plugin.loc.file, line=plugin.loc.line)
        rotors.append(ApRotor(
            joint=rotor.joint, link=rotor.link, channel=rotor.motor_number,
            turning_sign=rotor.turning_sign, position_com_flu_m=rotor.position_m - props.com_m,
            joint_axis_link=np.asarray(joint.axis, dtype=float),
            thrust_axis_link=np.array([0.0, 0.0, 1.0]),   # the motor models' thrust axis
            motor_constant=rotor.motor_constant, moment_constant=rotor.moment_constant,
            max_rot_velocity_rad_s=rotor.max_rot_velocity_rad_s,
            prop_radius_m=_prop_radius_m(link),
            inertia_axis_kg_m2=inertia_about_joint_kg_m2(link.inertial, joint.axis),
            time_constant_s=tau))
        rows[rotor.joint] = row
    frame_class, frame_type, outputs = frame_match(rotors)
    plugins, controls = ardupilot_elements(rotors, _imu_name(port))
    for joint, row in rows.items():
        row.target = controls[joint]
    return plugins, parm_text(port.name, frame_class, frame_type, outputs).replace(
        "generated by reedtool new-package", "generated by reedtool migrate")


def _imu_name(port: GzPort) -> str:
    """`link::sensor` of the port's first IMU, adding one on the root link if it has none
    (ArduPilotPlugin needs an IMU)."""
    for link in port.links:
        for sensor in link.sensors:
            if sensor.attrib.get("type") == "imu":
                return f"{link.name}::{sensor.attrib['name']}"
    root = port.links[0]
    sensor = Element("sensor", {"name": "imu_sensor", "type": "imu"})
    sensor.add("always_on", "true")
    sensor.add("update_rate", "1000")
    port.add_sensor(root, sensor, "ArduPilotPlugin reads an IMU and the model has none: "
                                  "one added on the root link")
    return f"{root.name}::imu_sensor"
