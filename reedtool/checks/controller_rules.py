"""Controller cross-check rules (C4xx): what the controller is told matches the motors.

A multirotor's geometry is often written twice: once in the motor plugins (where the
simulator applies thrust) and once in the controller's rotor table (what the controller
believes when it allocates thrust). They drift apart silently. These rules compare every
controller table reedtool can see (reedtool.flightstack.controller_tables: gz-sim
MulticopterVelocityControl in the model, RotorS vehicle YAML files from `--controller`)
with the discovered rotors and the whole-robot mass properties.

Matching: a velocity-control entry names its joint, so it is matched by `jointName`. A
RotorS YAML entry i is what the controller sends as motor speed i, which the motor plugin
with `<motorNumber>i` receives, so it is matched by motor number (by discovery order when
the motor numbers are not 0..n-1, which R302 reports). Geometry for a YAML entry is taken
in the base (root link) axes, about the whole robot's centre of mass: RotorS controllers
work in the body axes of the odometry (the base link), and their allocation's torques are
torques about the point the angles and arms are measured from, which must be the point
the body turns about. (With the COM at the base origin, as in RotorS' own models, the two
are the same; with the COM 15 mm off it, angles from the base origin leave RotorS' Lee
controller, which has no integral term, hovering tens of centimetres off its setpoint:
tests/test_lee_controller.py flies both.) Every finding names both places: the controller entry (its file and line
is the finding's location) and the model element (in the message).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Iterator

import numpy as np

from reedtool.checks.context import CheckContext
from reedtool.checks.finding import Issue
from reedtool.checks.registry import rule

if TYPE_CHECKING:
    from reedtool.flightstack.controller_tables import ControllerRotor, ControllerTable
    from reedtool.physics.rotors import Rotor

ANGLE_TOL_RAD = math.radians(0.5)
ARM_LENGTH_ABS_TOL_M = 0.001
ARM_LENGTH_REL_TOL = 0.01
CONSTANT_REL_TOL = 0.01
MASS_REL_TOL = 0.01
# Per tensor element, relative to that diagonal moment (off-diagonal: to the largest one).
INERTIA_REL_TOL = 0.10
DIRECTION_NAME = {1: "ccw", -1: "cw"}


# --------------------------------------------------------------- helpers

def _tables(ctx: CheckContext) -> list["ControllerTable"]:
    return ctx.controller_tables if ctx.tree_ok else []


def _wrap(angle_rad: float) -> float:
    return (angle_rad + math.pi) % (2.0 * math.pi) - math.pi


def _deg(angle_rad: float) -> str:
    return f"{math.degrees(angle_rad):.2f}°"


def _motor_index(ctx: CheckContext) -> dict[int, "Rotor"]:
    """Actuator index -> rotor: motorNumber when they are 0..n-1, else discovery order."""
    rotors = ctx.rotors
    numbers = [r.motor_number for r in rotors]
    if None not in numbers and sorted(numbers) == list(range(len(rotors))):
        return {r.motor_number: r for r in rotors}
    return dict(enumerate(rotors))


def _pairs(ctx: CheckContext, table: "ControllerTable") -> list[tuple["ControllerRotor", "Rotor"]]:
    if table.source == "velocity-control":
        by_joint = {r.joint: r for r in ctx.rotors if r.joint}
        return [(e, by_joint[e.joint_name]) for e in table.rotors if e.joint_name in by_joint]
    by_index = _motor_index(ctx)
    return [(e, by_index[e.index]) for e in table.rotors if e.index in by_index]


def _rotor_name(rotor: "Rotor") -> str:
    number = f"motor {rotor.motor_number}" if rotor.motor_number is not None else "motor"
    return f"{number} ('{rotor.joint or rotor.link}')"


def _geometry_loc(ctx: CheckContext, rotor: "Rotor"):
    """Where the rotor's position is written: its joint's pose/origin, else the plugin."""
    joint = ctx.robot.joint_map.get(rotor.joint or "")
    if joint is None and rotor.link:
        joint = ctx.parent_joint(rotor.link)
    if joint is not None:
        return joint.origin_loc or joint.loc
    return rotor.loc


def _com_xy(ctx: CheckContext) -> np.ndarray:
    """The whole robot's COM in the base xy-plane (0 when it cannot be computed)."""
    com = np.asarray(ctx.whole_robot.com_m, dtype=float)[:2]
    return com if ctx.whole_robot.mass_kg > 0 and np.all(np.isfinite(com)) else np.zeros(2)


