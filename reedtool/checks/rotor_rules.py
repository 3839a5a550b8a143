"""Rotor rules (R3xx): the motor plugins describe rotors that can hold the robot in hover.

They run only when rotors are found (RotorS, PX4 classic and gz-sim motor models,
ArduPilotPlugin velocity controls: reedtool.physics.rotors). The wiring rules (numbers,
directions, targets) see every rotor; the hover rules see the lift rotors only (a pusher
or puller is propulsion), and an omnidirectional frame is judged by its 6-DoF allocation.
Geometry
comes from reedtool.physics.rotors, the allocation matrix from reedtool.physics.allocation and the hover
trim from reedtool.physics.trim; this module interprets them.
"""

from __future__ import annotations

import math
from collections import Counter
from typing import TYPE_CHECKING, Iterator

import numpy as np

from reedtool.checks.context import CheckContext
from reedtool.checks.finding import Issue
from reedtool.checks.registry import rule
from reedtool.physics.trim import STANDARD_GRAVITY_M_S2

if TYPE_CHECKING:
    from reedtool.physics.rotors import Rotor

# Net yaw torque at equal rotor speed, as a fraction of the sum of the rotors' drag
# torques, above which the directions (or moment constants) do not balance.
YAW_BALANCE_REL_TOL = 0.01
# Condition number of the allocation matrix with each row scaled to unit norm: 1 for a
# symmetric frame, large when two of thrust/roll/pitch/yaw are almost coupled.
MAX_CONDITION_NUMBER = 25.0
RANK_TOL = 1e-9
THRUST_TO_WEIGHT_MIN = 1.0
THRUST_TO_WEIGHT_WARN = 1.5
HOVER_THROTTLE_MAX = 0.8
AXIS_TILT_TOL_DEG = 1.0
DIRECTIONS = ("ccw", "cw")
CONSTANTS = (("motor_constant", "motorConstant", "N/(rad/s)²"),
             ("moment_constant", "momentConstant", "m"),
             ("max_rot_velocity_rad_s", "maxRotVelocity", "rad/s"))


def _fmt(value: float) -> str:
    return f"{value:.4g}"


def all_rotors(ctx: CheckContext) -> list["Rotor"]:
    """Every rotor (for the wiring rules)."""
    return ctx.rotors if ctx.tree_ok else []


def _lift(ctx: CheckContext) -> list["Rotor"]:
    """The lift rotors (for the hover rules)."""
    return ctx.lift_rotors if ctx.tree_ok else []


def _written(rotor: "Rotor") -> bool:
    """Constants written in a motor plugin (ArduPilot's come from LiftDrag, if at all)."""
    return rotor.kind != "ardupilot"


def _constants_ok(rotor: "Rotor") -> bool:
    return (math.isfinite(rotor.motor_constant) and rotor.motor_constant > 0
            and math.isfinite(rotor.max_rot_velocity_rad_s) and rotor.max_rot_velocity_rad_s > 0
            and math.isfinite(rotor.moment_constant) and rotor.moment_constant >= 0)


def physics_ready(ctx: CheckContext) -> bool:
    """Every rotor placed, turning a known way, with usable constants; the robot has mass;
    no rotor carried by an actuated joint (its zero pose is not the flight pose: R319)."""
    rotors = _lift(ctx)
    if not rotors or ctx.articulated_rotors:
        return False
    for rotor in rotors:
        if not (np.all(np.isfinite(rotor.position_m)) and np.all(np.isfinite(rotor.axis))
                and np.linalg.norm(rotor.axis) > 0):
            return False
        if rotor.direction not in DIRECTIONS or not _constants_ok(rotor):
            return False
        joint = ctx.robot.joint_map.get(rotor.joint or "")
        if joint is None or joint.child != rotor.link:  # R314/R315: geometry of the wrong link
            return False
    whole = ctx.whole_robot
    return math.isfinite(whole.mass_kg) and whole.mass_kg > 0


def _direction_loc(rotor: "Rotor"):
    return rotor.param_loc(rotor.direction_tag)


# --------------------------------------------------------------- plugin wiring

def _number_or_nan(text: str) -> float:
    try:
        return float(text)
    except ValueError:
        return math.nan


def _number_what(rotor: "Rotor") -> str:
    return {"actuator_number": "actuator_number", "channel": "channel"}.get(
        rotor.number_tag, "motor number")


def _number_loc(rotor: "Rotor"):
    return rotor.param_loc(rotor.number_tag)


@rule("R301", "motor-number-duplicate", "error", "Two rotors have the same motor number.", clause="cannot-fly")
def motor_number_duplicate(ctx: CheckContext) -> Iterator[Issue]:
    """The motor number (`<motorNumber>`; gz-sim `<actuator_number>`; ArduPilot the
    `<control channel>`) is the rotor's index in the command the flight stack sends. Two
    rotors with the same number receive the same command and another index drives
    nothing; the vehicle flips on take-off.

    Severity (error, cannot-fly): two rotors read one command and another command spins
    nothing.
    """
    seen: dict[int, "Rotor"] = {}
    for rotor in all_rotors(ctx):
        number = rotor.motor_number
        if number is None:
            continue
        if number in seen:
            yield Issue(f"rotor '{rotor.name}' has {_number_what(rotor)} {number}, already "
                        f"used by '{seen[number].name}'", _number_loc(rotor),
                        rotor.name, hint="number the rotors 0, 1, ..., n-1, each once")
        else:
            seen[number] = rotor


@rule("R302", "motor-numbers-not-contiguous", "error",
      "A motor has no number, or one its autopilot interface never commands.",
      clause="cannot-fly")
