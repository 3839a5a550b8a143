"""Flight-stack cross-check rules (C413-C439): the autopilot's rotor table against the model.

The rotor geometry is written twice: in the model (where Gazebo applies thrust) and in
the autopilot's parameters (what the mixer believes). These rules compare the PX4
parameters of `validate --airframe` (reedtool.flightstack.px4) and the ArduPilot frame of
`validate --autopilot-params` (reedtool.flightstack.ardupilot) with the model's lift
rotors. Every finding names both places: the parameter line (the finding's location)
and the model element (in the message).

Matching. PX4: CA rotor i is driven through the gz ESC output k whose SIM_GZ_EC_FUNCk is
101 + i; output k commands the model's motor with actuator number k - 1 (a file without
SIM_GZ_EC_FUNC parameters is taken as CA rotor i on actuator i). ArduPilot: motor m is on
the servo output whose SERVOn_FUNCTION is 32 + m (default: output m); a model with the
ArduPilotPlugin reads output c + 1 in `<control channel="c">`, a model without it is
matched by motor number (motor m = actuator m - 1).

Which Gazebo. PX4 commands a Gazebo Sim model through the gz bridge, output k = the speed
between SIM_GZ_EC_MINk and SIM_GZ_EC_MAXk; a Gazebo Classic model through simulator_mavlink
and the model's gazebo_mavlink_interface, speed = (u + input_offset) * input_scaling +
zero_position_armed of its control channel (SIM_GZ_EC_* are never read). The command-range
rules use the one that applies (C419-C424 for gz, C436-C438 for Classic); an airframe for
the other Gazebo is one finding (C435), not a cascade. C439: a gz model PX4's bridge cannot
reach (no base_link, motors off command/motor_speed).

Positions are compared as PX4 does its allocation: about the centre of gravity, in FRD
(x forward, y right, z down). A position that differs but keeps the rotor in the same
quadrant within 20° of bearing still allocates roll and pitch with the right signs
(information: PX4's x500 airframe describes the real frame, its model a 45° square); a
different quadrant or a larger bearing error gives torque of the wrong sign (error).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Iterator

import numpy as np

from reedtool.checks.context import CheckContext
from reedtool.checks.finding import Issue
from reedtool.checks.registry import rule
from reedtool.checks.rotor_rules import physics_ready

if TYPE_CHECKING:
    from reedtool.flightstack.ardupilot import ArduPilotParams
    from reedtool.flightstack.px4 import Px4Params, Px4Rotor
    from reedtool.physics.rotors import Rotor

BEARING_TOL_DEG = 20.0          # allocation signs survive a bearing error up to this
POSITION_INFO_M = 0.005          # smaller position differences are not worth a line
AXIS_TOL_DEG = 10.0
AXIS_ERROR_DEG = 60.0           # beyond: less than half the thrust goes where PX4 expects
RANGE_REL_TOL = 1e-3
KM_REL_TOL = 0.01
HOVER_THROTTLE_TOL = 0.15
SPIN_NAME = {1: "ccw", -1: "cw", 0: "no yaw factor"}


# --------------------------------------------------------------- model side

def _lift_rotors(ctx: CheckContext) -> list["Rotor"]:
    if not ctx.tree_ok:
        return []
    return [r for r in ctx.rotors if getattr(r, "role", "lift") == "lift"]


def _all_rotors(ctx: CheckContext) -> list["Rotor"]:
    """Every motor: PX4's CA_ROTOR table lists lift rotors and pushers/pullers alike."""
    return ctx.rotors if ctx.tree_ok else []


def _actuator(rotor: "Rotor") -> int | None:
    return rotor.motor_number


def _rotor_label(rotor: "Rotor") -> str:
    if _channel(rotor) is not None:
        number = f"rotor on channel {_channel(rotor)}"
    else:
        number = f"motor {rotor.motor_number}" if rotor.motor_number is not None else "motor"
    return f"the model's {number} ('{rotor.joint or rotor.link}', {rotor.loc})"


def _com(ctx: CheckContext) -> np.ndarray:
    whole = ctx.whole_robot
    com = np.asarray(whole.com_m, dtype=float)
    return com if np.all(np.isfinite(com)) else np.zeros(3)


def _frd_about_com(ctx: CheckContext, rotor: "Rotor") -> np.ndarray:
    from reedtool.flightstack.px4 import frd_from_flu

    return frd_from_flu(rotor.position_m - _com(ctx))


def _bearing(p_frd: np.ndarray) -> float:
    return math.degrees(math.atan2(p_frd[1], p_frd[0]))


def _gap(a_deg: float, b_deg: float) -> float:
    return abs((a_deg - b_deg + 180.0) % 360.0 - 180.0)


def _same_quadrant(a: np.ndarray, b: np.ndarray) -> bool:
    """Same sign of x and of y, where the component is more than 5 % of the arm."""
    for axis in (0, 1):
        scale = 0.05 * max(math.hypot(a[0], a[1]), math.hypot(b[0], b[1]))
        if abs(a[axis]) > scale and abs(b[axis]) > scale and a[axis] * b[axis] < 0:
            return False
    return True


def _px4(ctx: CheckContext) -> list["Px4Params"]:
    return [p for p in ctx.flight_params if p.kind == "px4"] if ctx.tree_ok else []


def _ardupilot(ctx: CheckContext) -> list["ArduPilotParams"]:
    return [p for p in ctx.flight_params if p.kind == "ardupilot"] if ctx.tree_ok else []


def _px4_kind(params: "Px4Params"):
    """The effectiveness class CA_AIRFRAME selects, when it reads a rotor table."""
    from reedtool.flightstack.px4 import effectiveness

    kind = effectiveness(params)
    return kind if kind is not None and kind.rotor_table else None


def _model_simulator(ctx: CheckContext):
    """(simulator, what says so) of the model: Classic with a MAVLink interface or Classic
    motor plugins (PX4's gazebo_motor_model, RotorS'), gz with gz-sim motor systems."""
    from reedtool.physics.rotors import MAVLINK_PLUGINS

    for _block, plugin in ctx.robot.plugins():
        if plugin.library in MAVLINK_PLUGINS:
            return "classic", f"its {plugin.filename} ({plugin.loc})"
    for rotor in _all_rotors(ctx):
        if rotor.kind in ("px4", "rotors"):
            return "classic", f"its Classic motor plugin {rotor.plugin.filename} ({rotor.loc})"
        if rotor.kind == "gz":
            return "gz", f"its gz-sim motor system ({rotor.loc})"
    return None


def _simulator(ctx: CheckContext, params: "Px4Params") -> str | None:
    """The Gazebo whose command path applies: 'gz' or 'classic'; None when model and
    airframe are for different ones (C435 says so, the command rules stay silent)."""
    model = _model_simulator(ctx)
    airframe = params.simulator()
    if model is not None and airframe is not None and model[0] != airframe.simulator:
        return None
    if model is not None:
        return model[0]
    return airframe.simulator if airframe is not None else "gz"


