"""Inertia rules (I2xx): each link's mass and inertia are physically possible and plausible.

Physics comes from reedtool.physics.inertia (geometry mass properties, principal moments); this
module only compares declared values against it and words the findings.
"""

from __future__ import annotations

import math
from typing import Iterator

import numpy as np

from reedtool.checks.context import CheckContext
from reedtool.checks.finding import Issue
from reedtool.checks.registry import rule
from reedtool.model import Box, Cylinder, Link, Mesh, Sphere
from reedtool.physics.inertia import (
    TRIANGLE_REL_TOL,  # noqa: F401 - re-exported: the I203 tolerance
    robot_mass_problem,
    tensor_problem,
)

# How far outside its geometry's bounding box a COM may lie, as a fraction of the box size.
COM_MARGIN_FRACTION = 0.1
COM_MARGIN_MIN_M = 0.002
# Mesh extents (after unit and scale) outside this range are almost always a unit mistake.
MESH_EXTENT_RANGE_M = (0.001, 20.0)
# ... and certainly one (I210, error) this many times outside the range, or this many times
# the robot's own size (its link spread and primitive shapes), or, when the robot gives no
# size, when exactly one unit (mm, or m read as mm) turns it into a plausible part.
MESH_UNIT_CERTAIN_FACTOR = 50.0
PLAUSIBLE_PART_M = (0.01, 5.0)


def _fmt(value: float) -> str:
    return f"{value:.6g}"


def _inertia_xml(I: np.ndarray) -> str:
    I = np.asarray(I, dtype=float)
    # Products below 1e-4 of the largest entry come from rounded angles (1.57075 for pi/2).
    tiny = 1e-4 * max(float(np.max(np.abs(I))), 1e-300)
    v = lambda x: "0" if abs(x) < tiny else _fmt(x)  # noqa: E731
    return (f'<inertia ixx="{v(I[0, 0])}" ixy="{v(I[0, 1])}" ixz="{v(I[0, 2])}" '
            f'iyy="{v(I[1, 1])}" iyz="{v(I[1, 2])}" izz="{v(I[2, 2])}"/>')


def describe_geometry(geometry, mass_kg: float) -> str:
    m = f"{_fmt(mass_kg)} kg"
    if isinstance(geometry, Box):
        return f"a {m} box of {' x '.join(_fmt(s) for s in geometry.size_m)} m"
    if isinstance(geometry, Cylinder):
        return (f"a {m} cylinder of radius {_fmt(geometry.radius_m)} m and length "
                f"{_fmt(geometry.length_m)} m")
    if isinstance(geometry, Sphere):
        return f"a {m} sphere of radius {_fmt(geometry.radius_m)} m"
    if isinstance(geometry, Mesh):
        return f"a {m} solid mesh '{geometry.uri}'"
    return f"a {m} body"


def _massive(link: Link) -> bool:
    inertial = link.inertial
    return inertial is not None and math.isfinite(inertial.mass_kg) and inertial.mass_kg > 0


def _tensor_ok(I: np.ndarray) -> bool:
    return bool(np.all(np.isfinite(I)))


def _positive_definite(I: np.ndarray) -> bool:
    return tensor_problem(I) not in ("not-positive-definite", "non-finite")


def _geometry_hint(ctx: CheckContext, link: Link) -> tuple[str, np.ndarray] | None:
    """(description, tensor in the inertial frame's axes) of the link's own geometry."""
    props = ctx.geometry_mass_properties(link)
    if props is None:
        return None
    R_link_com = link.inertial.T_link_com[:3, :3]
    I_com_axes = R_link_com.T @ np.asarray(props.inertia_kg_m2, dtype=float) @ R_link_com
    geometry, _T = link.geometry_for_mass()
    kind = "collision" if any(c.geometry is geometry for c in link.collisions) else "visual"
    count = sum(s.geometry is not None
                for s in (link.collisions if kind == "collision" else link.visuals))
    if count > 1:
        return (f"a {_fmt(link.inertial.mass_kg)} kg body of its {count} {kind} shapes "
                "(one density)", I_com_axes)
    return describe_geometry(geometry, link.inertial.mass_kg), I_com_axes