def motor_numbers_not_contiguous(ctx: CheckContext) -> Iterator[Issue]:
    """A motor plugin spins at the entry of the command vector its number names. The
    vector is what the autopilot interface sends: RotorS's MAVLink interface sends
    `rotor_count` entries (0..count-1), PX4 classic's fills entry `input_index` of each
    control channel (a plane's puller is motor 4 because its channel's input_index is 4).
    A motor whose number the interface never fills never spins. A missing or unreadable
    `<motorNumber>` / `<actuator_number>` is reported as well.

    Without such an interface, RotorS' motor model (and PX4 classic's copy of it) still
    reads entry `motorNumber` of whatever the controller sends (gazebo_motor_model.cpp),
    and RotorS' controllers send one entry per rotor: with n rotors, a number beyond n-1
    (a gap below it) is a motor that never receives a command. On gz-sim, where PX4's gz
    bridge or another node sends the commands, the numbers are the flight stack's outputs
    and a gap is no mistake by itself: `--airframe` compares them with PX4's outputs (C414).

    Severity (error, cannot-fly): the motor never receives a command.
    """
    from reedtool.physics.rotors import command_vector, controller_command_vector

    # ArduPilot channels are servo outputs mapped by SERVOn_FUNCTION: any channel is fine.
    rotors = [r for r in all_rotors(ctx) if r.kind != "ardupilot"]
    if not rotors:
        return
    vector = command_vector(ctx.robot) or controller_command_vector(rotors)
    for rotor in rotors:
        if rotor.motor_number is None:
            tag = rotor.number_tag
            raw = rotor.param(tag)
            what = f"'{raw}' is not a motor number" if raw is not None else f"no <{tag}>"
            yield Issue(f"rotor '{rotor.name}': {what}", _number_loc(rotor),
                        rotor.name, hint=f"add <{tag}>N</{tag}>, N from 0 to "
                                         f"{len(rotors) - 1}")
    if vector is None:
        return
    used = {r.motor_number for r in rotors if r.motor_number is not None}
    free = sorted(vector.indices - used)
    for rotor in rotors:
        if rotor.motor_number is not None and rotor.motor_number not in vector.indices:
            indices = sorted(vector.indices)
            shown = (f"{indices[0]}..{indices[-1]}" if indices == list(range(indices[0],
                                                                              indices[-1] + 1))
                     else ", ".join(map(str, indices)))
            yield Issue(f"rotor '{rotor.name}' has {_number_what(rotor)} {rotor.motor_number}, "
                        f"but {vector.sender} entries {shown} ({vector.what}"
                        f"{f', {vector.loc}' if vector.loc else ''}): this motor never "
                        "receives a command",
                        _number_loc(rotor), rotor.name,
                        hint=f"unused numbers: {', '.join(map(str, free))}" if free else None)


@rule("R303", "rotor-direction-invalid", "error", "A rotor's turning direction is not cw or ccw.", clause="refused")
def rotor_direction_invalid(ctx: CheckContext) -> Iterator[Issue]:
    """`<turningDirection>` must be exactly `ccw` or `cw` (lower case: the motor plugins
    compare the string). Anything else makes the plugin refuse to load or spin the
    rotor with an undefined sign.

    Severity (error, refused): the motor plugin refuses the direction and the rotor
    never turns.
    """
    for rotor in all_rotors(ctx):
        if rotor.kind == "ardupilot":
            multiplier = _number_or_nan(rotor.param("multiplier") or "1")
            if not (math.isfinite(multiplier) and multiplier != 0):
                yield Issue(f"rotor '{rotor.name}': <multiplier> '{rotor.param('multiplier')}' "
                            "gives no spin direction", _direction_loc(rotor), rotor.name,
                            hint="a positive multiplier spins the joint along its axis, a "
                                 "negative one against it")
            continue
        if rotor.direction not in DIRECTIONS:
            what = f"'{rotor.direction}'" if rotor.direction else "missing"
            yield Issue(f"rotor '{rotor.name}': turning direction {what}", _direction_loc(rotor),
                        rotor.name, hint="write <turningDirection>ccw</turningDirection> or cw")


@rule("R304", "yaw-moment-imbalance", "error",
      "At equal rotor speed the rotors' yaw moments do not cancel.", clause="cannot-fly")
def yaw_moment_imbalance(ctx: CheckContext) -> Iterator[Issue]:
    """Each rotor's drag pushes the body the other way round (a ccw rotor pushes it cw),
    by momentConstant x thrust. When every rotor spins at the same speed these moments
    must cancel: as many ccw as cw rotors, with equal constants, in a symmetric layout.
    Otherwise the vehicle spins up in yaw as soon as it lifts off, or the controller
    must unbalance the rotors just to hold heading.

    The hint names the rotor whose direction, flipped, balances the set when there is one.

    Severity (error, cannot-fly): the vehicle spins up in yaw at take-off.
    """
    found = None if ctx.omnidirectional else _yaw_imbalance(ctx)
    if found is None:
        return
    rotors, net_N_m, total_N_m = found
    counts = Counter(r.direction for r in rotors)
    hint = "make half of the rotors ccw and half cw, alternating around the frame"
    best = _best_flip(ctx, rotors)
    target = rotors[0]
    if best is not None:
        target = rotors[best]
        other = "cw" if target.direction == "ccw" else "ccw"
        hint = f"set rotor '{target.name}' to {other}" if target.kind != "ardupilot" else \
            f"flip the sign of rotor '{target.name}''s <multiplier> (it turns {other} then)"
    yield Issue(f"at equal rotor speed the yaw moments do not cancel: net {_fmt(net_N_m)} N·m "
                f"at hover thrust ({counts['ccw']} ccw, {counts['cw']} cw; "
                f"{100 * abs(net_N_m) / total_N_m:.0f}% of the rotors' drag torque)",
                _direction_loc(target), target.name, hint=hint)


