"""Plausibility rules (R340-R349, I220-I229): numbers a model copied from another vehicle gets wrong.

Each of these models flies in Gazebo, but not like the vehicle it claims to be: a
thrust-to-weight ratio no real multirotor has, a mass and inertia that belong to a
frame ten times larger, a rotor joint spinning about another axis than the rotor
pushes, or one arm longer than the others so that the rotors share the hover load
unevenly. They are warnings with the numbers: each may be intended. One is not: a link
denser than any matter (I221) has a mass in other units than its geometry, an error.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Iterator

import numpy as np

from reedtool.checks.context import CheckContext
from reedtool.checks.finding import Issue
from reedtool.checks.registry import rule
from reedtool.checks.rotor_rules import MAX_CONDITION_NUMBER, normalised_allocation, physics_ready

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

# ---- I221: no link is denser than matter.
# The densest solid at room conditions is osmium, 22.59 g/cm³ (CRC Handbook of Chemistry
# and Physics, 97th ed., "Density of the elements"; iridium 22.56). No workflows of real
# material averages more than its densest part, so mass / volume above this is not a
# part of any material. The bound needs a volume that does not under-state the part:
#  - a closed mesh encloses the solid it bounds; when the part is a hollow shell drawn
#    by its outer skin only, the enclosed volume exceeds the material's, so mass over it
#    UNDER-states the material density: the bound still holds (it can only miss, never
#    accuse wrongly);
#  - an open mesh encloses nothing, so its convex hull is measured: any solid the open
#    surface stands for lies inside its hull, again an over-statement of the volume;
#  - several geometries are summed (overlaps count twice: more volume), and the larger
#    of the collision and visual groups is used;
#  - a stand-in geometry smaller than the part (a 5 mm box for a 0.3 kg servo) under-
#    states it. When the declared inertia gives that away (more than 10x the geometry's
#    at the same mass, I204's bound: no mass inside a shape turns it harder than that)
#    the link is not judged. When the inertia was computed from the stand-in too, only a
#    margin helps: PX4's sensors are drawn up to 1.5x too small (the 50 g aruco camera as
#    a 5 x 30 x 10 mm box: 33,300 kg/m³; the 15 g GPS as a 0.63 cm³ puck: 23,900), so the
#    error is at twice osmium. Grams written as kg multiply the density by 1000, so every
#    part built denser than 45 kg/m³ (all but foam) is still caught;
#  - a placeholder link (under 0.1 % of the robot's mass and inertia,
#    physics.inertia.PLACEHOLDER_FRACTION) cannot change a flight and is not judged.
OSMIUM_KG_M3 = 22_590.0
STAND_IN_MARGIN = 2.0
MAX_DENSITY_KG_M3 = STAND_IN_MARGIN * OSMIUM_KG_M3
# Grams written as kg: the mass a thousand times too large. Named as the cause when a
# thousandth of the mass gives the density of something drones are built of: 20 kg/m³
# (expanded foam) to 8,960 kg/m³ (copper windings; steel 7,850).
GRAMS_PER_KG = 1000.0
BUILD_DENSITY_KG_M3 = (20.0, 8960.0)

# ---- R343: mass against the rotor footprint, outside every real multirotor.
# Footprint loading w = m g / (pi L²), L the farthest lift rotor's distance from the COM.
# Published airframes (all-up or max take-off mass; L = half the motor-to-motor diagonal):
#   Bitcraze Crazyflie 2.1   0.027 kg, 92 mm diagonal        ->   40 N/m²
#   DJI F450                 1.2-1.6 kg, 450 mm             ->   74-99 N/m²
#   Holybro X500 (PX4 x500)  2.0 kg, 500 mm                 ->  100 N/m²
#   Tarot 680 Pro hexa       3-5 kg, 680 mm                 ->   81-135 N/m²
#   5-inch racing quad       0.6-0.8 kg, 220 mm             ->  155-206 N/m²
#   DJI Matrice 600          15.5 kg MTOW, 1133 mm          ->  151 N/m²
#   EHang 216 (cargo/people) 600 kg MTOW, ~5.6 m diagonal   ~  240 N/m²
#   AeroVelo Atlas (human-powered quad, Sikorsky prize 2013) ~128 kg with pilot, rotors of
#                            20.2 m on a 47 m square, L ~ 19 m -> ~1.1 N/m² (the lightest)
# Physics, heavy side: n coplanar rotors that do not overlap on a circle of radius L
# have radius at most L sin(pi/n), so a total disc area at most 2.25 pi L² (n = 3; a
# quad 2 pi L²): disc loading >= w / 2.25. The highest disc loading any rotorcraft
# hovers with is ~1,300 N/m² (V-22 Osprey: 27.4 t on two 11.6 m rotors; CH-53E 860);
# above it induced velocity sqrt(DL / 2 rho) passes 23 m/s and hover is a jet's. So
# w > 2.25 x 1,500 = 3,400 N/m² is a footprint no rotor set fits, 17x the heaviest
# multirotor above. Light side: below 0.3 N/m², a quarter of Atlas's (whose 47 m frame
# of carbon spars is the lightest structure for its size ever flown), the vehicle is
# lighter than any frame that spans its rotors.
FOOTPRINT_LOADING_MAX_N_M2 = 3400.0
FOOTPRINT_LOADING_MIN_N_M2 = 0.3
G_M_S2 = 9.80665
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
    if not physics_ready(ctx):
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
    if not physics_ready(ctx) or not _lift(ctx):
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
    if not physics_ready(ctx):
        return
    if float(np.linalg.cond(normalised_allocation(ctx))) > MAX_CONDITION_NUMBER:
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


def _placeholder_geometry(ctx: CheckContext, link_name: str) -> bool:
    """The declared inertia is more than PLAUSIBLE_TRACE_RATIO times the geometry's at the
    same mass: the geometry stands for a larger part, so it does not bound its volume."""
    from reedtool.physics.inertia import PLAUSIBLE_TRACE_RATIO

    for comparison in ctx.link_comparisons:
        if comparison.link == link_name:
            ratio = comparison.trace_ratio
            return ratio is not None and math.isfinite(ratio) and ratio > PLAUSIBLE_TRACE_RATIO
    return False


@rule("I221", "link-denser-than-matter", "error",
      "A link's mass over its geometry's volume is over twice osmium's density (45 g/cm³).",
      clause="cannot-fly")
def link_denser_than_matter(ctx: CheckContext) -> Iterator[Issue]:
    """No material is denser than osmium, 22.59 g/cm³ (CRC Handbook), so no part is: a
    link whose declared mass over the volume of its collision (or visual) geometry
    exceeds twice that (the factor allows a sensor drawn smaller than it is: PX4's 50 g
    aruco camera in 1.5 cm³ is 33 g/cm³) has a mass in other units than its geometry. The usual cause is grams
    written as kilograms (a CAD exporter set to mm-g-s: a 1.2 kg body declared 1200), and
    the message says whether a thousandth of the mass gives the density of something
    drones are built of (foam to copper, 20-8,960 kg/m³).

    Volume: the sum over the link's collision geometries or its visual ones, whichever is
    larger, with `<mesh scale>` applied. A closed mesh counts what it encloses (for a
    hollow part drawn by its outer skin that is more than its material, which only lowers
    the density computed: the bound still holds); an open mesh counts its convex hull.
    Not judged: placeholder links (under 0.1 % of the robot's mass and inertia) and a
    geometry that stands for a larger part (the declared inertia more than 10x the
    geometry's: I204 speaks about that).

    Severity (error): the mass is certainly not the part's; a vehicle a thousand times
    heavier than built does not hover on its rotors, and every inertia derived from the
    mass is as wrong.
    """
    from reedtool.physics.inertia import link_volumes

    placeholders = ctx.placeholder_links
    for link in ctx.robot.links:
        inertial = link.inertial
        if inertial is None or link.name in placeholders:
            continue
        mass = inertial.mass_kg
        if not (math.isfinite(mass) and mass > 0):
            continue
        volume = None              # the largest group, each too dense for its mass
        for group in link_volumes(link):
            if mass / group.volume_m3 <= MAX_DENSITY_KG_M3:
                volume = None      # one group gives the part room enough: plausible
                break
            if volume is None or group.volume_m3 > volume.volume_m3:
                volume = group
        if volume is None or _placeholder_geometry(ctx, link.name):
            continue
        density = mass / volume.volume_m3
        shapes = (f"{volume.count} {volume.source} geometries" if volume.count > 1
                  else f"its {volume.source} geometry")
        hull = " (convex hull: the mesh is open)" if volume.from_hull else ""
        grams = density / GRAMS_PER_KG
        low, high = BUILD_DENSITY_KG_M3
        if low <= grams <= high:
            hint = (f"grams written as kg? {mass / GRAMS_PER_KG:.4g} kg gives "
                    f"{grams:,.0f} kg/m³, a solid drones are built of; declare the mass in kg "
                    "(and the inertia in kg·m²)")
        else:
            hint = (f"the mass is {density / OSMIUM_KG_M3:,.3g}x too large for the "
                    "volume: check its unit, and the geometry's (a mesh in mm needs "
                    "scale=\"0.001 0.001 0.001\", once)")
        yield Issue(f"link '{link.name}': {mass:.4g} kg in {1e6 * volume.volume_m3:.4g} cm³ of "
                    f"{shapes}{hull} is {density:,.0f} kg/m³, {density / OSMIUM_KG_M3:,.3g}x "
                    f"the densest solid (osmium, {OSMIUM_KG_M3:,.0f} kg/m³)",
                    inertial.mass_loc or inertial.loc, link.name, hint=hint)


@rule("R343", "size-implausible-for-mass", "warning",
      "The mass on the rotors' footprint is outside every real multirotor.", clause="suspicious")
def size_implausible_for_mass(ctx: CheckContext) -> Iterator[Issue]:
    """Footprint loading m g / (pi L²), with L the farthest lift rotor from the COM, is
    40-240 N/m² across real multirotors from a 27 g Crazyflie to a 600 kg EHang 216;
    the lightest ever flown, the 47 m human-powered AeroVelo Atlas, carries ~1.1 N/m².
    Above 3,400 N/m² no set of rotors fits the footprint: n non-overlapping rotors on a
    circle of radius L have at most 2.25 pi L² of disc, and no rotorcraft hovers above
    ~1,500 N/m² of disc (the V-22 Osprey's 1,300). Below 0.3 N/m² the vehicle is lighter
    than any frame that spans its rotors. Either is a mass or a length in other units:
    1200 kg (grams) on a 0.38 m frame, a 36 m quad from an arm length of 18 meant as cm.
    The derivation and the airframe table sit next to the rule's bounds in
    reedtool/checks/plausibility_rules.py. A coaxial or single-rotor vehicle (every lift
    rotor within 1 cm of the COM's vertical) has no footprint and is not judged; the
    heavy side stays quiet when I220 reports the same mass on the same span.

    Severity (warning, suspicious): the model loads and may hover in simulation; no real
    vehicle has these proportions.
    """
    if not physics_ready(ctx) or not _lift(ctx):
        return
    whole = ctx.whole_robot
    arm_m = _span_m(ctx)
    if arm_m < SINGLE_AXIS_SPAN_M:
        return
    loading = whole.mass_kg * G_M_S2 / (math.pi * arm_m ** 2)
    farthest = max(_lift(ctx), key=lambda r: float(np.hypot(
        *(r.position_m - np.asarray(whole.com_m, dtype=float))[:2])))
    where = (f"{whole.mass_kg:.4g} kg with its farthest rotor {arm_m:.4g} m from the COM "
             f"(a {2 * arm_m:.3g} m frame): {loading:.3g} N/m² of footprint")
    typical_kg = 100.0 * math.pi * arm_m ** 2 / G_M_S2      # 100 N/m²: an F450, an x500
    if loading > FOOTPRINT_LOADING_MAX_N_M2:
        if whole.mass_kg / (2.0 * arm_m) ** 3 > SPAN_DENSITY_MAX_KG_M3:
            return                                           # I220 says it
        yield Issue(f"{where}, above the {FOOTPRINT_LOADING_MAX_N_M2:,.0f} N/m² no rotors on "
                    "that frame can lift (real multirotors: 40-240)", ctx.robot.loc,
                    ctx.robot.name,
                    hint=f"a multirotor this size weighs about {typical_kg:.3g} kg; check the "
                         "masses (grams written as kg?) or the arm length's unit")
    elif loading < FOOTPRINT_LOADING_MIN_N_M2:
        yield Issue(f"{where}, below the {FOOTPRINT_LOADING_MIN_N_M2:g} N/m² of any frame "
                    "that spans its rotors (real multirotors: 40-240; a 47 m human-powered "
                    "quad ~1)", farthest.loc, farthest.name,
                    hint=f"a multirotor of {whole.mass_kg:.3g} kg has its rotors about "
                         f"{math.sqrt(whole.mass_kg * G_M_S2 / (100.0 * math.pi)):.3g} m from "
                         "its centre; check the arm length's unit (cm or mm read as m?)")