def _px4_pairs(ctx: CheckContext, params: "Px4Params"
               ) -> list[tuple["Px4Rotor", int, "Rotor"]]:
    """(CA rotor, output k, model rotor output k drives) for every connected pair; none
    when CA_AIRFRAME selects no rotor table (rovers, helicopters). gz: output k (by
    SIM_GZ_EC_FUNC) drives actuator k-1. Classic: output k (by PWM_MAIN_FUNC) feeds the
    mavlink channels of input_index k-1, read by the motor of the channel's position
    (motor k-1 without channels)."""
    from reedtool.flightstack.px4 import mavlink_channels

    if _px4_kind(params) is None:
        return []
    by_actuator = {_actuator(r): r for r in _all_rotors(ctx) if _actuator(r) is not None}
    classic = params.simulator() is not None and params.simulator().simulator == "classic" \
        or (not params.uses_gz_outputs and (_model_simulator(ctx) or ("",))[0] == "classic")
    channels = mavlink_channels(ctx.robot) if classic else []
    pairs = []
    for ca in params.rotors():
        if not classic:
            outputs = params.outputs_of(ca.index) if params.uses_gz_outputs else [ca.index + 1]
            pairs += [(ca, k, by_actuator[k - 1]) for k in outputs if k - 1 in by_actuator]
            continue
        for k in params.classic_outputs_of(ca.index):
            motors = [c.position for c in channels if c.input_index == k - 1] \
                if channels else [k - 1]
            pairs += [(ca, k, by_actuator[m]) for m in motors if m in by_actuator]
    return pairs


def _gz_commands(ctx: CheckContext, params: "Px4Params") -> bool:
    return _simulator(ctx, params) == "gz"


# --------------------------------------------------------------- PX4: table shape

@rule("C413", "px4-rotor-count", "error",
      "CA_ROTOR_COUNT differs from the number of rotors in the model.", clause="flight-stack")
def px4_rotor_count(ctx: CheckContext) -> Iterator[Issue]:
    """PX4's control allocation builds one effectiveness column per CA rotor. With fewer
    CA rotors than motors in the model, some motors are never commanded; with more, PX4
    allocates thrust to rotors that do not exist. Either way the vehicle cannot hover.
    A missing CA_ROTOR_COUNT is PX4's default 0. Pushers and pullers count: PX4 lists
    every rotor (a standard VTOL has five).

    Severity (error, flight-stack): PX4 allocates thrust to rotors the model does not
    have, or leaves some unused.
    """
    rotors = _all_rotors(ctx)
    for params in _px4(ctx):
        count = params.get("CA_ROTOR_COUNT")
        if not rotors or count.value == len(rotors) or _px4_kind(params) is None:
            continue
        where = ", ".join(str(r.loc) for r in rotors[:4]) + (", ..." if len(rotors) > 4 else "")
        yield Issue(f"{count.describe()}, but the model has "
                    f"{len(rotors)} rotor(s) ({where})", count.loc, "CA_ROTOR_COUNT",
                    hint=f"param set-default CA_ROTOR_COUNT {len(rotors)}")


@rule("C414", "px4-output-mapping", "error",
      "A CA rotor and the model's motors are not connected one to one through SIM_GZ_EC_FUNC.", clause="flight-stack")
def px4_output_mapping(ctx: CheckContext) -> Iterator[Issue]:
    """For Gazebo SITL, PX4 sends the command of ESC output k to the model's motor with
    actuator number k-1, and output k carries CA rotor i when SIM_GZ_EC_FUNCk is 101 + i
    ("Motor i+1"). A CA rotor on no output is never spun; an output whose motor does not
    exist in the model spins nothing; a model motor on no motor output never turns.

    Severity (error, flight-stack): PX4 commands a motor the model does not have, or
    never commands one it has.
    """
    rotors = _all_rotors(ctx)
    by_actuator = {_actuator(r): r for r in rotors if _actuator(r) is not None}
    for params in _px4(ctx):
        if not rotors or not params.uses_gz_outputs or not _gz_commands(ctx, params):
            continue
        # Here, not at the top: without a PX4 parameter file the table is never loaded.
        from reedtool.flightstack.px4 import MAX_GZ_OUTPUTS, MOTOR_FUNCTION_BASE

        ca_count = min(params.rotor_count or 0, 12)
        for i in range(ca_count):
            if not params.outputs_of(i):
                yield Issue(f"CA rotor {i} (Motor {i + 1}, CA_ROTOR_COUNT at "
                            f"{params.get('CA_ROTOR_COUNT').loc}) is on no gz ESC output: no "
                            f"SIM_GZ_EC_FUNCk is {MOTOR_FUNCTION_BASE + i}",
                            params.get("CA_ROTOR_COUNT").loc, f"CA_ROTOR{i}",
                            hint=f"set SIM_GZ_EC_FUNCk {MOTOR_FUNCTION_BASE + i} on the output "
                                 "k = the model motor's actuator number + 1")
        driven = set()
        for k in range(1, MAX_GZ_OUTPUTS + 1):
            func = params.get(f"SIM_GZ_EC_FUNC{k}")
            ca_index = int(func.value) - MOTOR_FUNCTION_BASE if func.explicit else -1
            if not 0 <= ca_index < ca_count:
                continue
            driven.add(k - 1)
            if k - 1 not in by_actuator:
                yield Issue(f"SIM_GZ_EC_FUNC{k} {func.value:g} ({func.loc}) sends CA rotor "
                            f"{ca_index} to actuator {k - 1}, but no motor in the model has "
                            f"actuator number {k - 1} (it has "
                            f"{sorted(a for a in by_actuator if a is not None)})",
                            func.loc, f"SIM_GZ_EC_FUNC{k}",
                            hint="output k drives the motor with actuator number k-1")
        for actuator, rotor in sorted(by_actuator.items()):
            if actuator not in driven:
                yield Issue(f"{_rotor_label(rotor)} has actuator number {actuator}, but "
                            f"SIM_GZ_EC_FUNC{actuator + 1} in {params.label} carries no CA "
                            "rotor: this motor never turns", params.loc, rotor.name,
                            hint=f"param set-default SIM_GZ_EC_FUNC{actuator + 1} "
                                 f"{MOTOR_FUNCTION_BASE}+CA index")


# --------------------------------------------------------------- PX4: per rotor

def _describes_other(ctx: CheckContext, params: "Px4Params", ca: "Px4Rotor",
                     rotor: "Rotor") -> str:
    for other in _all_rotors(ctx):
        if other is rotor:
            continue
        p = _frd_about_com(ctx, other)
        if _gap(_bearing(ca.position_frd_m), _bearing(p)) <= BEARING_TOL_DEG \
                and _same_quadrant(ca.position_frd_m, p) \
                and np.sign(ca.km) == other.turning_sign:
            return (f"CA_ROTOR{ca.index} describes {_rotor_label(other)}: CA rotor i must "
                    "describe the motor its output drives (swap the CA_ROTOR entries or "
                    f"the {'SIM_GZ_EC_FUNC' if _gz_commands(ctx, params) else 'PWM_MAIN_FUNC'} "
                    "values)")
    return ""


@rule("C415", "px4-rotor-position", "error",
      "A CA rotor sits in another quadrant, or more than 20° of bearing away, than its motor.", clause="flight-stack")