def _equal_speed_yaw(ctx: CheckContext, signs: np.ndarray) -> tuple[float, float]:
    """(net, total) drag yaw torque [N·m] with every rotor at the speed that carries the weight.

    Only the rotors' drag reaction (-turning_sign * momentConstant * thrust along the
    rotor axis) counts: the yaw a tilted rotor makes through its lever arm is R311's.
    """
    rotors = _lift(ctx)
    k = np.array([r.motor_constant for r in rotors])
    axis_z = np.array([r.axis[2] / np.linalg.norm(r.axis) for r in rotors])
    km = np.array([r.moment_constant for r in rotors])
    # Common hover speed^2: sum(k * w2 * axis_z) = m g.
    weight_N = ctx.whole_robot.mass_kg * STANDARD_GRAVITY_M_S2
    lift_per_w2 = float(np.sum(k * np.clip(axis_z, 0, None)))
    w2 = weight_N / lift_per_w2 if lift_per_w2 > 0 else 1.0
    drag_N_m = km * k * w2 * axis_z
    return float(np.sum(-signs * drag_N_m)), float(np.sum(np.abs(drag_N_m)))


def _yaw_imbalance(ctx: CheckContext):
    if not physics_ready(ctx):
        return None
    rotors = _lift(ctx)
    signs = np.array([r.turning_sign for r in rotors], dtype=float)
    net, total = _equal_speed_yaw(ctx, signs)
    if total <= 0 or abs(net) <= YAW_BALANCE_REL_TOL * total:
        return None
    return rotors, net, total


def _best_flip(ctx: CheckContext, rotors) -> int | None:
    signs = np.array([r.turning_sign for r in rotors], dtype=float)
    best, best_net = None, None
    for i in range(len(rotors)):
        flipped = signs.copy()
        flipped[i] = -flipped[i]
        net, total = _equal_speed_yaw(ctx, flipped)
        if abs(net) <= YAW_BALANCE_REL_TOL * total and _rank(ctx, flipped) == 4 and \
                (best_net is None or abs(net) < best_net):
            best, best_net = i, abs(net)
    return best


# ----------------------------------------------------------------- allocation

def normalised_allocation(ctx: CheckContext, signs: np.ndarray | None = None) -> np.ndarray:
    """The allocation matrix with each row scaled to unit norm (unit-free conditioning)."""
    A = ctx.allocation.copy()
    if signs is not None:
        rotors = _lift(ctx)
        current = np.array([r.turning_sign for r in rotors], dtype=float)
        drag = np.array([r.moment_constant * r.axis[2] / np.linalg.norm(r.axis) for r in rotors])
        A[3] = A[3] + (current - signs) * drag
    norms = np.linalg.norm(A, axis=1, keepdims=True)
    return np.divide(A, norms, out=np.zeros_like(A), where=norms > 0)


def _rank(ctx: CheckContext, signs: np.ndarray | None = None) -> int:
    A = normalised_allocation(ctx, signs)
    singular = np.linalg.svd(A, compute_uv=False)
    return int(np.sum(singular > RANK_TOL * max(singular.max(initial=0), 1e-300)))


_AXES = ("thrust", "roll", "pitch", "yaw")


@rule("R305", "allocation-rank-deficient", "error",
      "The rotors cannot set thrust, roll, pitch and yaw independently.", clause="cannot-fly")
def allocation_rank_deficient(ctx: CheckContext) -> Iterator[Issue]:
    """The allocation matrix maps rotor thrusts to collective thrust and roll, pitch and
    yaw torque about the centre of mass; it is built from the rotors' positions, axes,
    directions and constants. With rank below 4 some combination of the four cannot be
    commanded: typically neighbouring rotors of a quad-X turn the same way (yaw becomes
    roll or pitch), or all rotors lie on one line.

    Severity (error, cannot-fly): some axis cannot be controlled.
    """
    if not physics_ready(ctx):
        return
    if ctx.omnidirectional:
        yield from _wrench_rank_deficient(ctx)
        return
    if _rank(ctx) == 4:
        return
    A = normalised_allocation(ctx)
    u, s, _vt = np.linalg.svd(A)
    rank = _rank(ctx)
    coupled = set()
    for vector in u[:, rank:].T:  # combinations of outputs no thrust vector can produce
        coupled |= {_AXES[i] for i in np.flatnonzero(np.abs(vector) > 1e-6)}
    names = [a for a in _AXES if a in coupled]
    hint = ("check the turning directions: diagonal rotors of a quad-X share a direction, "
            "neighbours alternate") if "yaw" in coupled else \
        "spread the rotors around the centre of mass in both x and y"
    yield Issue(f"allocation matrix has rank {rank} < 4 for {len(_lift(ctx))} rotors: "
                f"{', '.join(names)} cannot be set independently", _lift(ctx)[0].loc,
                "rotors", hint=hint)


_WRENCH_AXES = ("force x", "force y", "force z", "roll", "pitch", "yaw")