def _with_geometry(ctx: CheckContext, link: Link, text: str) -> str:
    found = _geometry_hint(ctx, link)
    if found is None:
        return text
    described, I = found
    return f"{text}; {described} gives {_inertia_xml(I)}"


def _judged_alone(ctx: CheckContext, link: Link, I: np.ndarray) -> bool:
    """Whether the simulator checks the link's own tensor (physics.inertia.
    degenerate_but_accepted: a point mass on a fixed joint, a merged URDF link's zeros)."""
    from reedtool.physics.inertia import degenerate_but_accepted

    return not degenerate_but_accepted(I, moving=ctx.is_moving(link),
                                       lumped=link.name in ctx.lumped_links)


@rule("I201", "mass-not-positive", "error", "A link's mass is negative, or zero on a moving link.", clause="cannot-fly")
def mass_not_positive(ctx: CheckContext) -> Iterator[Issue]:
    """A negative mass is never valid. A zero mass is fine on a link merged into its parent
    by a fixed joint (a frame marker), but a link that moves on its own joint needs mass:
    physics engines divide by it.

    Severity (error, cannot-fly): physics engines divide by a moving link's mass.
    """
    for link in ctx.robot.links:
        inertial = link.inertial
        if inertial is None or not math.isfinite(inertial.mass_kg):
            continue
        if any(issue.loc == inertial.mass_loc for issue in ctx.robot.parse_issues):
            continue  # unreadable <mass>: S101 reports it, the 0 here is a default
        mass = inertial.mass_kg
        if mass < 0 or (mass == 0 and ctx.is_moving(link)):
            why = "negative" if mass < 0 else "zero on a link that moves on its own joint"
            yield Issue(f"link '{link.name}' has mass {_fmt(mass)} kg ({why})",
                        inertial.mass_loc or inertial.loc, link.name,
                        hint="give the link its real (positive) mass in kg")


@rule("I202", "inertia-not-positive-definite", "error",
      "A link's inertia tensor is not symmetric positive definite.", clause="refused")
def inertia_not_positive_definite(ctx: CheckContext) -> Iterator[Issue]:
    """The inertia tensor of a body with mass has three positive principal moments. A zero
    or negative moment (often a zero `ixx`/`iyy`/`izz`, or products of inertia larger than
    the moments) makes the simulator reject the link or integrate nonsense.

    Links without mass are skipped (I201 covers moving ones; fixed ones are merged). A zero
    tensor on a fixed joint is a point mass, which gz-math accepts and a URDF link merged
    into its parent only adds to the parent's sum (aerial_gym's motor links); a negative
    moment is reported wherever it is (rounding noise of 1e-9 of the largest moment is
    zero, not negative).

    Severity (error, refused): gz-math rejects the tensor of a link simulated on its own.
    """
    for link in ctx.robot.links:
        if not _massive(link):
            continue
        I = np.asarray(link.inertial.inertia_kg_m2, dtype=float)
        if not _tensor_ok(I) or _positive_definite(I) or not _judged_alone(ctx, link, I):
            continue
        moments = np.linalg.eigvalsh((I + I.T) / 2)
        yield Issue(f"link '{link.name}': inertia is not positive definite (principal moments "
                    f"{', '.join(_fmt(m) for m in moments)} kg·m²)",
                    link.inertial.inertia_loc or link.inertial.loc, link.name,
                    hint=_with_geometry(ctx, link, "every principal moment must be > 0"))


@rule("I203", "inertia-triangle-inequality", "error",
      "A link's principal moments break the triangle inequality.", clause="refused")