def px4_rotor_position(ctx: CheckContext) -> Iterator[Issue]:
    """CA_ROTORi_PX/PY are the rotor's position in FRD (x forward, y right) about the
    centre of gravity. PX4 derives each rotor's roll and pitch effectiveness from them;
    a rotor placed in another quadrant (or far from its real bearing) gets torque of the
    wrong sign and the first take-off flips. The model's rotor is taken about the
    whole-robot centre of mass, with y and z negated (FLU to FRD). Two swapped CA_ROTOR
    entries show up here, one finding per entry.

    Severity (error, flight-stack): PX4 commands the wrong motor for a roll or pitch.
    """
    for params in _px4(ctx):
        for ca, k, rotor in _px4_pairs(ctx, params):
            model = _frd_about_com(ctx, rotor)
            axis = _ca_axis(params, ca)
            if axis is None:
                continue
            if not _upward(axis):
                conflict = _moment_conflict(ca, axis.axis_frd, model, rotor)
                if conflict:
                    yield Issue(f"{ca.where('PX', 'PY', 'PZ')} with thrust axis "
                                f"({_vec(axis.axis_frd)}) ({axis.text}) gives a {conflict} "
                                f"torque of the other sign than {_rotor_label(rotor)} on "
                                f"output {k}, at ({_vec(model)}) m thrusting along "
                                f"({_vec(_model_axis(rotor))}) (FRD about the COM)",
                                ca.loc_of("PX"), f"CA_ROTOR{ca.index}",
                                hint=f"param set-default CA_ROTOR{ca.index}_PX {model[0]:.4g}; "
                                     f"CA_ROTOR{ca.index}_PY {model[1]:.4g}; "
                                     f"CA_ROTOR{ca.index}_PZ {model[2]:.4g}")
                continue
            ca_bearing, model_bearing = _bearing(ca.position_frd_m), _bearing(model)
            gap = _gap(ca_bearing, model_bearing)
            if gap <= BEARING_TOL_DEG and _same_quadrant(ca.position_frd_m, model):
                continue
            hint = _describes_other(ctx, params, ca, rotor) or (
                f"param set-default CA_ROTOR{ca.index}_PX {model[0]:.4g}; "
                f"CA_ROTOR{ca.index}_PY {model[1]:.4g}")
            yield Issue(f"{ca.where('PX', 'PY')}: bearing {ca_bearing:.1f}° from the nose, but "
                        f"{_rotor_label(rotor)} on output {k} sits at x {model[0]:.4g}, "
                        f"y {model[1]:.4g} m (FRD about the COM), bearing "
                        f"{model_bearing:.1f}° ({gap:.1f}° apart)",
                        ca.loc_of("PX"), f"CA_ROTOR{ca.index}", hint=hint)


@rule("C423", "px4-rotor-position-offset", "info",
      "A CA rotor's position differs from its motor's, without changing allocation signs.", clause="explains")
def px4_rotor_position_offset(ctx: CheckContext) -> Iterator[Issue]:
    """A CA position in the right quadrant and within 20° of the model rotor's bearing
    allocates roll and pitch with the right signs, only with slightly different gains.
    That is common and often deliberate: PX4's own x500 airframe describes the real
    frame's rotor positions while the x500 Gazebo model places its rotors on a 45° square.
    Reported so the numbers can be compared; differences under 5 mm are not reported.

    Severity (info, explains): the allocation keeps its signs; only the gains differ.
    """
    for params in _px4(ctx):
        for ca, k, rotor in _px4_pairs(ctx, params):
            axis = _ca_axis(params, ca)
            if axis is None or not _upward(axis):
                continue
            model = _frd_about_com(ctx, rotor)
            gap = _gap(_bearing(ca.position_frd_m), _bearing(model))
            if gap > BEARING_TOL_DEG or not _same_quadrant(ca.position_frd_m, model):
                continue
            delta = float(np.linalg.norm(ca.position_frd_m[:2] - model[:2]))
            if delta <= POSITION_INFO_M:
                continue
            yield Issue(f"{ca.where('PX', 'PY')} vs {_rotor_label(rotor)} at x {model[0]:.4g}, "
                        f"y {model[1]:.4g} m (FRD about the COM): {1000 * delta:.0f} mm and "
                        f"{gap:.1f}° of bearing apart; the allocation keeps its signs",
                        ca.loc_of("PX"), f"CA_ROTOR{ca.index}")


@rule("C416", "px4-rotor-spin", "error",
      "The sign of CA_ROTORi_KM disagrees with its motor's turning direction.", clause="flight-stack")
def px4_rotor_spin(ctx: CheckContext) -> Iterator[Issue]:
    """CA_ROTORi_KM is the yaw moment per thrust, positive for a rotor turning
    counter-clockwise seen from above and negative for clockwise (PX4 parameter reference,
    control_allocator module.yaml). A sign that disagrees with the model's
    turningDirection makes PX4 yaw the wrong way with that rotor: on take-off the vehicle
    spins up in yaw. An unset KM is PX4's default 0.05 (counter-clockwise).

    Only where PX4 uses KM: not on a fixed-wing (CA_AIRFRAME 1 disables propeller torque),
    not for a standard VTOL's pusher (CA_AIRFRAME 2 drops the
    propeller torque of rotors that are not upward), a tailsitter with 3 rotors or fewer, or
    a tiltrotor whose tilt servos control yaw (CA_SV_TLk_CT 1 or 3).

    Severity (error, flight-stack): PX4 yaws with the motor the other way.
    """
    for params in _px4(ctx):
        for ca, k, rotor in _px4_pairs(ctx, params):
            if rotor.turning_sign == 0 or ca.km == 0 or not math.isfinite(ca.km) \
                    or not _uses_km(params, ca):
                continue
            if int(np.sign(ca.km)) != rotor.turning_sign:
                yield Issue(f"{ca.where('KM')} says {SPIN_NAME[int(np.sign(ca.km))]}, but "
                            f"{_rotor_label(rotor)} on output {k} turns "
                            f"{SPIN_NAME[rotor.turning_sign]} (turningDirection at "
                            f"{rotor.param_loc(rotor.direction_tag)})",
                            ca.loc_of("KM"), f"CA_ROTOR{ca.index}",
                            hint=f"param set-default CA_ROTOR{ca.index}_KM {-ca.km:g}, or fix "
                                 "the motor's turningDirection if PX4 is right")


@rule("C417", "px4-moment-ratio", "info",
      "|CA_ROTORi_KM| differs from the motor's momentConstant.", clause="explains")
def px4_moment_ratio(ctx: CheckContext) -> Iterator[Issue]:
    """|KM| is PX4's yaw moment per thrust, the same quantity as the motor model's
    momentConstant. A different value scales PX4's yaw effectiveness, which the yaw
    rate controller's gains absorb: PX4's own gz airframes use 0.05 against models with
    0.016. Reported with both numbers, as information.

    Severity (info, explains): a yaw gain that the rate controller's tuning absorbs.
    """
    for params in _px4(ctx):
        for ca, k, rotor in _px4_pairs(ctx, params):
            model = rotor.moment_constant
            if not (math.isfinite(model) and model > 0 and math.isfinite(ca.km)) \
                    or not _uses_km(params, ca):
                continue
            if abs(abs(ca.km) - model) > KM_REL_TOL * model:
                yield Issue(f"{ca.where('KM')} vs momentConstant {model:g} of "
                            f"{_rotor_label(rotor)} ({rotor.param_loc('momentConstant')})"
                            f": PX4's yaw effectiveness is {abs(ca.km) / model:.3g}x the model's",
                            ca.loc_of("KM"), f"CA_ROTOR{ca.index}")


def _ca_axis(params: "Px4Params", ca: "Px4Rotor"):
    """PX4's hover thrust axis for CA rotor i (reedtool.flightstack.px4.rotor_axis)."""
    from reedtool.flightstack.px4 import rotor_axis

    kind = _px4_kind(params)
    return rotor_axis(params, ca, kind) if kind is not None else None


def _upward(axis) -> bool:
    from reedtool.flightstack.px4 import is_upward

    return is_upward(axis.axis_frd)


def _uses_km(params: "Px4Params", ca: "Px4Rotor") -> bool:
    from reedtool.flightstack.px4 import uses_yaw_moment

    axis, kind = _ca_axis(params, ca), _px4_kind(params)
    return axis is not None and uses_yaw_moment(params, kind, axis)


def _model_axis(rotor: "Rotor") -> np.ndarray:
    from reedtool.flightstack.px4 import frd_from_flu

    axis = frd_from_flu(rotor.axis)
    norm = float(np.linalg.norm(axis))
    return axis / norm if norm > 0 and math.isfinite(norm) else axis