def _wrench_rank_deficient(ctx: CheckContext) -> Iterator[Issue]:
    """Omnidirectional frames: the 6 x n force-and-torque allocation must have rank 6."""
    W = ctx.wrench_allocation
    norms = np.linalg.norm(W, axis=1, keepdims=True)
    W = np.divide(W, norms, out=np.zeros_like(W), where=norms > 0)
    u, s, _vt = np.linalg.svd(W)
    rank = int(np.sum(s > RANK_TOL * max(s.max(initial=0), 1e-300)))
    if rank == 6:
        return
    coupled = set()
    for vector in u[:, rank:].T:
        coupled |= {_WRENCH_AXES[i] for i in np.flatnonzero(np.abs(vector) > 1e-6)}
    yield Issue(f"omnidirectional frame: the force-and-torque allocation has rank {rank} < 6 "
                f"for {len(_lift(ctx))} rotors: "
                f"{', '.join(a for a in _WRENCH_AXES if a in coupled)} cannot be set "
                "independently", _lift(ctx)[0].loc, "rotors",
                hint="point the rotors in more independent directions")


@rule("R306", "allocation-ill-conditioned", "warning",
      "The allocation matrix is nearly singular.", clause="suspicious")
def allocation_ill_conditioned(ctx: CheckContext) -> Iterator[Issue]:
    """With each row scaled to unit norm, the allocation matrix of a symmetric frame has
    condition number 1. Above 25 one axis is controlled only by large, opposing thrust
    changes: the controller saturates motors on small commands.

    Severity (warning, suspicious): every axis is controllable, with little authority on
    one.
    """
    if not physics_ready(ctx) or ctx.omnidirectional or _rank(ctx) < 4:
        return
    cond = float(np.linalg.cond(normalised_allocation(ctx)))
    if cond > MAX_CONDITION_NUMBER:
        yield Issue(f"allocation matrix condition number {cond:.3g} > {MAX_CONDITION_NUMBER:g} "
                    "(rows scaled to unit norm)", _lift(ctx)[0].loc, "rotors",
                    hint="place the rotors symmetrically about the centre of mass")


# ----------------------------------------------------------------------- trim

@rule("R307", "trim-infeasible", "error",
      "No rotor thrusts within [0, k·ω_max²] hold the robot level in hover.", clause="cannot-fly")
def trim_infeasible(ctx: CheckContext) -> Iterator[Issue]:
    """Hover needs thrusts that give collective thrust m·g and no torque about the
    centre of mass, each between 0 and the rotor's maximum k·ω_max². When the least-
    squares thrusts leave that range although the rotors can lift the robot, the centre
    of mass is too far from the rotors' centre (a rotor would have to push down) or the
    yaw moments cannot cancel.

    Not reported when R304, R305 or R308 already explain it.

    Severity (error, cannot-fly): the vehicle cannot hover level.
    """
    if not physics_ready(ctx):
        return
    if not ctx.omnidirectional and (_rank(ctx) < 4 or _yaw_imbalance(ctx) is not None):
        return
    if ctx.omnidirectional and next(_wrench_rank_deficient(ctx), None) is not None:
        return
    trim = ctx.trim
    if trim.feasible or trim.thrust_to_weight < THRUST_TO_WEIGHT_MIN:
        return
    com = ctx.whole_robot.com_m
    yield Issue(f"no hover trim: {trim.message} (COM at {', '.join(_fmt(v) for v in com)} m "
                "in the base frame)", _lift(ctx)[0].loc, "rotors",
                hint="move the centre of mass (link masses and <inertial> origins) over the "
                     "middle of the rotors, or move the rotors")


def _weight_and_trim(ctx: CheckContext):
    if not physics_ready(ctx):
        return None
    trim = ctx.trim
    if not math.isfinite(trim.thrust_to_weight):
        return None
    return trim


def _omega_for(ctx: CheckContext, ratio: float) -> str | None:
    """maxRotVelocity that would bring thrust-to-weight to `ratio` (same for all rotors),
    or None when no speed would: rotors whose full-speed thrust is zero (a zero constant,
    or k·ω_max² below the smallest float) scale to nothing."""
    trim = ctx.trim
    omega = max(r.max_rot_velocity_rad_s for r in _lift(ctx))
    if not trim.thrust_to_weight > 0:
        return None
    needed = omega * math.sqrt(ratio / trim.thrust_to_weight)
    return f"{needed:.0f} rad/s" if math.isfinite(needed) else None


def _max_loc(rotor: "Rotor"):
    return rotor.param_loc("multiplier" if rotor.kind == "ardupilot" else "maxRotVelocity")


@rule("R308", "thrust-to-weight-below-one", "error",
      "At full speed the rotors cannot lift the robot.", clause="cannot-fly")
def thrust_to_weight_below_one(ctx: CheckContext) -> Iterator[Issue]:
    """Thrust-to-weight is the rotors' combined upward thrust at maxRotVelocity,
    sum(k·ω_max²·axis_z), over the robot's weight m·g. Below 1 the model cannot leave
    the ground. Usually a mass in grams read as kilograms, a motor constant off by a
    power of ten, or maxRotVelocity in rpm instead of rad/s.

    Severity (error, cannot-fly): the vehicle cannot leave the ground.
    """
    trim = _weight_and_trim(ctx)
    if trim is None or trim.thrust_to_weight >= THRUST_TO_WEIGHT_MIN:
        return
    yield Issue(f"thrust-to-weight {trim.thrust_to_weight:.3g} < 1: the rotors give at most "
                f"{_fmt(trim.thrust_to_weight * trim.weight_N)} N, the robot weighs "
                f"{_fmt(trim.weight_N)} N ({_fmt(ctx.whole_robot.mass_kg)} kg)",
                _max_loc(_lift(ctx)[0]), "rotors",
                hint=_more_thrust_hint(ctx))