def inertia_triangle_inequality(ctx: CheckContext) -> Iterator[Issue]:
    """For any real mass distribution each principal moment is at most the sum of the
    other two (A + B >= C; equality for a flat plate). Gazebo (gz-math) rejects a tensor
    that breaks it, and ODE/DART produce unphysical motion with it. The tolerance is
    0.1 % of the largest moment, for rounded hand-written values.

    Hand-edited inertia, or one copied from another model and scaled along one axis only,
    is the usual cause. Compute the tensor from the geometry (`reedtool inertia`). A URDF
    link on a fixed joint is merged into its parent by Gazebo's URDF parser: it is reported
    only when the merged body's tensor breaks the inequality too (RotorS's
    base_link_inertia is most of its body, so the seed's error stays).

    Severity (error, refused): gz-math rejects the tensor.
    """
    for link in ctx.robot.links:
        if not _massive(link):
            continue
        I = np.asarray(link.inertial.inertia_kg_m2, dtype=float)
        if not _tensor_ok(I) or not _positive_definite(I):
            continue  # I202
        if link.name in ctx.lumped_links and tensor_problem(I) == "triangle":
            # A merged URDF link counts only in the body Gazebo makes with its parent
            # (RotorS's base_link_inertia is most of that body: seed 000 stays an error).
            body = ctx.lumped_tensor(link.name)
            if body is not None and tensor_problem(body) != "triangle":
                continue
        a, b, c = np.linalg.eigvalsh((I + I.T) / 2)
        if tensor_problem(I) == "triangle":
            yield Issue(f"link '{link.name}': principal moments break the triangle inequality: "
                        f"{_fmt(a)} + {_fmt(b)} = {_fmt(a + b)} < {_fmt(c)} kg·m²",
                        link.inertial.inertia_loc or link.inertial.loc, link.name,
                        hint=_with_geometry(ctx, link, f"the largest moment can be at most "
                                                       f"{_fmt(a + b)} kg·m²"))


def _trace_findings(ctx: CheckContext, verdict: str) -> Iterator[Issue]:
    """Links whose shared verdict (physics.inertia.compare_link) is `verdict`."""
    for link, comparison in zip(ctx.robot.links, ctx.link_comparisons):
        if comparison.verdict != verdict or not _massive(link):
            continue
        if _mesh_extent_implausible(ctx, link):
            continue  # I206/I210 explain a mis-scaled mesh better
        found = _geometry_hint(ctx, link)
        if found is None:
            continue
        described, I_geom = found
        I = np.asarray(link.inertial.inertia_kg_m2, dtype=float)
        declared, expected = float(np.trace(I)), float(np.trace(I_geom))
        if expected <= 0:
            continue
        # The verdict's ratio: with several shapes, against the mass distribution over
        # them that fits best (physics.inertia.compare_link).
        ratio = comparison.trace_ratio if comparison.trace_ratio else declared / expected
        expected = declared / ratio if ratio > 0 else expected
        r_decl = math.sqrt(declared / (2 * link.inertial.mass_kg))
        r_geom = math.sqrt(expected / (2 * link.inertial.mass_kg))
        way = "larger" if ratio > 1 else "smaller"
        factor = ratio if ratio > 1 else 1 / ratio
        # The robot-level judgement (physics.inertia.judge_in_robot) says why a tensor
        # 100x off is only a warning, or why it is an error.
        why = comparison.message.split("; ", 1)[1] if "; " in comparison.message else ""
        yield Issue(f"link '{link.name}': inertia is {factor:,.3g}x {way} than "
                    f"{described} (radius of gyration {_fmt(r_decl)} m vs {_fmt(r_geom)} m)"
                    + (f"; {why}" if why else ""),
                    link.inertial.inertia_loc or link.inertial.loc, link.name,
                    hint=f"{described} gives {_inertia_xml(I_geom)}")


@rule("I204", "inertia-implausible-for-geometry", "warning",
      "A link's inertia is 10x above (or 100x below) what its geometry and mass give, "
      "without changing how the robot flies.", clause="ambiguous")