def _planar(rotor: "Rotor", com_xy: np.ndarray) -> tuple[float, float] | None:
    """(angle from +x towards +y [rad], arm length in the xy-plane [m]) about the COM,
    base axes."""
    p = rotor.position_m
    if not np.all(np.isfinite(p)):
        return None
    x, y = p[0] - com_xy[0], p[1] - com_xy[1]
    return math.atan2(y, x), math.hypot(x, y)


def _about(com_xy: np.ndarray) -> str:
    if not np.any(np.abs(com_xy) >= 5e-4):
        return ""
    return (f", measured from the centre of mass at ({1000 * com_xy[0]:.1f}, "
            f"{1000 * com_xy[1]:.1f}) mm of the base origin")


def _entry(table: "ControllerTable", entry: "ControllerRotor") -> str:
    if table.source == "yaml":
        return f"{table.label} rotor_configuration/{entry.index}"
    return f"{table.label} rotor {entry.index} ('{entry.joint_name}')"


def _relative_gap(a: float, b: float) -> float:
    return abs(a - b) / max(abs(b), 1e-300)


# --------------------------------------------------------------- table shape

@rule("C401", "controller-rotor-count", "error",
      "A controller rotor table has a different number of rotors than the model.", clause="flight-stack")
def controller_rotor_count(ctx: CheckContext) -> Iterator[Issue]:
    """The controller's allocation matrix has one column per table entry and it sends that
    many motor speeds. With fewer entries than motors, some motors never receive a
    command; with more, the controller allocates thrust to rotors that do not exist.
    Either way the vehicle cannot hover level.

    Severity (error, flight-stack): the controller commands another number of rotors
    than the model has.
    """
    rotors = ctx.rotors
    for table in _tables(ctx):
        if len(table.rotors) != len(rotors):
            where = ", ".join(str(r.loc) for r in rotors[:6]) or "none found"
            yield Issue(f"{table.label} lists {len(table.rotors)} rotor(s) ({table.loc}), the "
                        f"model has {len(rotors)} motor plugin(s) ({where})", table.loc,
                        table.label, hint="give the controller one entry per motor plugin")


@rule("C402", "controller-rotor-joint-unknown", "error",
      "A velocity-control rotor names a joint that has no motor plugin.", clause="flight-stack")
def controller_rotor_joint_unknown(ctx: CheckContext) -> Iterator[Issue]:
    """gz-sim's MulticopterVelocityControl finds each rotor by `<jointName>` and computes
    its arm from that joint's pose. A joint that does not exist makes gz-sim skip the
    rotor (and the allocation loses a column); a joint without a MulticopterMotorModel
    gets commands no motor turns into thrust.

    Severity (error, flight-stack): the controller commands a motor the model does not
    have.
    """
    motor_joints = {r.joint for r in ctx.rotors if r.joint}
    for table in _tables(ctx):
        if table.source != "velocity-control":
            continue
        for entry in table.rotors:
            if entry.joint_name is None or entry.joint_name in motor_joints:
                continue
            loc = entry.loc_of("joint_name")
            if entry.joint_name not in ctx.robot.joint_map:
                import difflib

                close = difflib.get_close_matches(entry.joint_name, sorted(motor_joints), n=1)
                yield Issue(f"{_entry(table, entry)} names joint '{entry.joint_name}', which "
                            "does not exist", loc, entry.joint_name,
                            hint=f"did you mean '{close[0]}'?" if close else
                            "name the joint of a rotor's motor plugin")
            else:
                joint = ctx.robot.joint_map[entry.joint_name]
                yield Issue(f"{_entry(table, entry)} names joint '{entry.joint_name}' "
                            f"({joint.loc}), which no motor plugin drives", loc, entry.joint_name,
                            hint="name the <jointName> of a MulticopterMotorModel")