def _more_thrust_hint(ctx: CheckContext) -> str:
    omega = _omega_for(ctx, THRUST_TO_WEIGHT_WARN)
    if omega is None:
        return ("the rotors give no thrust at full speed: check motorConstant and "
                "maxRotVelocity (units: N/(rad/s)^2 and rad/s), and the mass")
    return (f"check mass and motor constants; for thrust-to-weight "
            f"{THRUST_TO_WEIGHT_WARN:g} maxRotVelocity would be {omega}")


@rule("R309", "thrust-to-weight-low", "warning",
      "Thrust-to-weight is below 1.5: little margin to climb and control.", clause="suspicious")
def thrust_to_weight_low(ctx: CheckContext) -> Iterator[Issue]:
    """A multirotor that can lift itself but with thrust-to-weight below 1.5 hovers near
    full throttle, with little left for attitude control or climbing; real vehicles are
    built for 2 or more.

    Severity (warning, suspicious): it flies, with little margin to climb and control.
    """
    trim = _weight_and_trim(ctx)
    if trim is None or not THRUST_TO_WEIGHT_MIN <= trim.thrust_to_weight < THRUST_TO_WEIGHT_WARN:
        return
    yield Issue(f"thrust-to-weight {trim.thrust_to_weight:.3g} < {THRUST_TO_WEIGHT_WARN:g}: "
                f"{_fmt(trim.thrust_to_weight * trim.weight_N)} N of thrust for "
                f"{_fmt(trim.weight_N)} N of weight",
                _max_loc(_lift(ctx)[0]), "rotors",
                hint=f"maxRotVelocity {_omega_for(ctx, THRUST_TO_WEIGHT_WARN)} (or a "
                     f"correspondingly larger motor constant, or less mass) gives "
                     f"{THRUST_TO_WEIGHT_WARN:g}")


@rule("R310", "hover-throttle-high", "warning",
      "A rotor needs more than 80 % of its maximum speed to hover.", clause="suspicious")
def hover_throttle_high(ctx: CheckContext) -> Iterator[Issue]:
    """Hover throttle is the trim speed over maxRotVelocity. Above 0.8 for any rotor,
    that rotor has almost no speed left to correct attitude and the controller
    saturates in the first gust (or the first Gazebo step with an unlucky contact).

    Severity (warning, suspicious): it hovers, with little left for control.
    """
    trim = _weight_and_trim(ctx)
    if trim is None or not trim.feasible or trim.hover_throttle_max <= HOVER_THROTTLE_MAX:
        return
    rotors = _lift(ctx)
    worst = int(np.argmax(trim.throttle))
    rotor = rotors[worst]
    needed = trim.omega_rad_s[worst] / HOVER_THROTTLE_MAX
    yield Issue(f"rotor '{rotor.name}' hovers at {trim.omega_rad_s[worst]:.0f} rad/s, "
                f"{100 * trim.throttle[worst]:.0f}% of its maximum "
                f"{_fmt(rotor.max_rot_velocity_rad_s)} rad/s",
                _max_loc(rotor), rotor.name,
                hint=f"maxRotVelocity >= {needed:.0f} rad/s keeps hover at 80%")


# ------------------------------------------------------------------- geometry

@rule("R311", "rotor-axis-tilted", "warning", "A rotor's thrust axis is not along body z.", clause="suspicious")
def rotor_axis_tilted(ctx: CheckContext) -> Iterator[Issue]:
    """Motor plugins push along the rotor link's z axis. For a conventional multirotor
    that axis is the base link's z; a tilt usually comes from an `rpy` on the rotor joint
    or an axis written in the wrong frame. Deliberately tilted designs can ignore this
    rule (`--ignore R311`).

    A balanced pattern (R320: several rotors tilted so that their side forces and tilt
    yaw torques cancel, as on the AscTec Neo) is information, not this warning. Propulsion
    rotors (R319) and omnidirectional frames are not judged by tilt, nor rotors carried by
    an actuated joint (R319: the servo sets their tilt in flight).

    Severity (warning, suspicious): a tilt may be deliberate.
    """
    if ctx.omnidirectional or ctx.articulated_rotors or balanced_tilt(ctx) is not None:
        return
    for rotor in _lift(ctx):
        axis = np.asarray(rotor.axis, dtype=float)
        norm = np.linalg.norm(axis)
        if not np.all(np.isfinite(axis)) or norm == 0:
            continue
        tilt_deg = math.degrees(math.acos(float(np.clip(axis[2] / norm, -1, 1))))
        if tilt_deg > AXIS_TILT_TOL_DEG:
            joint = ctx.robot.joint_map.get(rotor.joint or "")
            loc = (joint.origin_loc or joint.loc) if joint else rotor.loc
            down = "; it points down, so its thrust pushes the robot to the ground" \
                if tilt_deg > 90 else ""
            yield Issue(f"rotor '{rotor.name}' thrust axis ({', '.join(f'{v:.3f}' for v in axis / norm)}) "
                        f"is tilted {tilt_deg:.1f}° from body z{down}", loc, rotor.name,
                        hint="check the rpy of the rotor joint's <origin>")


@rule("R312", "rotor-count-mismatch", "error",
      "The MAVLink/PX4 interface declares a different number of rotors than exist.", clause="flight-stack")