def _vec(v) -> str:
    return ", ".join(f"{x:.3g}" for x in np.asarray(v, dtype=float) + 0.0)


def _moment_conflict(ca: "Px4Rotor", ca_axis: np.ndarray, model_p: np.ndarray,
                     rotor: "Rotor") -> str:
    """'roll', 'pitch' or 'yaw' when PX4's torque per thrust (position x axis) and the
    model's have a component of opposite sign, both beyond 20 % of the longer arm."""
    ours = np.cross(ca.position_frd_m, ca_axis)
    theirs = np.cross(model_p, _model_axis(rotor))
    scale = 0.2 * max(float(np.linalg.norm(ca.position_frd_m)), float(np.linalg.norm(model_p)))
    for i, name in enumerate(("roll", "pitch", "yaw")):
        if abs(ours[i]) > scale and abs(theirs[i]) > scale and ours[i] * theirs[i] < 0:
            return name
    return ""


def _axis_angles(ctx: CheckContext):
    """(params, CA rotor, output, model rotor, PX4 axis, angle in degrees) per pair."""
    for params in _px4(ctx):
        for ca, k, rotor in _px4_pairs(ctx, params):
            axis = _ca_axis(params, ca)
            model = _model_axis(rotor)
            if axis is None or not np.all(np.isfinite(model)) or np.linalg.norm(model) == 0:
                continue
            cos = float(np.dot(axis.axis_frd, model))
            yield params, ca, k, rotor, axis, math.degrees(math.acos(max(-1.0, min(1.0, cos))))


def _axis_message(ca: "Px4Rotor", rotor: "Rotor", axis, angle: float) -> str:
    return (f"PX4 allocates CA rotor {ca.index} along ({_vec(axis.axis_frd)}) in FRD "
            f"({axis.text}): {angle:.1f}° from {_rotor_label(rotor)}'s thrust axis "
            f"({_vec(_model_axis(rotor))})")


def _axis_hint(ca: "Px4Rotor", rotor: "Rotor", axis) -> str | None:
    model = _model_axis(rotor)
    if axis.source != "parameters":
        return "CA_AIRFRAME fixes this axis: choose the CA_AIRFRAME of the vehicle, or turn " \
               "the rotor in the model"
    return (f"CA_ROTOR{ca.index}_AX {model[0]:.3g}, _AY {model[1]:.3g}, _AZ {model[2]:.3g}")


@rule("C418", "px4-thrust-axis", "error",
      "PX4 allocates a rotor along an axis more than 60° from the model's.",
      clause="flight-stack")
def px4_thrust_axis(ctx: CheckContext) -> Iterator[Issue]:
    """The thrust axis PX4 allocates CA rotor i with depends on CA_AIRFRAME
    (ActuatorEffectivenessRotors' axis configuration): multirotor, standard VTOL,
    tailsitter and custom airframes read CA_ROTORi_AX/AY/AZ (default 0, 0, -1: up);
    fixed-wing fixes every rotor forward (1, 0, 0) and ignores the parameters; a tiltrotor's
    rotor with CA_ROTORi_TILT follows its tilt servo (hover: the servo's minimum angle
    CA_SV_TLk_MINA in direction CA_SV_TLk_TD). The model's rotor thrusts along its link's z
    axis, in FRD (x, -y, -z).

    Severity (error, flight-stack): more than 60° apart, less than half of the thrust PX4
    counts on goes where it expects (cos 60° = 0.5): PX4 uses the rotor for an axis it
    does not serve (a pusher for lift, a lift rotor for forward thrust) and the vehicle
    cannot hover or fly as commanded. 10°-60° is C426 (warning) or C427 (information).
    """
    for params, ca, k, rotor, axis, angle in _axis_angles(ctx):
        if angle > AXIS_ERROR_DEG:
            yield Issue(_axis_message(ca, rotor, axis, angle), _axis_loc(params, ca, axis),
                        f"CA_ROTOR{ca.index}", hint=_axis_hint(ca, rotor, axis))


def _axis_loc(params: "Px4Params", ca: "Px4Rotor", axis):
    if axis.source == "parameters":
        return ca.loc_of("AZ")
    return params.get("CA_AIRFRAME").loc


def _axis_ignored(ctx: CheckContext, axis) -> bool:
    """PX4 cannot be told the tilt (a fixed axis), or the model's tilt is a balanced
    pattern (R320) whose side forces cancel: leaving it out of PX4's table is the
    convention (PX4's quadtailsitter)."""
    from reedtool.checks.rotor_rules import balanced_tilt

    return axis.source != "parameters" or balanced_tilt(ctx) is not None


@rule("C426", "px4-thrust-axis-offset", "warning",
      "A CA rotor's configured thrust axis is 10°-60° from its motor's.", clause="suspicious")
def px4_thrust_axis_offset(ctx: CheckContext) -> Iterator[Issue]:
    """As C418, for an axis PX4 reads from CA_ROTORi_AX/AY/AZ that is 10°-60° from the
    model rotor's, where the model's tilt is not a balanced pattern: PX4 puts a force and a
    torque into its allocation that the vehicle does not produce, so attitude and position
    control fight a steady error.

    Severity (warning: suspicious, but the vehicle loads and flies): most of the thrust
    still goes where PX4 expects it. The hint gives the axis to write.
    """
    for params, ca, k, rotor, axis, angle in _axis_angles(ctx):
        if AXIS_TOL_DEG < angle <= AXIS_ERROR_DEG and not _axis_ignored(ctx, axis):
            yield Issue(_axis_message(ca, rotor, axis, angle), _axis_loc(params, ca, axis),
                        f"CA_ROTOR{ca.index}", hint=_axis_hint(ca, rotor, axis))


@rule("C427", "px4-thrust-axis-fixed", "info",
      "A rotor is tilted 10°-60° from the axis PX4 fixes or assumes for it, by convention.",
      clause="ambiguous")
def px4_thrust_axis_fixed(ctx: CheckContext) -> Iterator[Issue]:
    """As C426, where the difference is the convention rather than a mistake: CA_AIRFRAME
    fixes the axis (fixed-wing: forward), so there is no parameter to set, or the model's
    rotors are tilted in a balanced pattern (R320: side forces and tilt torques cancel at
    equal thrust, as on PX4's own quadtailsitter with its 0.17 rad tilts) that PX4's table
    leaves out on purpose.

    Severity (information): reedtool cannot tell the convention from a mistake here, so it
    says what it sees.
    """
    for params, ca, k, rotor, axis, angle in _axis_angles(ctx):
        if AXIS_TOL_DEG < angle <= AXIS_ERROR_DEG and _axis_ignored(ctx, axis):
            yield Issue(_axis_message(ca, rotor, axis, angle), _axis_loc(params, ca, axis),
                        f"CA_ROTOR{ca.index}")


# --------------------------------------------------------------- PX4: command range

@rule("C419", "px4-command-above-max", "warning",
      "SIM_GZ_EC_MAX is above the motor's maxRotVelocity: the top of the range does nothing.", clause="suspicious")