@rule("C403", "controller-rotor-order", "error",
      "A velocity-control rotor's position in the table is not its motor number.", clause="flight-stack")
def controller_rotor_order(ctx: CheckContext) -> Iterator[Issue]:
    """The controller publishes one speed per table entry, in table order; the motor plugin
    with `<motorNumber>k` spins at speed k. Entry i must therefore name the joint of the
    motor whose motorNumber is i, or every speed goes to the wrong rotor.

    Severity (error, flight-stack): the controller commands the wrong motor.
    """
    for table in _tables(ctx):
        if table.source != "velocity-control":
            continue
        for entry, rotor in _pairs(ctx, table):
            if rotor.motor_number is not None and rotor.motor_number != entry.index:
                yield Issue(f"{_entry(table, entry)} is entry {entry.index}, but the motor on "
                            f"'{entry.joint_name}' has {rotor.number_tag} {rotor.motor_number} "
                            f"({rotor.param_loc(rotor.number_tag)}); speed {entry.index} "
                            "drives another rotor", entry.loc, entry.joint_name,
                            hint=f"order the <rotor> entries by {rotor.number_tag} 0, 1, 2, ...")


@rule("C411", "controller-entry-invalid", "error",
      "A controller table entry is missing a value or cannot be read.", clause="refused")
def controller_entry_invalid(ctx: CheckContext) -> Iterator[Issue]:
    """Every entry needs all of its values: jointName, forceConstant, momentConstant and
    direction for gz-sim (which skips an incomplete rotor), and angle, arm_length,
    rotor_force_constant, rotor_moment_constant and direction for RotorS (which keeps its
    default for a missing one). RotorS reads rotor_configuration '0', '1', ... and stops at
    the first missing index, so entries after a gap are never read. Directions are +1 or -1.

    Severity (error, refused): the controller cannot read its table and does not start.
    """
    for table in ctx.controller_tables:
        for message, loc in table.problems:
            yield Issue(f"{table.label}: {message}", loc, table.label)
        for entry in table.rotors:
            if math.isfinite(entry.direction) and entry.direction not in (1.0, -1.0):
                yield Issue(f"{_entry(table, entry)}: direction {entry.direction:g} is not +1 "
                            "(ccw) or -1 (cw)", entry.loc_of("direction"), table.label,
                            hint="use 1 for a counter-clockwise rotor, -1 for clockwise")


@rule("C412", "controller-com-link-missing", "error",
      "MulticopterVelocityControl's comLinkName is missing or names no link.", clause="refused")
def controller_com_link_missing(ctx: CheckContext) -> Iterator[Issue]:
    """`<comLinkName>` is the body frame gz-sim measures rotor arms in and reads the
    vehicle state from, almost always the base link. Without it, or when it names no
    link, the controller does not start.

    Severity (error, refused): the velocity-control system does not load.
    """
    for table in ctx.controller_tables:
        if table.source != "velocity-control":
            continue
        if not table.com_link:
            base = ctx.robot.base_link if ctx.tree_ok else "base_link"
            yield Issue(f"{table.label} has no <comLinkName>", table.plugin.loc, table.label,
                        hint=f"add <comLinkName>{base}</comLinkName>")
        elif table.com_link not in ctx.robot.link_map:
            yield Issue(f"{table.label} <comLinkName> '{table.com_link}' names no link",
                        table.loc_of("comLinkName"), table.com_link,
                        hint="name the vehicle's base link")


# --------------------------------------------------------------- per rotor

@rule("C404", "controller-direction-mismatch", "error",
      "A controller entry's direction disagrees with the motor's turningDirection.", clause="flight-stack")