def rotor_count_mismatch(ctx: CheckContext) -> Iterator[Issue]:
    """RotorS's autopilot interface plugin forwards one motor command per declared rotor
    (`rotor_count`). More than there are motor plugins and the autopilot mixes for a frame
    that does not exist; fewer and some rotors never spin. A count that is not a whole
    number is reported too: the plugin cannot use it either. PX4 classic's control
    channels declare no count (unused channels are unused outputs; a motor no channel
    fills is R302).

    Severity (error, flight-stack): the autopilot commands motors the model does not have.
    """
    if not ctx.tree_ok:
        return
    found = len(ctx.rotors)
    for declaration in ctx.rotor_count_declarations:
        plugin = declaration.plugin
        if declaration.rotor_count is None:
            yield Issue(f"'{plugin.name}' declares rotor count '{declaration.text}', which is not "
                        f"a whole number; the model has {found} motor plugin"
                        f"{'s' if found != 1 else ''}", declaration.loc, plugin.name,
                        hint=f"set rotor_count to {found}")
        elif declaration.rotor_count != found:
            yield Issue(f"'{plugin.name}' declares {declaration.rotor_count} rotors but the model "
                        f"has {found} motor plugin{'s' if found != 1 else ''}",
                        declaration.loc, plugin.name,
                        hint=f"set rotor_count to {found}")


@rule("R313", "rotor-joint-not-continuous", "error", "A rotor turns on a joint that is not continuous.", clause="cannot-fly")
def rotor_joint_not_continuous(ctx: CheckContext) -> Iterator[Issue]:
    """A motor plugin spins its joint without end: the joint must be `continuous`, or a
    revolute one whose limit in the way it turns is open. A revolute joint stops at its
    limits, a fixed one is merged away by Gazebo and the plugin finds no joint.

    sdformat writes "no limit" as ±1e16, and a rotor turns one way only, so a revolute
    joint whose limit on that side is 1e9 rad or beyond spins like a continuous one: at
    3000 rad/s it would take 92 hours of simulated time to reach it (SITL_Models'
    mini_talon_vtail: -1e-16..1e16, turned positive by its multiplier; SwiftGust's
    Sikorsky X2 blades: ±1e12). The
    way is the sign of the joint velocity the plugin commands: the ArduPilotPlugin's
    multiplier, or the motor model's turningDirection (ccw +1, cw -1).

    Severity (error, cannot-fly): the rotor stops at the limit.
    """
    for rotor in all_rotors(ctx):
        joint = ctx.robot.joint_map.get(rotor.joint or "")
        if joint is not None and joint.type == "revolute" and joint.limit is not None:
            if rotor.kind == "ardupilot":
                way = np.sign(_number_or_nan(rotor.param("multiplier") or "1"))
            else:
                way = rotor.turning_sign
            if (way > 0 and joint.limit.upper >= ROTOR_LIMIT_OPEN_RAD) \
                    or (way < 0 and joint.limit.lower <= -ROTOR_LIMIT_OPEN_RAD):
                continue
        if joint is not None and joint.type != "continuous":
            yield Issue(f"rotor '{rotor.name}' spins joint '{joint.name}', which is {joint.type}",
                        joint.loc, joint.name, hint='use type="continuous"')


@rule("R314", "rotor-plugin-target-missing", "error",
      "A motor plugin names a joint or link that does not exist.", clause="refused")
def rotor_plugin_target_missing(ctx: CheckContext) -> Iterator[Issue]:
    """`<jointName>` and `<linkName>` of a motor plugin must name the rotor's joint and
    link exactly (namespace prefix included); the plugin fails to load otherwise and the
    rotor does not exist in the simulation.

    Severity (error, refused): the plugin finds no joint or link and the rotor never
    turns.
    """
    from reedtool.physics.rotors import resolve_name

    for rotor in all_rotors(ctx):
        for tag, name, table in (("jointName", rotor.param("jointName"), ctx.robot.joint_map),
                                 ("linkName", rotor.param("linkName"), ctx.robot.link_map)):
            if rotor.kind == "ardupilot" and name is not None \
                    and resolve_name(name, table) is not None:
                continue  # ArduPilotPlugin finds scoped and unscoped names alike
            if tag == "jointName" and name is None:
                yield Issue(f"motor plugin '{rotor.plugin.name}' has no <jointName>", rotor.loc,
                            rotor.name, hint="add <jointName> naming the rotor's joint")
            elif name is not None and name not in table:
                import difflib  # here: only a wrong name needs it, not every validate

                close = difflib.get_close_matches(name, list(table), n=1)
                yield Issue(f"motor plugin '{rotor.plugin.name}' <{tag}> '{name}' does not exist",
                            rotor.param_loc(tag), rotor.name,
                            hint=f"did you mean '{close[0]}'?" if close else None)


@rule("R315", "rotor-link-not-joint-child", "error",
      "A motor plugin's link is not the child of its joint.", clause="cannot-fly")
def rotor_link_not_joint_child(ctx: CheckContext) -> Iterator[Issue]:
    """The plugin spins `<jointName>` and applies thrust to `<linkName>`; they must be the
    same rotor: the link is the joint's child. Otherwise thrust is applied to a link that
    does not turn, typically after copying a rotor block and renaming only one of them.

    Severity (error, cannot-fly): thrust is applied to another body than the one that
    spins.
    """
    for rotor in all_rotors(ctx):
        joint = ctx.robot.joint_map.get(rotor.joint or "")
        link = rotor.param("linkName")
        if joint is not None and link is not None and link in ctx.robot.link_map \
                and joint.child != link:
            yield Issue(f"motor plugin '{rotor.plugin.name}': link '{link}' is not the child of "
                        f"joint '{joint.name}' (its child is '{joint.child}')",
                        rotor.param_loc("linkName"), rotor.name,
                        hint=f"<linkName>{joint.child}</linkName>")


@rule("R316", "rotor-constant-invalid", "error",
      "A rotor's motor constant, moment constant or maximum speed is missing or not positive.", clause="cannot-fly")