def inertia_implausible_for_geometry(ctx: CheckContext) -> Iterator[Issue]:
    """Compares the declared tensor with that of the link's geometry (all its collision
    shapes, else all its visual shapes, filled with the declared mass at one density)
    through the trace (twice the mass times the squared radius of gyration). With several
    shapes the mass may sit in any of them (a motor can and its prop disc): the tensor is
    judged against the distribution that fits it best, the uniform one or all of the mass
    in one shape. 10x larger is no real mass
    distribution (all mass in the corners of a box gives only 3x the solid box's inertia);
    smaller is, down to any share (a hub inside a large collision cylinder), so the
    smaller side is reported from 100x (a radius of gyration a tenth of the solid's).

    Severity (warning: suspicious, but the model loads and flies): reedtool cannot tell
    which of the two is wrong, the tensor or the geometry, and the robot flies the same
    either way: swapping the tensor for the geometry's changes none of the whole robot's
    principal moments by 2x. A tensor 100x off that does change them 2x or more is I209,
    an error.

    A geometry that no material could fill with the declared mass (denser than osmium,
    22,590 kg/m³: RotorS omav's 0.28 kg tilt units on 5 mm boxes need 2.2e6) is a
    placeholder standing for the part, not its body: the tensor is not compared with it.

    Placeholder links are not compared: a link whose mass and whose inertia about the
    robot's centre of mass are both under 0.1 % of the robot's (control surfaces of
    1e-8 kg, a 1e-15 kg sonar frame) changes hover thrust and attitude response by less
    than any flight stack resolves (physics.inertia.PLACEHOLDER_FRACTION has the
    derivation).

    A rotor link driven by a motor plugin with `rotorVelocitySlowdownSim` s (RotorS, PX4
    classic, gz MulticopterMotorModel) may declare s times its geometry's inertia: RotorS
    simulates the rotor s times slower and scales its inertia to keep its momentum. Such a
    link is reported by neither rule while the declared inertia divided by s is plausible.

    The verdict is `reedtool inertia`'s (one function), so both name the same links.
    The hint gives the geometry-derived tensor in the frame of the `<inertial>`.
    """
    yield from _trace_findings(ctx, "implausible")


@rule("I209", "inertia-orders-off-geometry", "error",
      "A link's inertia is 100x or more above its geometry's and decides how the robot flies.", clause="cannot-fly")
def inertia_orders_off_geometry(ctx: CheckContext) -> Iterator[Issue]:
    """The declared tensor's trace is at least 100x larger than that of the link's
    geometry filled uniformly with the declared mass (a smaller one is I204: mass gathered
    inside a shape is real, down to any share), and it matters: swapping
    every such tensor of the robot for its geometry's changes a principal moment of the
    whole robot by 2x or more, and this link's share of that change is a tenth or more.
    It is a placeholder value (`1.0` copied into every link: 43,000x for a 0.1 kg wheel
    of 6 cm radius) or a unit mistake (kg·mm² for kg·m² on the heavy side).

    Severity (error: the model as written cannot do what it is for): the robot's attitude
    dynamics are those of another body, beyond the 2x gain margin a controller tuned on
    the real vehicle keeps. Where the robot flies the same with either tensor it is I204
    (warning); placeholder links are not compared (see I204). The RotorS slowdown
    convention is recognised as for I204. `reedtool inertia` calls such a link "way-off"
    and exits 1.
    """
    yield from _trace_findings(ctx, "way-off")


@rule("I207", "robot-mass-not-positive", "error", "The whole robot's mass is zero or negative.", clause="cannot-fly")
def robot_mass_not_positive(ctx: CheckContext) -> Iterator[Issue]:
    """The links' declared masses add up to zero or less (one link with `mass 0` or
    `-0.0`, or negative masses cancelling positive ones). Gazebo cannot integrate a body
    without mass, and every thrust and hover figure divides by it.

    Severity (error, cannot-fly): there is nothing to integrate, and every thrust figure
    divides by the mass.
    """
    problem = robot_mass_problem(ctx.robot)
    if problem:
        first = next((link for link in ctx.robot.links if link.inertial is not None), None)
        loc = (first.inertial.mass_loc or first.inertial.loc) if first else None
        yield Issue(problem, loc, first.name if first else None,
                    hint="give each link its real mass in kg")