def controller_direction_mismatch(ctx: CheckContext) -> Iterator[Issue]:
    """direction +1 means counter-clockwise seen from above (turningDirection `ccw`), -1
    clockwise; this is the convention of both RotorS (rotor_configuration `direction`)
    and gz-sim (`<direction>`), whose allocation matrices use -direction * k_F * k_M for
    the yaw row. A flipped sign makes the controller push yaw the wrong way with that
    rotor: the vehicle spins up in yaw on take-off.

    Severity (error, flight-stack): the controller spins the motor's torque the other
    way in its yaw allocation.
    """
    for table in _tables(ctx):
        for entry, rotor in _pairs(ctx, table):
            if rotor.turning_sign == 0 or entry.direction not in (1.0, -1.0):
                continue
            if int(entry.direction) != rotor.turning_sign:
                model = DIRECTION_NAME[rotor.turning_sign]
                yield Issue(
                    f"{_entry(table, entry)}: direction {entry.direction:+g} "
                    f"({DIRECTION_NAME[int(entry.direction)]}), but {_rotor_name(rotor)} turns "
                    f"{model} ({rotor.direction_tag} at {rotor.param_loc(rotor.direction_tag)})",
                    entry.loc_of("direction"), rotor.joint or rotor.name,
                    hint=f"set direction to {rotor.turning_sign:+d} ({model}), or fix the "
                         "motor's turningDirection if the controller is right")


def _angle_hint(ctx: CheckContext, entry: "ControllerRotor", model_rad: float,
                controller_rad: float) -> str:
    # Degrees where radians are read: the number, taken as degrees, is the model's angle.
    if abs(controller_rad) > ANGLE_TOL_RAD \
            and abs(_wrap(math.radians(controller_rad) - model_rad)) < ANGLE_TOL_RAD:
        return (f"{controller_rad:g} is the rotor's angle in degrees; RotorS reads radians: "
                f"set angle: {model_rad:.6g}")
    # An entry that matches another motor in angle and direction is an ordering mistake.
    for number, other in _motor_index(ctx).items():
        planar = _planar(other, _com_xy(ctx))
        if number != entry.index and planar \
                and abs(_wrap(planar[0] - controller_rad)) < ANGLE_TOL_RAD \
                and entry.direction == other.turning_sign:
            return (f"this entry describes motor {number}: entry i must describe the motor "
                    f"with motorNumber i (else set angle: {model_rad:.6g})")
    if abs(_wrap(math.pi / 2 - controller_rad - model_rad)) < ANGLE_TOL_RAD:
        return (f"the table's angle is the model's with x and y swapped; angles are measured "
                f"from body +x towards +y: set angle: {model_rad:.6g}")
    if abs(_wrap(-controller_rad - model_rad)) < ANGLE_TOL_RAD:
        return (f"the table's angle is the model's mirrored (measured clockwise, or y "
                f"pointing right); set angle: {model_rad:.6g}")
    return f"set angle: {model_rad:.6g}"


@rule("C405", "controller-angle-mismatch", "error",
      "A controller entry's rotor angle disagrees with where the rotor is.", clause="flight-stack")
def controller_angle_mismatch(ctx: CheckContext) -> Iterator[Issue]:
    """RotorS's rotor_configuration `angle` [rad] is the rotor's bearing in the body
    xy-plane, measured from +x (forward) towards +y (left), i.e. counter-clockwise seen
    from above. The controller's roll and pitch columns are sin(angle) and -cos(angle)
    times the arm: a wrong angle commands roll when pitch is wanted, and the vehicle
    drifts or flips. Compared in the base axes about the whole robot's COM (the module
    docstring says why) with a tolerance of 0.5°.

    Severity (error, flight-stack): the controller gives the rotor roll and pitch torque
    of the wrong sign.
    """
    com_xy = _com_xy(ctx) if _tables(ctx) else np.zeros(2)
    for table in _tables(ctx):
        for entry, rotor in _pairs(ctx, table):
            planar = _planar(rotor, com_xy)
            if entry.angle_rad is None or not math.isfinite(entry.angle_rad) or planar is None:
                continue
            model_rad = planar[0]
            if abs(_wrap(entry.angle_rad - model_rad)) > ANGLE_TOL_RAD:
                yield Issue(
                    f"{_entry(table, entry)}: angle {entry.angle_rad:.4f} rad "
                    f"({_deg(entry.angle_rad)}), but {_rotor_name(rotor)} sits at "
                    f"{model_rad:.4f} rad ({_deg(model_rad)}) from body +x towards +y"
                    f"{_about(com_xy)} (pose at {_geometry_loc(ctx, rotor)})",
                    entry.loc_of("angle_rad"), rotor.joint or rotor.name,
                    hint=_angle_hint(ctx, entry, model_rad, entry.angle_rad))