def rotor_constant_invalid(ctx: CheckContext) -> Iterator[Issue]:
    """`motorConstant` (thrust = k·ω², N/(rad/s)²) and `maxRotVelocity` (rad/s) must be
    positive and `momentConstant` (yaw drag torque per newton of thrust, m) must not be
    negative. Missing values silently fall back to a plugin default that differs between
    RotorS, PX4 and gz-sim; write them out. (ArduPilot rotors have no such elements:
    R317 says what is estimated for them.)

    Severity (error, cannot-fly): the rotor gives no thrust, or pulls down.
    """
    for rotor in filter(_written, all_rotors(ctx)):
        for attr, tag, unit in CONSTANTS:
            value = getattr(rotor, attr)
            raw = rotor.param(tag)
            floor_ok = value >= 0 if attr == "moment_constant" else value > 0
            if raw is None:
                yield Issue(f"rotor '{rotor.name}': no <{tag}>", rotor.loc, rotor.name,
                            hint=f"add <{tag}> ({unit})")
            elif not (math.isfinite(value) and floor_ok):
                yield Issue(f"rotor '{rotor.name}': <{tag}> is '{raw}'",
                            rotor.param_loc(tag), rotor.name,
                            hint=f"a {'non-negative' if attr == 'moment_constant' else 'positive'}"
                                 f" number in {unit}")


# A revolute rotor joint's limit this far out is never reached (3000 rad/s: 92 h).
ROTOR_LIMIT_OPEN_RAD = 1e9
# Beyond this angle between a rotor's joint axis and its thrust axis, "the way it spins
# about its thrust axis" is not defined (the two are closer to perpendicular than parallel).
SPIN_AXIS_UNDEFINED_DEG = 45.0


def joint_axis_angle_deg(ctx: CheckContext, rotor: "Rotor") -> float | None:
    """Angle between the rotor's joint axis (in the base frame) and its thrust axis, folded
    to 0-90° (a joint axis either way spins the same rotor); None when undefined."""
    if not ctx.tree_ok:
        return None
    poses = ctx.link_poses
    joint = ctx.robot.joint_map.get(rotor.joint or "")
    if joint is None or joint.child not in poses or not np.all(np.isfinite(rotor.axis)) \
            or np.linalg.norm(rotor.axis) == 0:
        return None
    axis = np.asarray(joint.axis, dtype=float)
    if not np.all(np.isfinite(axis)) or np.linalg.norm(axis) == 0:
        return None
    axis_base = poses[joint.child][:3, :3] @ (axis / np.linalg.norm(axis))
    cos = abs(float(np.dot(axis_base, rotor.axis / np.linalg.norm(rotor.axis))))
    return math.degrees(math.acos(min(1.0, cos)))


# ------------------------------------------------- families, roles and patterns

# A tilt pattern is balanced when, at equal thrust, the rotors' side forces and tilt yaw
# torques each cancel to within this fraction of their magnitudes.
TILT_BALANCE_REL_TOL = 0.05


def balanced_tilt(ctx: CheckContext):
    """(tilted rotors, tilts in degrees) when several lift rotors are tilted in a pattern
    whose side forces and tilt yaw torques cancel at equal thrust; else None."""
    from reedtool.physics.allocation import tilt_balance

    rotors = [r for r in _lift(ctx) if np.all(np.isfinite(r.axis))
              and np.all(np.isfinite(r.position_m)) and np.linalg.norm(r.axis) > 0]
    tilted = [r for r in rotors if r.tilt_deg > AXIS_TILT_TOL_DEG]
    if len(tilted) < 2 or any(r.tilt_deg > 90 for r in tilted):
        return None
    side, side_abs, yaw, yaw_abs = tilt_balance(rotors, ctx.whole_robot.com_m
                                                if math.isfinite(ctx.whole_robot.mass_kg)
                                                and ctx.whole_robot.mass_kg > 0
                                                else np.zeros(3))
    if side > TILT_BALANCE_REL_TOL * side_abs or yaw > TILT_BALANCE_REL_TOL * max(yaw_abs, 1e-12):
        return None
    return tilted, [r.tilt_deg for r in tilted]


@rule("R317", "rotor-constants-estimated", "info",
      "An ArduPilot rotor's thrust constants are estimated from its LiftDrag blades.", clause="explains")
def rotor_constants_estimated(ctx: CheckContext) -> Iterator[Issue]:
    """ArduPilotPlugin models write no motor constant: thrust comes from LiftDrag plugins
    on the blades. reedtool estimates k_f = sum(0.5·rho·r²·area·cla·a0) over the blades
    (each blade's centre of pressure at radius r moving at omega·r, angle of attack a0),
    the moment constant from their drag (cda·a0) at r, and the top speed from
    |multiplier| (the joint target is multiplier × the [0, 1] command). The hover rules use
    these numbers; LiftDrag in flight also sees the inflow, so the real thrust is lower.
    Without blades the rotor's thrust is unknown and the hover rules are skipped.

    Severity (info, explains): it says how numbers the model does not write were
    estimated.
    """
    for rotor in all_rotors(ctx):
        if rotor.kind != "ardupilot":
            continue
        if rotor.constants_estimated and math.isfinite(rotor.motor_constant):
            yield Issue(f"rotor '{rotor.name}' (channel {rotor.channel}): estimated from "
                        f"{len(rotor.blades)} LiftDrag blade(s): k_f ≈ "
                        f"{_fmt(rotor.motor_constant)} N/(rad/s)², moment constant ≈ "
                        f"{_fmt(rotor.moment_constant)} m, maximum speed "
                        f"{_fmt(rotor.max_rot_velocity_rad_s)} rad/s", rotor.loc, rotor.name)
        else:
            yield Issue(f"rotor '{rotor.name}' (channel {rotor.channel}): no usable LiftDrag "
                        f"blade on link '{rotor.link}', so its thrust is unknown; hover "
                        "physics is not checked", rotor.loc, rotor.name)