@rule("I208", "massless-link-with-inertia", "error",
      "A link has zero mass but a non-zero inertia.", clause="refused")
def massless_link_with_inertia(ctx: CheckContext) -> Iterator[Issue]:
    """Inertia is mass times squared distance: a body with no mass has none. A zero mass
    with a non-zero tensor is a mass that was forgotten (or set to 0 to "switch the link
    off"): the physics engines either reject the link or treat it as a body with
    rotational inertia but no translational one. A massless link with a zero tensor on a
    fixed joint is a frame and stays quiet. (On a moving link I201 already reports the
    zero mass.)

    Severity (error, refused): gz-math rejects a tensor without mass, and engines treat
    the link as half a body.
    """
    for link, comparison in zip(ctx.robot.links, ctx.link_comparisons):
        if comparison.verdict == "massless-inertia" and not ctx.is_moving(link):
            yield Issue(f"link '{link.name}' has mass 0 kg but a non-zero inertia",
                        link.inertial.mass_loc or link.inertial.loc, link.name,
                        hint="give the link its real mass, or zero the inertia of a frame-only "
                             "link")


def _local_bounds(ctx: CheckContext, geometry) -> np.ndarray | None:
    """(2, 3) bounding box of a geometry in its own frame."""
    if isinstance(geometry, Box):
        half = np.asarray(geometry.size_m, dtype=float) / 2
        return np.vstack([-half, half])
    if isinstance(geometry, Cylinder):
        half = np.array([geometry.radius_m, geometry.radius_m, geometry.length_m / 2])
        return np.vstack([-half, half])
    if isinstance(geometry, Sphere):
        half = np.full(3, geometry.radius_m)
        return np.vstack([-half, half])
    if isinstance(geometry, Mesh):
        return ctx.mesh_bounds(geometry)
    return None


def link_geometry_bounds(ctx: CheckContext, link: Link) -> np.ndarray | None:
    """Axis-aligned box (2, 3) around all of a link's visuals and collisions, in the link frame."""
    corners = []
    for shape in [*link.visuals, *link.collisions]:
        bounds = _local_bounds(ctx, shape.geometry)
        if bounds is None or not np.all(np.isfinite(bounds)):
            continue
        box = np.array([[bounds[i, 0], bounds[j, 1], bounds[k, 2]]
                        for i in (0, 1) for j in (0, 1) for k in (0, 1)])
        T = shape.T_link_geom
        corners.append(box @ T[:3, :3].T + T[:3, 3])
    if not corners:
        return None
    points = np.vstack(corners)
    return np.vstack([points.min(axis=0), points.max(axis=0)])


@rule("I205", "com-outside-geometry", "warning",
      "A link's centre of mass lies outside its geometry.", clause="suspicious")
def com_outside_geometry(ctx: CheckContext) -> Iterator[Issue]:
    """The `<inertial><origin>` is the centre of mass in the link frame; it lies inside
    the link's visual and collision shapes (their bounding box, plus 10 %). Outside it,
    the usual cause is an origin given in the parent's frame, or the joint offset applied
    twice.

    Severity (warning): the model loads and flies; where the mass sits may be a mistake.
    Placeholder links (under 0.1 % of the robot's mass and inertia, see I204: PX4's
    1e-8 kg control surfaces with their COM at the hinge's far end) are not judged.
    """
    for link in ctx.robot.links:
        if not _massive(link) or link.name in ctx.placeholder_links \
                or _mesh_extent_implausible(ctx, link):
            continue
        bounds = link_geometry_bounds(ctx, link)
        com = np.asarray(link.inertial.com_m, dtype=float)
        if bounds is None or not np.all(np.isfinite(com)):
            continue
        margin = max(COM_MARGIN_FRACTION * float(np.max(bounds[1] - bounds[0])),
                     COM_MARGIN_MIN_M)
        if np.any(com < bounds[0] - margin) or np.any(com > bounds[1] + margin):
            centre = (bounds[0] + bounds[1]) / 2
            yield Issue(f"link '{link.name}': centre of mass ({', '.join(_fmt(v) for v in com)}) m "
                        f"is outside its geometry, which spans "
                        f"({', '.join(_fmt(v) for v in bounds[0])}) to "
                        f"({', '.join(_fmt(v) for v in bounds[1])}) m",
                        link.inertial.loc, link.name,
                        hint="<inertial><origin xyz=> is in the link frame; the geometry's centre "
                             f"is xyz=\"{' '.join(_fmt(v) for v in centre)}\"")