@rule("C406", "controller-arm-length-mismatch", "warning",
      "A controller entry's arm length disagrees with where the rotor is.", clause="suspicious")
def controller_arm_length_mismatch(ctx: CheckContext) -> Iterator[Issue]:
    """`arm_length` [m] is the rotor's distance from the vehicle's centre of mass in the
    body xy-plane (the height of the rotor above the frame does not count; RotorS' own
    models have the COM at the base origin). The controller
    scales roll and pitch torque with it: a wrong arm gives a wrong attitude gain on that
    axis. Tolerance: 1 mm or 1 %, whichever is larger.

    Severity (warning): the torque keeps its sign, only its gain changes, so the vehicle
    flies (C405 is the error: a rotor at another angle gets torque of the wrong sign).
    """
    com_xy = _com_xy(ctx) if _tables(ctx) else np.zeros(2)
    for table in _tables(ctx):
        for entry, rotor in _pairs(ctx, table):
            planar = _planar(rotor, com_xy)
            if entry.arm_length_m is None or not math.isfinite(entry.arm_length_m) \
                    or planar is None:
                continue
            model_m = planar[1]
            if abs(entry.arm_length_m - model_m) > max(ARM_LENGTH_ABS_TOL_M,
                                                       ARM_LENGTH_REL_TOL * model_m):
                yield Issue(
                    f"{_entry(table, entry)}: arm_length {entry.arm_length_m:.4g} m, but "
                    f"{_rotor_name(rotor)} is {model_m:.4g} m from the centre of mass in the "
                    f"xy-plane{_about(com_xy)} (pose at {_geometry_loc(ctx, rotor)})",
                    entry.loc_of("arm_length_m"), rotor.joint or rotor.name,
                    hint=f"set arm_length: {model_m:.6g}")


def _constant_issues(ctx: CheckContext, attr: str, rotor_attr: str, param: str,
                     label: dict[str, str], unit: str) -> Iterator[Issue]:
    for table in _tables(ctx):
        for entry, rotor in _pairs(ctx, table):
            value, model = getattr(entry, attr), getattr(rotor, rotor_attr)
            if not (math.isfinite(value) and math.isfinite(model)) or model == 0:
                continue
            if _relative_gap(value, model) > CONSTANT_REL_TOL:
                yield Issue(
                    f"{_entry(table, entry)}: {label[table.source]} {value:.6g} {unit}, but "
                    f"{_rotor_name(rotor)} has {param} {model:.6g} {unit} "
                    f"({rotor.param_loc(param)})",
                    entry.loc_of(attr), rotor.joint or rotor.name,
                    hint=f"use the motor's value {model:.6g}, or fix the motor plugin")


@rule("C407", "controller-force-constant-mismatch", "warning",
      "A controller entry's force constant differs from the motor's motorConstant.", clause="suspicious")
def controller_force_constant_mismatch(ctx: CheckContext) -> Iterator[Issue]:
    """The controller turns wanted thrust into rotor speed with its force constant; the
    motor turns speed into thrust with `motorConstant` [N/(rad/s)²]. If they differ by
    more than 1 %, the vehicle hovers off its commanded height and its attitude gains are
    scaled.

    Severity (warning, suspicious): a force constant scales the controller's gains, it
    does not flip a sign.
    """
    yield from _constant_issues(ctx, "force_constant", "motor_constant", "motorConstant",
                                {"yaml": "rotor_force_constant",
                                 "velocity-control": "forceConstant"}, "N/(rad/s)²")


@rule("C408", "controller-moment-constant-mismatch", "warning",
      "A controller entry's moment constant differs from the motor's momentConstant.", clause="suspicious")