def px4_command_above_max(ctx: CheckContext) -> Iterator[Issue]:
    """The gz bridge scales PX4's motor output 0..1 to SIM_GZ_EC_MINk..SIM_GZ_EC_MAXk rad/s
    and the motor model clamps the command at maxRotVelocity. With MAX above that limit,
    the top of PX4's output range changes nothing: PX4's mixer believes it has thrust in
    reserve that does not exist, and saturation goes unnoticed (px4vision: 1100 against
    1000, 9 % of the range lost).

    Severity (warning, suspicious): the vehicle flies; PX4 believes in a reserve of
    thrust that does not exist.
    """
    for params in _px4(ctx):
        if not _gz_commands(ctx, params):
            continue
        for ca, k, rotor in _px4_pairs(ctx, params):
            high, low = params.get(f"SIM_GZ_EC_MAX{k}"), params.get(f"SIM_GZ_EC_MIN{k}")
            limit = rotor.max_rot_velocity_rad_s
            if not math.isfinite(limit) or high.value <= limit * (1 + RANGE_REL_TOL):
                continue
            lost = (high.value - limit) / max(high.value - low.value, 1e-9)
            written = str(high.loc) if high.explicit else "PX4's default"
            yield Issue(f"SIM_GZ_EC_MAX{k} {high.value:g} rad/s ({written}) is above "
                        f"maxRotVelocity {limit:g} of {_rotor_label(rotor)} "
                        f"({rotor.param_loc('maxRotVelocity')}): the top "
                        f"{100 * lost:.0f} % of the command range does nothing",
                        high.loc, f"SIM_GZ_EC_MAX{k}",
                        hint=f"param set-default SIM_GZ_EC_MAX{k} {limit:g}")


@rule("C424", "px4-command-below-max", "warning",
      "SIM_GZ_EC_MAX is below the motor's maxRotVelocity: full thrust is never reached.", clause="suspicious")
def px4_command_below_max(ctx: CheckContext) -> Iterator[Issue]:
    """With SIM_GZ_EC_MAXk below maxRotVelocity, PX4's full output commands less than the
    motor's top speed; thrust grows with speed squared, so the vehicle has
    (MAX / maxRotVelocity)² of the thrust the model was built with. That may be a
    deliberate limit; the finding gives the fraction.

    Severity (warning, suspicious): it may be a deliberate limit; the vehicle flies with
    less thrust.
    """
    for params in _px4(ctx):
        if not _gz_commands(ctx, params):
            continue
        for ca, k, rotor in _px4_pairs(ctx, params):
            high = params.get(f"SIM_GZ_EC_MAX{k}")
            limit = rotor.max_rot_velocity_rad_s
            if not math.isfinite(limit) or high.value >= limit * (1 - RANGE_REL_TOL) \
                    or high.value <= 0:
                continue
            written = str(high.loc) if high.explicit else "PX4's default"
            yield Issue(f"SIM_GZ_EC_MAX{k} {high.value:g} rad/s ({written}) is below "
                        f"maxRotVelocity {limit:g} of {_rotor_label(rotor)} "
                        f"({rotor.param_loc('maxRotVelocity')}): PX4 reaches "
                        f"{100 * (high.value / limit) ** 2:.0f} % of the rotor's thrust",
                        high.loc, f"SIM_GZ_EC_MAX{k}",
                        hint=f"param set-default SIM_GZ_EC_MAX{k} {limit:g}")


def _hover_speeds(ctx: CheckContext) -> dict[int, float] | None:
    """id(rotor) -> hover speed [rad/s] from the static trim, or None."""
    if not physics_ready(ctx):
        return None
    trim = ctx.trim
    if not trim.feasible:
        return None
    for rotors in (ctx.rotors, _lift_rotors(ctx)):   # the trim's rotors: all, or lift only
        if len(trim.omega_rad_s) == len(rotors):
            return {id(r): float(w) for r, w in zip(rotors, trim.omega_rad_s)}
    return None


@rule("C420", "px4-idle-command", "error",
      "SIM_GZ_EC_MIN is not below the motor's hover speed (or not below SIM_GZ_EC_MAX).", clause="flight-stack")
def px4_idle_command(ctx: CheckContext) -> Iterator[Issue]:
    """SIM_GZ_EC_MINk is the rotor speed at PX4's zero output once armed. At or above the
    speed the rotor needs to hover the vehicle climbs at zero throttle and cannot
    descend; at or above SIM_GZ_EC_MAXk the command range is empty. A reversible rotor
    (PX4's omnicopter) is commanded both ways and has no idle speed to compare.

    Severity (error, flight-stack): PX4 cannot command the motor below what it needs.
    """
    hover = _hover_speeds(ctx)
    for params in _px4(ctx):
        if not _gz_commands(ctx, params):
            continue
        for ca, k, rotor in _px4_pairs(ctx, params):
            low, high = params.get(f"SIM_GZ_EC_MIN{k}"), params.get(f"SIM_GZ_EC_MAX{k}")
            if low.value >= high.value:
                yield Issue(f"{low.describe()} is not below {high.describe()}: output {k} "
                            f"({_rotor_label(rotor)}) has no command range", low.loc,
                            f"SIM_GZ_EC_MIN{k}", hint="idle is usually 10-20 % of the maximum")
            elif hover and id(rotor) in hover and not rotor.reversible \
                    and low.value >= hover[id(rotor)]:
                yield Issue(f"{low.describe()} rad/s is at or above "
                            f"the {hover[id(rotor)]:.0f} rad/s {_rotor_label(rotor)} needs to "
                            "hover: at zero throttle the vehicle still climbs", low.loc,
                            f"SIM_GZ_EC_MIN{k}",
                            hint=f"an idle well below {hover[id(rotor)]:.0f} rad/s")


def _hover_throttle(ctx: CheckContext, params: "Px4Params") -> tuple[float, float] | None:
    """(the collective thrust setpoint the model needs at hover, MPC_THR_HOVER)."""
    from reedtool.flightstack.px4 import thrust_fraction

    hover = _hover_speeds(ctx)
    pairs = _px4_pairs(ctx, params)
    simulator = _simulator(ctx, params)
    if not hover or not pairs or ctx.omnidirectional or simulator is None:
        return None     # 6-DoF hover (reversible rotors): no single collective throttle
    factor = params.get("THR_MDL_FAC").value
    needed = []
    for ca, k, rotor in pairs:
        if simulator == "gz":
            low, high = params.get(f"SIM_GZ_EC_MIN{k}").value, params.get(f"SIM_GZ_EC_MAX{k}").value
        else:
            channel = _channel_of(ctx, rotor)
            if channel is None:
                return None
            low, high = channel.range_rad_s()
        if id(rotor) not in hover:
            continue                                 # a pusher: not part of the hover
        if high <= low:
            return None
        u = (hover[id(rotor)] - low) / (high - low)
        needed.append(thrust_fraction(min(max(u, 0.0), 1.0), factor))
    if not needed:
        return None
    return float(np.mean(needed)), params.get("MPC_THR_HOVER").value


def _ranges(ctx: CheckContext, params: "Px4Params") -> str:
    return "SIM_GZ_EC_MIN/MAX" if _simulator(ctx, params) == "gz" else \
        "the mavlink interface's channels"


def _hover_message(params: "Px4Params", needed: float, setting: float,
                   ranges: str = "SIM_GZ_EC_MIN/MAX") -> str:
    value = params.get("MPC_THR_HOVER")
    written = str(value.loc) if value.explicit else "not set: PX4's default"
    return (f"MPC_THR_HOVER {setting:.2f} ({written}); the model hovers at a thrust setpoint "
            f"of {needed:.3f} (trim speeds through {ranges} and THR_MDL_FAC "
            f"{params.get('THR_MDL_FAC').value:g}), {abs(needed - setting):.3f} apart")


@rule("C421", "px4-hover-throttle", "info",
      "MPC_THR_HOVER and the throttle the model needs at hover, side by side.", clause="explains")