def _mesh_extents(ctx: CheckContext, link: Link) -> Iterator[tuple[object, Mesh, float]]:
    seen: set[str] = set()
    for shape in [*link.visuals, *link.collisions]:
        mesh = shape.geometry
        if not isinstance(mesh, Mesh) or mesh.path is None:
            continue
        key = f"{mesh.path}|{tuple(np.asarray(mesh.scale, dtype=float))}"
        bounds = ctx.mesh_bounds(mesh) if key not in seen else None
        seen.add(key)
        if bounds is not None:
            yield shape, mesh, float(np.max(bounds[1] - bounds[0]))


def _mesh_extent_implausible(ctx: CheckContext, link: Link) -> bool:
    low, high = MESH_EXTENT_RANGE_M
    return any(not low <= extent <= high for _s, _m, extent in _mesh_extents(ctx, link))


def robot_size_m(ctx: CheckContext) -> float | None:
    """The robot's size from everything but its meshes: the spread of its link origins and
    its primitive shapes. None when that says nothing (one link, meshes only)."""
    sizes = []
    poses = ctx.link_poses
    if len(poses) > 1:
        origins = np.array([T[:3, 3] for T in poses.values()])
        sizes.append(float(np.max(origins.max(axis=0) - origins.min(axis=0))))
    for link in ctx.robot.links:
        for shape in [*link.visuals, *link.collisions]:
            if not isinstance(shape.geometry, Mesh):
                bounds = _local_bounds(ctx, shape.geometry)
                if bounds is not None and np.all(np.isfinite(bounds)):
                    sizes.append(float(np.max(bounds[1] - bounds[0])))
    size = max(sizes, default=0.0)
    return size if size > 0 else None


def _unit_certainly_wrong(ctx: CheckContext, extent_m: float) -> bool:
    """I210 rather than I206: see the thresholds in mesh_unit_wrong's docstring."""
    low, high = MESH_EXTENT_RANGE_M
    factor = MESH_UNIT_CERTAIN_FACTOR
    if extent_m > high * factor or extent_m < low / factor:
        return True
    reference = robot_size_m(ctx)
    if reference is not None:
        return extent_m >= factor * reference if extent_m > high else \
            extent_m <= reference / factor
    part_low, part_high = PLAUSIBLE_PART_M
    guess = extent_m * (0.001 if extent_m > high else 1000.0)
    return part_low <= guess <= part_high


def _mesh_scale_findings(ctx: CheckContext, certain: bool) -> Iterator[Issue]:
    if ctx.robot.static:
        return      # scenery (a 1.5 km runway, a warehouse floor): any size is a size
    low, high = MESH_EXTENT_RANGE_M
    for link in ctx.robot.links:
        for shape, mesh, extent in _mesh_extents(ctx, link):
            if low <= extent <= high or extent <= 0 or not math.isfinite(extent):
                continue
            if _unit_certainly_wrong(ctx, extent) != certain:
                continue
            from reedtool.physics.mesh_units import UNIT_WORDS, UNITS_M

            scale = np.asarray(mesh.scale, dtype=float)
            read = ctx.mesh_file(mesh)
            units = ["mm"]
            if extent > high:
                units = _units_of(link, read, scale) or units
                factors = [UNITS_M[u] for u in units]
                why = f"looks like {' or '.join(UNIT_WORDS[u] for u in units)} read as metres"
            else:
                factors, why = [1000.0], "looks scaled down twice"
            unit = getattr(read, "metres_per_unit", 1.0)
            declared = (f"; the file declares <unit meter=\"{unit:g}\">"
                        if getattr(read, "unit_declared", False) else "")
            fixes = [" ".join(_fmt(s * factor) for s in scale) for factor in factors]
            uses = " or ".join(f"scale=\"{fixed}\"" + (f" ({UNIT_WORDS[u]})" if len(fixes) > 1
                                                        else "")
                               for fixed, u in zip(fixes, units))
            yield Issue(f"link '{link.name}': mesh '{mesh.uri}' is {_fmt(extent)} m across "
                        f"({why}{declared})", shape.loc, link.name,
                        hint=f"use <mesh filename=\"{mesh.uri}\" {uses}/>, or "
                             "convert the file (reedtool import-stl)")