def controller_moment_constant_mismatch(ctx: CheckContext) -> Iterator[Issue]:
    """The yaw drag torque is momentConstant [m] times thrust. A controller that assumes
    another value gets the wrong yaw authority: sluggish or oscillating heading.
    Tolerance 1 %.

    Severity (warning, suspicious): a moment constant scales the yaw gain, it does not
    flip a sign.
    """
    yield from _constant_issues(ctx, "moment_constant", "moment_constant", "momentConstant",
                                {"yaml": "rotor_moment_constant",
                                 "velocity-control": "momentConstant"}, "m")


# --------------------------------------------------------------- vehicle

@rule("C409", "controller-mass-mismatch", "warning",
      "A controller's vehicle mass differs from the model's total mass.", clause="suspicious")
def controller_mass_mismatch(ctx: CheckContext) -> Iterator[Issue]:
    """The controller's feed-forward thrust is mass x g. When its mass differs from the sum
    of the model's link masses by more than 1 %, the vehicle sinks or climbs until an
    integrator (if any) catches up, and position gains are scaled. RotorS ships parameter
    files with the base link's mass only; the model's total includes rotors and sensors.

    Severity (warning, suspicious): a mass scales the controller's feed-forward;
    integrators absorb it.
    """
    for table in _tables(ctx):
        if table.mass_kg is None or not math.isfinite(table.mass_kg):
            continue
        whole = ctx.whole_robot.mass_kg
        if whole > 0 and _relative_gap(table.mass_kg, whole) > MASS_REL_TOL:
            yield Issue(f"{table.label}: mass {table.mass_kg:.6g} kg, but the model "
                        f"('{ctx.robot.name}', {ctx.robot.loc}) weighs {whole:.6g} kg in total "
                        f"({100 * (table.mass_kg - whole) / whole:+.1f} %)",
                        table.loc_of("mass"), ctx.robot.name, hint=f"set mass: {whole:.6g}")


@rule("C410", "controller-inertia-mismatch", "warning",
      "A controller's inertia differs from the model's whole-robot inertia.", clause="suspicious")
def controller_inertia_mismatch(ctx: CheckContext) -> Iterator[Issue]:
    """The controller's `inertia` is the whole vehicle's tensor about its centre of mass in
    body axes [kg·m²]; attitude control feeds forward with it. Each element is compared
    with the model's (all links at zero joint positions), within 10 % of that diagonal
    moment (off-diagonal: of the largest one).

    Severity (warning, suspicious): an inertia scales the attitude gains; it does not
    flip a sign.
    """
    for table in _tables(ctx):
        I_c = table.inertia_kg_m2
        if I_c is None or not np.all(np.isfinite(I_c)):
            continue
        whole = ctx.whole_robot
        I_m = np.asarray(whole.inertia_kg_m2, dtype=float)
        if whole.mass_kg <= 0 or not np.all(np.isfinite(I_m)):
            continue
        largest = float(np.max(np.abs(np.diag(I_m))))
        bad = []
        for (i, j), key in zip([(0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2)],
                               ("xx", "xy", "xz", "yy", "yz", "zz")):
            scale = abs(I_m[i, i]) if i == j else largest
            if abs(I_c[i, j] - I_m[i, j]) > INERTIA_REL_TOL * scale:
                bad.append(f"{key} {I_c[i, j]:.4g} vs {I_m[i, j]:.4g}")
        if bad:
            model = " ".join(f"{k}: {v:.6g}," for k, v in zip(
                ("xx", "xy", "xz", "yy", "yz", "zz"),
                (I_m[0, 0], I_m[0, 1], I_m[0, 2], I_m[1, 1], I_m[1, 2], I_m[2, 2])))
            yield Issue(f"{table.label}: inertia differs from the model's whole-robot inertia "
                        f"about its COM ('{ctx.robot.name}', {ctx.robot.loc}) in kg·m²: "
                        f"{'; '.join(bad)}", table.loc_of("inertia"), ctx.robot.name,
                        hint=f"set inertia: {{{model.rstrip(',')}}}")