def px4_hover_throttle(ctx: CheckContext) -> Iterator[Issue]:
    """MPC_THR_HOVER is the collective thrust PX4 starts from in position control
    (it learns the real value in flight when MPC_USE_HTE is on). reedtool computes what
    the model needs: each rotor's hover speed from the static trim, as a command
    u = (ω - SIM_GZ_EC_MIN) / (SIM_GZ_EC_MAX - SIM_GZ_EC_MIN), through PX4's thrust model
    THR_MDL_FAC·u² + (1 - THR_MDL_FAC)·u, averaged over the rotors. Within 0.15 of each
    other this is information (C422 warns beyond).

    Severity (info, explains): it shows two numbers side by side.
    """
    for params in _px4(ctx):
        values = _hover_throttle(ctx, params)
        if values and abs(values[0] - values[1]) <= HOVER_THROTTLE_TOL:
            yield Issue(_hover_message(params, *values, _ranges(ctx, params)),
                        params.get("MPC_THR_HOVER").loc,
                        "MPC_THR_HOVER")


@rule("C422", "px4-hover-throttle-mismatch", "warning",
      "MPC_THR_HOVER is more than 0.15 from the throttle the model needs at hover.", clause="suspicious")
def px4_hover_throttle_mismatch(ctx: CheckContext) -> Iterator[Issue]:
    """As C421, with the two values more than 0.15 apart: PX4 takes off with the wrong
    feed-forward, sinks or balloons after take-off until the hover thrust estimator
    catches up, and a position controller without the estimator never does.

    Severity (warning, suspicious): the vehicle flies; take-off sinks or balloons until
    the hover estimator catches up.
    """
    for params in _px4(ctx):
        values = _hover_throttle(ctx, params)
        if values and abs(values[0] - values[1]) > HOVER_THROTTLE_TOL:
            yield Issue(_hover_message(params, *values, _ranges(ctx, params)),
                        params.get("MPC_THR_HOVER").loc,
                        "MPC_THR_HOVER",
                        hint=f"param set-default MPC_THR_HOVER {min(max(values[0], 0.1), 0.8):.2f}")


# --------------------------------------------------------------- PX4: which Gazebo

@rule("C435", "px4-simulator-mismatch", "error",
      "The PX4 airframe is for the other Gazebo than the model (Gazebo Sim vs Classic).",
      clause="flight-stack")
def px4_simulator_mismatch(ctx: CheckContext) -> Iterator[Issue]:
    """PX4 flies a Gazebo Sim model through its gz bridge (the airframe sets SIM_GZ_EN 1
    and SIM_GZ_EC_*; px4-rc.simulator starts gz_bridge) and a Gazebo Classic model
    through simulator_mavlink and the model's gazebo_mavlink_interface (PWM_MAIN outputs,
    the mavlink channels' input_scaling; SIM_GZ_EC_* is never read). An airframe for the
    one on a model for the other starts the wrong simulator interface: nothing commands the
    motors. One finding; the command-range rules of either side stay silent, since
    neither set of numbers is what will command this model.

    Severity (error, flight-stack): PX4 cannot command the model's motors at all.
    """
    for params in _px4(ctx):
        model = _model_simulator(ctx)
        airframe = params.simulator()
        if model is None or airframe is None or model[0] == airframe.simulator:
            continue
        names = {"gz": "Gazebo Sim (gz bridge)", "classic": "Gazebo Classic (simulator_mavlink)"}
        fix = ("use the model's Classic airframe (PX4's NNNN_gazebo-classic_*), or port the "
               "model with `reedtool migrate MODEL --to gz --autopilot px4`"
               if model[0] == "classic" else
               "use a gz airframe (SIM_GZ_EN 1, SIM_GZ_EC_*): `reedtool migrate` and "
               "`new-package --autopilot px4` write one")
        yield Issue(f"{params.label} is for {names[airframe.simulator]} ({airframe.what}), "
                    f"but the model is for {names[model[0]]}: {model[1]}",
                    airframe.loc, "simulator", hint=fix)


@rule("C439", "px4-gz-bridge-unreachable", "error",
      "PX4's gz bridge cannot reach the model: no link named base_link, or motors off "
      "command/motor_speed.", clause="flight-stack")
def px4_gz_bridge_unreachable(ctx: CheckContext) -> Iterator[Issue]:
    """With a Gazebo Sim airframe, PX4's gz bridge reads the IMU, barometer, magnetometer
    and GNSS of the link named base_link (/world/W/model/M/link/base_link/sensor/...,
    GZBridge.cpp) and publishes motor speeds on /M/command/motor_speed
    (GZMixingInterfaceESC.cpp), which a MulticopterMotorModel hears with commandSubTopic
    command/motor_speed under the model's name. A model without a base_link gives PX4
    no sensors; a motor on another topic is never commanded. `migrate --autopilot px4` and
    `new-package --sim gz --autopilot px4` write both as PX4's x500 has them.

    Severity (error, flight-stack): PX4 cannot fly the model.
    """
    for params in _px4(ctx):
        model = _model_simulator(ctx)
        airframe = params.simulator()
        if model is None or model[0] != "gz" or airframe is None or airframe.simulator != "gz":
            continue
        from reedtool.flightstack.px4 import PX4_BRIDGE_LINK, PX4_MOTOR_TOPIC   # a PX4 file

        if PX4_BRIDGE_LINK not in ctx.robot.link_map:
            yield Issue(f"{params.label} is for PX4's gz bridge ({airframe.what}), which reads "
                        f"its sensors from a link named '{PX4_BRIDGE_LINK}'; the model has none "
                        f"(its root is '{ctx.robot.base_link}')", ctx.robot.loc,
                        PX4_BRIDGE_LINK, hint="`reedtool migrate MODEL --to gz --autopilot px4` "
                                              "writes PX4's gz contract")
        off = [r for r in _all_rotors(ctx) if r.kind == "gz"
               and (r.plugin.param("commandSubTopic") or "").strip().strip("/") != PX4_MOTOR_TOPIC]
        if off:
            first = off[0]
            topic = first.plugin.param("commandSubTopic")
            yield Issue(f"{len(off)} motor(s) of the model do not listen where PX4's gz bridge "
                        f"publishes (/<model>/{PX4_MOTOR_TOPIC}): {_rotor_label(first)} has "
                        f"commandSubTopic '{topic or ''}'", first.loc, first.name,
                        hint=f"<commandSubTopic>{PX4_MOTOR_TOPIC}</commandSubTopic> and no "
                             "<robotNamespace>, as PX4's x500")


def _channel_of(ctx: CheckContext, rotor: "Rotor"):
    """The mavlink control channel the Classic motor reads (the channel at its motor
    number), when it is a velocity channel."""
    from reedtool.flightstack.px4 import mavlink_channels

    channels = mavlink_channels(ctx.robot)
    number = rotor.motor_number
    if number is None or not 0 <= number < len(channels) or not channels[number].velocity:
        return None
    return channels[number]


def _classic_pairs(ctx: CheckContext):
    """(params, rotor, channel) of every Classic-commanded motor, once per motor."""
    for params in _px4(ctx):
        if _simulator(ctx, params) != "classic":
            continue
        seen = set()
        for _ca, _k, rotor in _px4_pairs(ctx, params):
            channel = _channel_of(ctx, rotor)
            if channel is not None and id(rotor) not in seen:
                seen.add(id(rotor))
                yield params, rotor, channel


@rule("C436", "px4-classic-command-above-max", "warning",
      "The mavlink interface commands more than the Classic motor's maxRotVelocity.",
      clause="suspicious")