@rule("R318", "ardupilot-spin-against-blades", "error",
      "An ArduPilot channel spins its rotor against the way its blades make lift.", clause="cannot-fly")
def ardupilot_spin_against_blades(ctx: CheckContext) -> Iterator[Issue]:
    """The ArduPilotPlugin turns the joint at `multiplier` × command about the joint axis,
    so the multiplier's sign is the spin direction. Each LiftDrag blade makes lift only
    when its centre of pressure moves along its `<forward>` vector; turning the other way
    it pushes down. A multiplier whose sign disagrees with the blades (copying a cw
    rotor's control block onto a ccw rotor) makes that rotor push the vehicle to the
    ground at take-off.

    A rotor whose joint turns about an axis more than 45° from its thrust axis has no
    spin direction about that axis to compare (SITL_Models' alti_transition_quad's forward
    motor turns about the vertical while its blades face forward): R341 reports the axis.

    Severity (error, cannot-fly): the rotor pushes the wrong way.
    """
    for rotor in all_rotors(ctx):
        if rotor.kind != "ardupilot" or rotor.blade_turning_sign == 0 or rotor.turning_sign == 0:
            continue
        angle = joint_axis_angle_deg(ctx, rotor)
        if angle is not None and angle > SPIN_AXIS_UNDEFINED_DEG:
            continue    # the joint does not spin it about its thrust axis: R341 says so
        if rotor.blade_turning_sign != rotor.turning_sign:
            want = "ccw" if rotor.blade_turning_sign > 0 else "cw"
            yield Issue(f"rotor '{rotor.name}' (channel {rotor.channel}): multiplier "
                        f"{rotor.param('multiplier')} spins it {rotor.direction}, but its "
                        f"LiftDrag blades ({rotor.blades[0].plugin.loc}) lift when it turns "
                        f"{want}", _direction_loc(rotor), rotor.name,
                        hint="flip the sign of <multiplier>, or the blades' <forward> vectors")


@rule("R319", "rotor-role", "info",
      "Rotors that are not lift rotors, or an omnidirectional frame.", clause="explains")
def rotor_role(ctx: CheckContext) -> Iterator[Issue]:
    """A rotor whose thrust axis is 60-120° from body z on a vehicle that also has lift
    rotors (or a wing), pointing along body ±x or on a vehicle with a wing, is
    propulsion: a fixed-wing puller or a VTOL pusher. It is
    left out of the hover allocation, the trim and the lift-rotor rules (R304-R311). A
    frame with reversible motors or rotors pointing in every direction is
    omnidirectional: it is judged by the full 6-DoF force-and-torque allocation. Rotors
    carried by an actuated joint (a tilt servo, an arm, a leg: SITL_Models' hexapod_copter
    flies with its rotors where its leg servos put them) have no fixed flight pose: the
    hover rules do not judge them at the model's zero pose.

    Severity (info, explains): it says which rotors the hover rules leave out, and why.
    """
    for rotor in all_rotors(ctx):
        if rotor.role == "propulsion":
            axis = rotor.axis / np.linalg.norm(rotor.axis)
            yield Issue(f"rotor '{rotor.name}' is propulsion (thrust axis "
                        f"{', '.join(f'{v:.3f}' for v in axis)}, {rotor.tilt_deg:.0f}° from "
                        "body z): not used for hover", rotor.loc, rotor.name)
    if ctx.articulated_rotors:
        name, joint = next(iter(ctx.articulated_rotors.items()))
        more = len(ctx.articulated_rotors) - 1
        yield Issue(f"rotor '{name}'{f' and {more} more' if more else ''} ride on actuated "
                    f"joint '{joint}': their flight pose is set by it, so hover, trim, "
                    "allocation and tilt are not judged at the zero pose (R304-R311, R340-R342, "
                    "I220)", _lift(ctx)[0].loc, "rotors")
    if _lift(ctx) and ctx.omnidirectional:
        reversible = sum(r.reversible for r in _lift(ctx))
        yield Issue(f"omnidirectional frame: {len(_lift(ctx))} rotors ({reversible} "
                    "reversible) checked with the 6-DoF force-and-torque allocation",
                    _lift(ctx)[0].loc, "rotors")


@rule("R320", "rotor-tilt-pattern", "info",
      "The rotors are tilted in a balanced pattern.", clause="explains")
def rotor_tilt_pattern(ctx: CheckContext) -> Iterator[Issue]:
    """Some frames tilt every rotor on purpose: the AscTec Neo (RotorS neo9/neo11) tilts
    each rotor 5° sideways, alternating, for more yaw authority; tailsitters tilt theirs
    tangentially. At equal thrust their side forces cancel and so do the yaw torques the
    tilts make through the lever arms. Such a pattern is reported here; a single or
    unbalanced tilt is R311's warning.

    Severity (info, explains): a balanced tilt pattern is a design.
    """
    if ctx.omnidirectional:
        return
    found = balanced_tilt(ctx)
    if found is None:
        return
    tilted, tilts = found
    yield Issue(f"{len(tilted)} rotors tilted {min(tilts):.1f}-{max(tilts):.1f}° in a balanced "
                "pattern (side forces and tilt yaw torques cancel at equal thrust)",
                tilted[0].loc, "rotors")
