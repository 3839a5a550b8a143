"""Plausibility rules (R340-R349, I220-I229): numbers a model copied from another vehicle gets wrong.

Each of these models flies in Gazebo, but not like the vehicle it claims to be: a
thrust-to-weight ratio no real multirotor has, a mass and inertia that belong to a
frame ten times larger, a rotor joint spinning about another axis than the rotor
pushes, or one arm longer than the others so that the rotors share the hover load
unevenly. They are warnings with the numbers: each may be intended.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Iterator

import numpy as np

from reedtool.checks.context import CheckContext
from reedtool.checks.finding import Issue
from reedtool.checks.registry import rule
from reedtool.checks.rotor_rules import MAX_CONDITION_NUMBER, _normalised_allocation, _physics_ready

if TYPE_CHECKING:
    from reedtool.physics.rotors import Rotor

# Above this no multirotor flies: camera and transport frames are built for 2-3, 5-inch
# racing quads for 8-15, the lightest freestyle builds approach 20, and omnidirectional
# frames carry margin because half their rotors push against the other half (PX4's
# omnicopter 9.1, RotorS omav 6.3). 25 leaves room above the lightest real builds; a
# copied speed or a unit mistake lands far beyond (gz-sim's test quadrotor: 147).
THRUST_TO_WEIGHT_HIGH = 25.0
# Whole-robot mass over the cube of the rotor span (2 x the farthest rotor from the COM):
# real multirotors sit at 10-150 kg/m³ (x500 ~17, a 65 mm whoop ~90); above this the mass
# belongs to a larger vehicle.
SPAN_DENSITY_MAX_KG_M3 = 1000.0
# Yaw radius of gyration sqrt(Izz/m) over the farthest rotor's distance from the COM: the
# mass of a multirotor lies inside its rotor circle, so above this the inertia does not fit.
GYRATION_RATIO_MAX = 1.5
# Lift rotors all within this horizontal distance of the COM: a coaxial or single-rotor
# helicopter (the Sikorsky X2 shape), whose size the rotor positions do not tell.
SINGLE_AXIS_SPAN_M = 0.01
JOINT_AXIS_TOL_DEG = 5.0
TRIM_SPREAD_MAX = 0.15
PARALLEL_TOL_DEG = 1.0


def _lift(ctx: CheckContext) -> list["Rotor"]:
    return [r for r in ctx.rotors if getattr(r, "role", "lift") == "lift"] if ctx.tree_ok else []


def _span_m(ctx: CheckContext) -> float:
    com = np.asarray(ctx.whole_robot.com_m, dtype=float)
    return max(float(np.hypot(*(r.position_m - com)[:2])) for r in _lift(ctx))


@rule("R340", "thrust-to-weight-high", "warning",
      "Thrust-to-weight is above 25: the motor constants or speeds belong to another vehicle.", clause="suspicious")
def thrust_to_weight_high(ctx: CheckContext) -> Iterator[Issue]:
    """Camera and transport multirotors fly with a thrust-to-weight ratio of 2-3, 5-inch
    racing quads with 8-15, the lightest freestyle builds approach 20, and omnidirectional
    frames need margin (PX4's omnicopter 9.1, RotorS omav 6.3): none of those is
    suspicious. Above 25 no multirotor flies; the motor constant or maxRotVelocity was
    copied from a larger vehicle or written in other units (gz-sim's test-world quadrotor
    with maxRotVelocity 8000 reaches 147): the controller's output range then spans far
    more thrust than the vehicle could have, and every gain tuned on it is wrong.

    Severity (warning): the model loads and flies; only its numbers are implausible.
    """
    if not _physics_ready(ctx):
        return
    trim = ctx.trim
    if not math.isfinite(trim.thrust_to_weight) or trim.thrust_to_weight <= THRUST_TO_WEIGHT_HIGH:
        return
    rotor = _lift(ctx)[0] if _lift(ctx) else ctx.rotors[0]
    needed = rotor.max_rot_velocity_rad_s * math.sqrt(3.0 / trim.thrust_to_weight)
    yield Issue(f"thrust-to-weight {trim.thrust_to_weight:.3g}: the rotors give "
                f"{trim.thrust_to_weight * trim.weight_N:.4g} N at maxRotVelocity "
                f"{rotor.max_rot_velocity_rad_s:g} rad/s for {trim.weight_N:.4g} N of weight "
                f"({ctx.whole_robot.mass_kg:.4g} kg)",
                rotor.param_loc("maxRotVelocity"), "rotors",
                hint=f"check motorConstant and maxRotVelocity; maxRotVelocity {needed:.0f} rad/s "
                     "gives thrust-to-weight 3")


@rule("I220", "mass-implausible-for-size", "warning",
      "The whole-robot mass or inertia does not fit the rotor span.", clause="suspicious")
def mass_implausible_for_size(ctx: CheckContext) -> Iterator[Issue]:
    """Two ratios that real multirotors keep whatever their size. Mass over the cube of
    the rotor span (twice the farthest rotor's distance from the COM) stays within about
    10-150 kg/m³: above 1000 the frame would be denser than water filling its own
    bounding cube. The yaw radius of gyration sqrt(Izz/m) stays inside the rotor circle:
    above 1.5 times the rotor distance the inertia puts the mass outside the rotors. Both
    catch a mass and inertia copied from a larger vehicle (1.5 kg on a 65 mm frame).
    A coaxial or single-rotor helicopter (every lift rotor within 1 cm of the COM's
    vertical) has no rotor span to compare with and is not judged.

    Severity (warning): the model flies, like a vehicle of another size.
    """
    if not _physics_ready(ctx) or not _lift(ctx):
        return
    whole = ctx.whole_robot
    span = _span_m(ctx)
    if span < SINGLE_AXIS_SPAN_M:
        return      # coaxial or single-rotor: no rotor span to size the vehicle by
    rotor = _lift(ctx)[0]
    density = whole.mass_kg / (2.0 * span) ** 3
    if density > SPAN_DENSITY_MAX_KG_M3:
        yield Issue(f"{whole.mass_kg:.4g} kg on a rotor span of {2000 * span:.0f} mm: "
                    f"{density:.0f} kg/m³ of span cube (real multirotors: 10-150)",
                    ctx.robot.loc, ctx.robot.name,
                    hint=f"a frame of this size weighs about "
                         f"{100.0 * (2.0 * span) ** 3:.3g} kg; check the masses (grams as kg?) "
                         "or the rotor positions")
    izz = float(whole.inertia_kg_m2[2, 2])
    if whole.mass_kg > 0 and izz > 0:
        gyration = math.sqrt(izz / whole.mass_kg)
        if gyration > GYRATION_RATIO_MAX * span:
            yield Issue(f"yaw radius of gyration sqrt(Izz/m) = {1000 * gyration:.0f} mm "
                        f"(Izz {izz:.4g} kg·m², {whole.mass_kg:.4g} kg) is "
                        f"{gyration / span:.2g}x the rotor distance {1000 * span:.0f} mm "
                        f"({rotor.loc}): the inertia puts the mass outside the rotors",
                        ctx.robot.loc, ctx.robot.name,
                        hint="recompute the inertias from the links' real geometry "
                             "(reedtool inertia)")


@rule("R341", "rotor-joint-axis-not-thrust-axis", "warning",
      "A rotor's joint turns about another axis than the rotor's thrust axis.", clause="suspicious")
def rotor_joint_axis(ctx: CheckContext) -> Iterator[Issue]:
    """The motor plugin pushes along the rotor link's z axis and spins the rotor about
    its joint axis. When the two differ by more than 5°, the propeller visibly wobbles,
    its gyroscopic torque acts about the wrong axis, and usually one of the two poses
    is wrong (a rotor link rotated by a mesh correction, an axis given in the parent's
    frame).

    Severity (warning, suspicious): the motor plugin pushes along the link's z axis, so
    the vehicle flies; the prop spins and precesses about the wrong axis.
    """
    if not ctx.tree_ok:
        return
    poses = ctx.link_poses
    for rotor in ctx.rotors:
        joint = ctx.robot.joint_map.get(rotor.joint or "")
        if joint is None or joint.child not in poses or not np.all(np.isfinite(rotor.axis)):
            continue
        axis = np.asarray(joint.axis, dtype=float)
        if not np.all(np.isfinite(axis)) or np.linalg.norm(axis) == 0:
            continue
        axis_base = poses[joint.child][:3, :3] @ (axis / np.linalg.norm(axis))
        cos = abs(float(np.dot(axis_base, rotor.axis / np.linalg.norm(rotor.axis))))
        angle = math.degrees(math.acos(min(1.0, cos)))
        if angle > JOINT_AXIS_TOL_DEG:
            yield Issue(f"joint '{joint.name}' turns about ({axis_base[0]:.3g}, "
                        f"{axis_base[1]:.3g}, {axis_base[2]:.3g}) in the base frame, "
                        f"{angle:.1f}° from the thrust axis ({rotor.axis[0]:.3g}, "
                        f"{rotor.axis[1]:.3g}, {rotor.axis[2]:.3g}) of its rotor "
                        f"({rotor.loc})", joint.axis_loc or joint.loc, joint.name,
                        hint="make the joint axis the rotor link's z axis: <axis xyz=\"0 0 1\"/>")


@rule("R342", "uneven-hover-trim", "warning",
      "At hover the rotor thrusts differ by more than 15 %: the COM is off the rotor centroid.", clause="suspicious")
def uneven_hover_trim(ctx: CheckContext) -> Iterator[Issue]:
    """With every lift rotor parallel, equal thrusts hold the vehicle level only when the
    centre of mass sits over the rotors' centroid. Otherwise some rotors hover harder than
    others (one arm 0.15 m longer: one pair at 65 %, the other at 77 % of full speed),
    losing control margin on one side. Reported when the largest hover thrust is more
    than 15 % above the smallest, with the COM shift that would even them out. A nearly
    singular allocation (R306) spreads the thrusts by its geometry alone; that is R306's
    finding, not this one.

    Severity (warning, suspicious): it hovers, with less margin on one side.
    """
    if not _physics_ready(ctx):
        return
    if float(np.linalg.cond(_normalised_allocation(ctx))) > MAX_CONDITION_NUMBER:
        return
    rotors, trim = ctx.rotors, ctx.trim
    lift = _lift(ctx)
    if len(lift) != len(rotors) or len(rotors) < 3 or not trim.feasible:
        return
    axes = np.array([r.axis / np.linalg.norm(r.axis) for r in rotors])
    if np.degrees(np.arccos(np.clip(axes @ axes[0], -1, 1))).max() > PARALLEL_TOL_DEG:
        return
    thrust = np.asarray(trim.thrust_N, dtype=float)
    low, high = int(np.argmin(thrust)), int(np.argmax(thrust))
    if thrust[low] <= 0 or thrust[high] / thrust[low] - 1.0 <= TRIM_SPREAD_MAX:
        return
    com = np.asarray(ctx.whole_robot.com_m, dtype=float)
    centroid = np.mean([r.position_m for r in rotors], axis=0)
    shift = (centroid - com)[:2]
    yield Issue(f"hover thrusts from {thrust[low]:.3g} N ('{rotors[low].name}', "
                f"{100 * trim.throttle[low]:.0f} % speed) to {thrust[high]:.3g} N "
                f"('{rotors[high].name}', {100 * trim.throttle[high]:.0f} % speed), "
                f"{100 * (thrust[high] / thrust[low] - 1):.0f} % apart; the COM "
                f"({com[0]:.4g}, {com[1]:.4g}) m is off the rotor centroid "
                f"({centroid[0]:.4g}, {centroid[1]:.4g}) m", rotors[high].loc, rotors[high].name,
                hint=f"move the COM by ({shift[0]:+.4g}, {shift[1]:+.4g}) m in x, y, or the "
                     "rotors so their centroid is over it (an arm longer than the others?)")