def px4_classic_command_above_max(ctx: CheckContext) -> Iterator[Issue]:
    """Gazebo Classic SITL: PX4's motor output u (0..1) becomes the speed (u +
    input_offset) * input_scaling + zero_position_armed of the motor's control channel
    (PX4-SITL_gazebo-classic gazebo_mavlink_interface.cpp), and the motor model clamps it
    at maxRotVelocity. A top command above the limit is a part of PX4's range that does
    nothing (typhoon_h480: 100 + 1500 against 1500, 6 %).

    Severity (warning, suspicious): the vehicle flies; PX4 believes in a reserve of
    thrust that does not exist.
    """
    for params, rotor, channel in _classic_pairs(ctx):
        low, high = channel.range_rad_s()
        limit = rotor.max_rot_velocity_rad_s
        if not math.isfinite(limit) or not high > limit * (1 + RANGE_REL_TOL):
            continue
        lost = (high - limit) / max(high - low, 1e-9)
        yield Issue(f"{channel.describe()} commands up to {high:g} rad/s, above "
                    f"maxRotVelocity {limit:g} of {_rotor_label(rotor)}: the top "
                    f"{100 * lost:.0f} % of PX4's output does nothing", channel.loc,
                    f"channel {channel.position}",
                    hint=_full_scale_hint(channel, limit))


def _full_scale_hint(channel, limit_rad_s: float) -> str:
    """The input_scaling at which PX4's full output (u = 1) commands maxRotVelocity."""
    scaling = (limit_rad_s - channel.zero_armed) / (1 + channel.offset)
    return f"input_scaling {scaling:g} makes u = 1 reach maxRotVelocity"


@rule("C437", "px4-classic-command-below-max", "warning",
      "The mavlink interface never commands the Classic motor's maxRotVelocity.",
      clause="suspicious")
def px4_classic_command_below_max(ctx: CheckContext) -> Iterator[Issue]:
    """As C436, with PX4's full output below maxRotVelocity: the vehicle has (top /
    maxRotVelocity)² of the thrust the model was built with. It may be a deliberate limit;
    the finding gives the fraction.

    Severity (warning, suspicious): the vehicle flies with less thrust than the model has.
    """
    for params, rotor, channel in _classic_pairs(ctx):
        _low, high = channel.range_rad_s()
        limit = rotor.max_rot_velocity_rad_s
        if not math.isfinite(limit) or not 0 < high < limit * (1 - RANGE_REL_TOL):
            continue
        yield Issue(f"{channel.describe()} commands at most {high:g} rad/s, below "
                    f"maxRotVelocity {limit:g} of {_rotor_label(rotor)}: PX4 reaches "
                    f"{100 * (high / limit) ** 2:.0f} % of the rotor's thrust", channel.loc,
                    f"channel {channel.position}",
                    hint=_full_scale_hint(channel, limit))


@rule("C438", "px4-classic-idle-command", "error",
      "The mavlink interface's armed idle is not below the Classic motor's hover speed.",
      clause="flight-stack")
def px4_classic_idle_command(ctx: CheckContext) -> Iterator[Issue]:
    """At zero output the armed Classic motor turns at input_offset * input_scaling +
    zero_position_armed. At or above the speed it needs to hover the vehicle climbs at
    zero throttle and cannot descend; a range that does not grow with u (input_scaling
    <= 0) cannot command it at all.

    Severity (error, flight-stack): PX4 cannot command the motor below what it needs.
    """
    hover = _hover_speeds(ctx)
    for params, rotor, channel in _classic_pairs(ctx):
        low, high = channel.range_rad_s()
        if not high > low:
            yield Issue(f"{channel.describe()}: the command does not grow with PX4's output "
                        f"({low:g} to {high:g} rad/s) for {_rotor_label(rotor)}", channel.loc,
                        f"channel {channel.position}", hint="input_scaling must be positive")
        elif hover and id(rotor) in hover and low >= hover[id(rotor)]:
            yield Issue(f"{channel.describe()} idles at {low:g} rad/s, at or above the "
                        f"{hover[id(rotor)]:.0f} rad/s {_rotor_label(rotor)} needs to hover: "
                        "at zero throttle the vehicle still climbs", channel.loc,
                        f"channel {channel.position}",
                        hint=f"zero_position_armed well below {hover[id(rotor)]:.0f} rad/s")


@rule("C425", "px4-param-out-of-range", "warning",
      "A PX4 parameter is outside the range PX4 documents for it.", clause="suspicious")
def px4_param_out_of_range(ctx: CheckContext) -> Iterator[Issue]:
    """reedtool knows the documented ranges of the parameters it reads (the PARAM_RANGES
    table in reedtool.flightstack.px4, with its sources): CA_ROTOR_COUNT 0..12,
    CA_ROTORi_KM -1..1, positions and axes -100..100, SIM_GZ_EC_MIN/MAX 0..1000 rad/s,
    MPC_THR_HOVER 0.1..0.8, THR_MDL_FAC 0..1. QGroundControl refuses such values, and
    PX4 may clamp them. SIM_GZ_EC_MIN/MAX are left to C419/C420/C424, which compare them
    with the model's motors (PX4's own px4vision airframe commands up to 1100 rad/s).

    Severity (warning, suspicious): QGroundControl refuses the value and PX4 may clamp
    it, but the vehicle loads.
    """
    for params in ctx.flight_params:
        if params.kind != "px4":
            continue
        from reedtool.flightstack.px4 import out_of_range   # only with a PX4 parameter file

        for value, (low, high, _default, source) in out_of_range(params):
            if value.name.startswith("SIM_GZ_EC_"):
                continue
            yield Issue(f"{value.name} {value.value:g} is outside {low:g}..{high:g} ({source})",
                        value.loc, value.name)


# --------------------------------------------------------------- ArduPilot

def _ap_frame(params: "ArduPilotParams"):
    from reedtool.flightstack.ardupilot import motor_table

    frame_class, frame_type = params.frame()
    if frame_class is None:
        return None
    return motor_table(int(frame_class.value), int(frame_type.value))


def _channel(rotor: "Rotor") -> int | None:
    return getattr(rotor, "channel", None)


def _ap_pairs(ctx: CheckContext, params: "ArduPilotParams"):
    """(AP motor, servo output, the SERVOn_FUNCTION line or None, model rotor)."""
    motors = _ap_frame(params) or ()
    rotors = _lift_rotors(ctx)
    if len(motors) != len(rotors):
        return []                                  # C431 says so; nothing pairs up
    with_channels = [r for r in rotors if _channel(r) is not None]
    if with_channels:
        by_output = {_channel(r) + 1: r for r in with_channels}
    else:
        by_output = {_actuator(r) + 1: r for r in rotors if _actuator(r) is not None}
    pairs = []
    for motor in motors:
        output, line = params.output_of_motor(motor.number)
        if output in by_output:
            pairs.append((motor, output, line, by_output[output]))
    return pairs


def _ap_where(params: "ArduPilotParams") -> str:
    from reedtool.flightstack.ardupilot import frame_name

    frame_class, frame_type = params.frame()
    type_loc = str(frame_type.loc) if frame_type.explicit else \
        f"not set: ArduCopter's default 1, {frame_type.loc}"
    return (f"FRAME_CLASS {frame_class.value:g} ({frame_class.loc}), FRAME_TYPE "
            f"{frame_type.value:g} ({type_loc}): "
            f"{frame_name(int(frame_class.value), int(frame_type.value))}")


def _output_text(output: int, line) -> str:
    return f"SERVO{output}" + (f" ({line.loc})" if line is not None else " (default)")


@rule("C430", "ardupilot-frame-unknown", "info",
      "FRAME_CLASS/FRAME_TYPE is not set or names a frame reedtool has no motor table for.",
      clause="ambiguous")