def _units_of(link: Link, read, scale) -> list[str]:
    """The units the mesh was likely written in, by the one detector import-stl and
    new-package use (physics.mesh_units): its size and the link's mass over its volume."""
    from reedtool.physics.mesh_units import signed_volume, units_read_as_metres

    triangles = getattr(read, "triangles_m", None)
    if triangles is None or len(triangles) == 0:
        return []
    scaled = np.asarray(triangles) * scale
    extent = float(np.max(np.ptp(scaled.reshape(-1, 3), axis=0)))
    mass = link.inertial.mass_kg if link.inertial is not None else None
    mass = mass if mass is not None and math.isfinite(mass) and mass > 0 else None
    return units_read_as_metres(extent, signed_volume(scaled) or None, mass)


@rule("I206", "mesh-scale-implausible", "warning",
      "A mesh is implausibly large or small: perhaps the wrong unit.", clause="ambiguous")
def mesh_scale_implausible(ctx: CheckContext) -> Iterator[Issue]:
    """CAD tools export STL in millimetres by default, URDF reads metres: a 470 mm frame
    becomes 470 m. The size is the mesh as Gazebo loads it: its coordinates times the
    COLLADA `<asset><unit meter=>` (a .dae exported in mm with meter="0.001" is right),
    times the `<mesh scale>`; STL and OBJ have no unit and are read as metres.

    A mesh larger than 20 m or smaller than 1 mm across is reported with the scale that
    brings it into range, for each unit (mm, inch, cm) that makes it a plausible link by
    the detector import-stl and new-package use (physics.mesh_units: its size, and the
    link's mass over its volume): as this warning when the rest of the robot leaves room for it
    being intended (a large ground plane, a tiny marker), as I210 (error) when the unit is
    certainly wrong.

    Severity (warning, ambiguous): a large ground plane or a tiny marker may be
    intended; I210 is the certain case.
    """
    yield from _mesh_scale_findings(ctx, certain=False)


@rule("I210", "mesh-unit-wrong", "error",
      "A mesh is about 1000x too large or too small: certainly the wrong unit.", clause="cannot-fly")
def mesh_unit_wrong(ctx: CheckContext) -> Iterator[Issue]:
    """The mesh, sized as Gazebo loads it (see I206), is outside 1 mm - 20 m and the unit
    is certainly wrong, which is the case when any of these holds:

    - it is more than 50x outside that range (over 1 km, or under 20 µm across);
    - it is at least 50x larger (or 50x smaller) than the robot's own size, taken from the
      spread of its link origins and its box, cylinder and sphere shapes;
    - the robot gives no size (meshes only) and reading the coordinates as the other unit
      (mm for a too large mesh, m for a too small one) makes it a plausible 1 cm - 5 m part.

    Gazebo shows and collides with a body a thousand times its size (or invisible), and
    a mesh used for inertia gives a tensor a million times off.

    Severity (error, cannot-fly): the body collides and weighs as one a thousand times
    its size (or invisible).

    A static model (`<static>true</static>`) is scenery, not a robot part: a runway mesh
    1.5 km across or a 20 m warehouse floor is what it is, and neither I206 nor I210
    judges its size.
    """
    yield from _mesh_scale_findings(ctx, certain=True)