def ardupilot_frame_unknown(ctx: CheckContext) -> Iterator[Issue]:
    """ArduCopter's FRAME_CLASS defaults to 0 (undefined: the motors do not start), but a
    parameter file is often one of several (SITL loads its frame's defaults first, then
    the user's file), so a file without it cannot be judged alone. reedtool knows the
    motor tables of quad (plus, X, V, H, V-tail, A-tail, plus-rev, BetaFlight X and
    reversed, DJI X, clockwise X, no-yaw plus and X), hexa (plus, X), octa (plus, X),
    octaquad (plus, X, H) and Y6 (default, Y6B, Y6F); for other frames nothing is compared.

    Severity (information): it says what reedtool could not compare.
    """
    for params in _ardupilot(ctx):
        frame_class, frame_type = params.frame()
        if frame_class is None:
            yield Issue(f"{params.label} does not set FRAME_CLASS (ArduCopter's default 0 "
                        "is undefined: the motors do not start)", params.loc, "FRAME_CLASS",
                        hint="FRAME_CLASS 1 (quad), 2 (hexa), 3 (octa), 4 (octaquad), 5 (Y6)")
        elif _ap_frame(params) is None:
            yield Issue(f"{_ap_where(params)}: reedtool has no motor table for this frame; "
                        "motor order and spin are not checked", frame_class.loc, "FRAME_CLASS")


@rule("C431", "ardupilot-motor-count", "error",
      "The ArduPilot frame has a different number of motors than the model has lift rotors.", clause="flight-stack")
def ardupilot_motor_count(ctx: CheckContext) -> Iterator[Issue]:
    """FRAME_CLASS fixes the number of motors ArduCopter mixes for (quad 4, hexa 6, octa
    and octaquad 8, Y6 6). A model with a different number of lift rotors cannot be flown
    by that mixer.

    Severity (error, flight-stack): ArduPilot's mixer mixes for another number of motors
    than the model has.
    """
    rotors = _lift_rotors(ctx)
    for params in _ardupilot(ctx):
        motors = _ap_frame(params)
        if motors is None or not rotors or len(motors) == len(rotors):
            continue
        yield Issue(f"{_ap_where(params)} has {len(motors)} motors, the model has "
                    f"{len(rotors)} lift rotor(s) ({rotors[0].loc}, ...)",
                    params.frame()[0].loc, "FRAME_CLASS",
                    hint="choose the FRAME_CLASS/FRAME_TYPE of the model's layout")


@rule("C432", "ardupilot-motor-position", "error",
      "An ArduPilot motor is driven on a rotor in another place than its frame puts it.", clause="flight-stack")
def ardupilot_motor_position(ctx: CheckContext) -> Iterator[Issue]:
    """Each ArduPilot frame puts motor m at a bearing from the nose (AP_MotorsMatrix); the
    mixer gives it roll and pitch factors from that bearing. The model rotor that output
    receives (ArduPilotPlugin channel = output - 1, or actuator number = output - 1 without
    the plugin) must sit there, within 20° of bearing and in the same quadrant: a plus
    frame type on an X model, or two swapped channels, flip the vehicle on take-off.

    Severity (error, flight-stack): ArduPilot commands the wrong motor for a roll or
    pitch.
    """
    for params in _ardupilot(ctx):
        for motor, output, line, rotor in _ap_pairs(ctx, params):
            model = _frd_about_com(ctx, rotor)
            table = np.array([math.cos(math.radians(motor.bearing_deg)),
                              math.sin(math.radians(motor.bearing_deg))])
            gap = _gap(motor.bearing_deg, _bearing(model))
            if gap <= BEARING_TOL_DEG and _same_quadrant(table * np.hypot(*model[:2]), model):
                continue
            # A motor whose bearing some model rotor has is misrouted (the SERVO line is
            # to edit); one no rotor has means the frame type is not the model's.
            routed = line is not None and any(
                _gap(motor.bearing_deg, _bearing(_frd_about_com(ctx, r))) <= BEARING_TOL_DEG
                for r in _lift_rotors(ctx))
            yield Issue(f"{_ap_where(params)} puts motor {motor.number} at bearing "
                        f"{motor.bearing_deg:g}°; it is sent on {_output_text(output, line)} "
                        f"to {_rotor_label(rotor)}, which sits at bearing "
                        f"{_bearing(model):.1f}° ({gap:.1f}° apart)",
                        line.loc if routed else params.frame()[1].loc,
                        rotor.joint or rotor.name,
                        hint="set FRAME_TYPE to the model's layout, or SERVOn_FUNCTION so "
                             f"motor {motor.number} reaches the rotor at {motor.bearing_deg:g}°")


@rule("C433", "ardupilot-motor-spin", "error",
      "An ArduPilot motor's spin disagrees with the turning direction of the rotor it drives.", clause="flight-stack")
def ardupilot_motor_spin(ctx: CheckContext) -> Iterator[Issue]:
    """AP_MotorsMatrix gives every motor a yaw factor: +1 counter-clockwise, -1 clockwise
    seen from above. The rotor the motor's output drives must turn that way (the model's
    turningDirection, or the sign of the ArduPilotPlugin multiplier), or yaw control has
    the wrong sign for it.

    Severity (error, flight-stack): ArduPilot yaws with the motor the other way.
    """
    for params in _ardupilot(ctx):
        for motor, output, line, rotor in _ap_pairs(ctx, params):
            if motor.spin == 0 or rotor.turning_sign == 0 or motor.spin == rotor.turning_sign:
                continue
            model = _frd_about_com(ctx, rotor)
            if _gap(motor.bearing_deg, _bearing(model)) > BEARING_TOL_DEG:
                continue   # wrong place: C432 reports it, the spin follows from it
            yield Issue(f"{_ap_where(params)}: motor {motor.number} spins "
                        f"{SPIN_NAME[motor.spin]}, but {_rotor_label(rotor)} on "
                        f"{_output_text(output, line)} turns {SPIN_NAME[rotor.turning_sign]}",
                        line.loc if line is not None else params.frame()[1].loc,
                        rotor.joint or rotor.name,
                        hint="choose the frame type with this spin pattern (e.g. H for a "
                             "reversed X), or reverse the rotor in the model")


@rule("C434", "ardupilot-motor-unassigned", "error",
      "An ArduPilot motor reaches no rotor of the model, or a rotor gets no motor.", clause="flight-stack")
def ardupilot_motor_unassigned(ctx: CheckContext) -> Iterator[Issue]:
    """Motor m goes out on the servo output whose SERVOn_FUNCTION is 32 + m (default:
    output m). When that output drives no rotor of the model, or a model rotor's output
    carries no motor, the mixer and the model disagree about which rotors exist.

    Severity (error, flight-stack): ArduPilot commands a motor the model does not have,
    or never one it has.
    """
    for params in _ardupilot(ctx):
        motors = _ap_frame(params)
        rotors = _lift_rotors(ctx)
        if not motors or not rotors or len(motors) != len(rotors):
            continue
        paired = _ap_pairs(ctx, params)
        reached = {id(rotor) for *_, rotor in paired}
        for motor in motors:
            if not any(m is motor for m, *_ in paired):
                output, line = params.output_of_motor(motor.number)
                where = _output_text(output, line) if output else "no output"
                yield Issue(f"{_ap_where(params)}: motor {motor.number} is sent on {where}, "
                            "which drives no rotor of the model",
                            line.loc if line is not None else params.frame()[0].loc,
                            f"motor {motor.number}",
                            hint="ArduPilotPlugin channel c is servo output c+1")
        for rotor in rotors:
            if id(rotor) not in reached:
                yield Issue(f"{_rotor_label(rotor)} receives no ArduPilot motor from "
                            f"{params.label}", params.frame()[0].loc, rotor.joint or rotor.name)

