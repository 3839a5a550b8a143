"""Structure rules (S1xx): the model is a well-formed URDF tree that Gazebo will load as written.

A superset of what `check_urdf` (urdfdom) verifies, plus what the URDF->SDF conversion in
Gazebo does silently: dropping links without mass and resolving every mesh.
"""

from __future__ import annotations

import math
import os
from typing import Iterator

import numpy as np

from reedtool.checks.context import CheckContext
from reedtool.checks.finding import Issue
from reedtool.checks.registry import rule
from reedtool.model import JOINT_TYPES, Box, Cylinder, Mesh, Sphere

# Below this mass Gazebo's URDF->SDF conversion treats a link as massless and drops it.
SDF_MIN_MASS_KG = 1e-6

# Parse-issue kinds that have a rule of their own; every other kind is S101.
_ROUTED_KINDS = frozenset({
    "non-finite",               # S102
    "legacy-xacro",             # S103
    "xml-tolerated",            # S119
    "sdf-default-inertial",     # S120
    "sdf-undefined-element",    # S123
    "xml-declaration-late",     # S124
    "sdf-short-pose",           # S125
    "package-duplicate",        # S150
    *(f"sdf-refused-{kind}" for kind in (   # S160-S168: libsdformat's structural refusals
        "double-colon", "name-collision", "reserved-name", "canonical-link", "attached-to",
        "relative-to", "joint-frames", "model-without-link", "version", "script-uri", "root-elements")),
    "absolute-uri",             # S169
    "remote-uri",               # S190
    "classic-scoped-name",      # S191
})
# libsdformat's joint types (sdf/1.x/joint.sdf): what an SDF <joint type=> may be.
SDF_JOINT_TYPES = ("revolute", "continuous", "prismatic", "fixed", "ball", "screw",
                   "universal", "revolute2", "gearbox")
_PER_AXIS_JOINTS = {"revolute", "continuous", "prismatic", "planar"}
_LIMITED_JOINTS = {"revolute", "prismatic"}


def _fmt_names(names) -> str:
    return ", ".join(f"'{n}'" for n in names)


@rule("S101", "urdf-parse-error", "error", "An element or attribute could not be read as URDF.", clause="refused")
def urdf_parse_error(ctx: CheckContext) -> Iterator[Issue]:
    """The URDF reader could not read an element: a number that is not a number, a missing
    required attribute (a link or joint without name=, a <mass> without value=), a missing
    required element (<inertial> without <mass>) or an unknown geometry.

    urdfdom refuses such a file outright (check_urdf fails); Gazebo's parser may instead
    substitute defaults (zero mass, zero inertia) and simulate something you did not write.
    Fix the element at the reported line.

    Severity (error, refused): urdfdom and sdformat's URDF parser refuse the element.
    """
    for issue in ctx.robot.parse_issues:
        if issue.kind not in _ROUTED_KINDS:
            yield Issue(issue.message, issue.loc, issue.subject)


def _reader_issues(ctx: CheckContext, kind: str, hint: str | None = None) -> Iterator[Issue]:
    """The readers' issues of one routed kind, as this rule's findings."""
    for issue in ctx.robot.parse_issues:
        if issue.kind == kind:
            yield Issue(issue.message, issue.loc, issue.subject, hint=hint)


@rule("S102", "non-finite-number", "error", "A number in the model is NaN or infinite.", clause="cannot-fly")
def non_finite_number(ctx: CheckContext) -> Iterator[Issue]:
    """Every number in a URDF or SDF must be finite. `nan` and `inf` usually come from an xacro
    expression that divided by zero or used an undefined property default.

    Physics engines propagate a NaN through the whole simulation: the model explodes or
    vanishes on the first step. A joint limit written as DBL_MAX (1.79769e+308) is the
    exporters' "no limit", stored as given by the loaders: read as unbounded, not reported.

    Severity (error, cannot-fly): a NaN spreads through the whole simulation on the
    first step.
    """
    hint = ("write the number itself: SDF computes nothing, the text is the value"
            if ctx.robot.source_format == "sdf"
            else "check the xacro expression that computes this value")
    yield from _reader_issues(ctx, "non-finite", hint)


@rule("S103", "legacy-xacro-tag", "warning", "An old-style xacro tag was copied into the URDF.",
      clause="suspicious")
def legacy_xacro_tag(ctx: CheckContext) -> Iterator[Issue]:
    """Old tutorials use `<property>`, `<include>`, `<macro>` and macro calls without the
    `xacro:` prefix. xacro 2.x no longer understands them and copies them into the URDF
    unchanged, so properties are never defined and macros never expanded.

    Severity (warning: suspicious, but the model loads): Gazebo ignores the copied tag. What
    it should have made is missing, and where that breaks the model it shows elsewhere: an
    undefined property stops the expansion (an input error), a missing link or joint is
    a structure error (S104, S105). A copied call of a macro that makes only a
    `<transmission>` (GRVC's aeroarms) changes nothing Gazebo flies.

    Spell them `<xacro:property>`, `<xacro:include>`, `<xacro:macro>` and `<xacro:NAME/>`
    (`reedtool expand --fix-legacy` rewrites them).
    """
    for issue in ctx.robot.parse_issues:
        if issue.kind == "legacy-xacro":
            message = issue.message.removeprefix(f"{issue.loc}: ")  # the finding says where
            yield Issue(message, issue.loc, issue.subject,
                        hint="use the xacro: prefix (reedtool expand --fix-legacy rewrites it)")


@rule("S104", "single-root", "error", "The model must have exactly one root link.", clause="refused")
def single_root(ctx: CheckContext) -> Iterator[Issue]:
    """A URDF is a tree: exactly one link is not the child of any joint. Two roots mean a
    joint is missing (or names the wrong child); urdfdom rejects the file with "two root
    links found". A model without any link is rejected too.

    A static SDF model (a stand with a ball resting on it) may hold free bodies: its own
    links are fixed in the world, and libsdformat loads several roots; not reported there.

    Severity (error, refused): urdfdom rejects a URDF without exactly one root.
    """
    if not ctx.robot.links:
        yield Issue("the model has no <link>", ctx.robot.loc, ctx.robot.name,
                    hint="a URDF needs at least one link")
        return
    roots = ctx.tree.roots
    if len(roots) > 1 and not ctx.robot.static:
        first, *others = roots
        for name in others:
            link = ctx.robot.link_map[name]
            yield Issue(f"link '{name}' is a second root: no joint has it as child "
                        f"(the first root is '{first}')", link.loc, name,
                        hint=f"add a joint with <child link=\"{name}\"/> to attach it")


@rule("S105", "joint-link-missing", "error", "A joint's parent or child link does not exist.", clause="refused")
def joint_link_missing(ctx: CheckContext) -> Iterator[Issue]:
    """Every joint's `<parent link=>` and `<child link=>` must name a link of the model.
    A typo or a missing namespace prefix here makes urdfdom reject the file. In SDF a
    parent may also be `world` (the model welded to the world), and a parent or child a
    frame, joint, nested model or `__model__`, each standing for the link it is on.

    In SDF, `<parent>world</parent>` names the world frame (libsdformat accepts it): a
    joint that pins the model in the world, not a missing link.

    Severity (error, refused): urdfdom rejects the joint and Gazebo cannot create it.
    """
    links = ctx.robot.link_map
    sdf = ctx.robot.source_format == "sdf"
    for joint in ctx.robot.joints:
        for role, name in (("parent", joint.parent), ("child", joint.child)):
            if sdf and role == "parent" and name == "world":
                continue    # SDF's fixed frame: a joint to it pins the model in the world
            if name is not None and name not in links:
                yield Issue(f"joint '{joint.name}': {role} link '{name}' does not exist",
                            joint.loc, joint.name, hint=_closest_hint(name, links))


def _closest_hint(name: str, candidates) -> str:
    import difflib

    close = difflib.get_close_matches(name, list(candidates), n=1)
    return f"did you mean '{close[0]}'?" if close else "declare the link or fix the name"


@rule("S106", "duplicate-link-name", "error", "Two links have the same name.", clause="refused")
def duplicate_link_name(ctx: CheckContext) -> Iterator[Issue]:
    """Link names must be unique. A macro instantiated twice without a distinct prefix or
    suffix is the usual cause; urdfdom rejects the file.

    Severity (error, refused): urdfdom and libsdformat reject two elements of one name.
    """
    yield from _redeclared(ctx.robot.links, ctx.robot.link_map, "link")


@rule("S107", "duplicate-joint-name", "error", "Two joints have the same name.", clause="refused")
def duplicate_joint_name(ctx: CheckContext) -> Iterator[Issue]:
    """Joint names must be unique; urdfdom rejects the file otherwise, and Gazebo plugins
    that look a joint up by name would find only one of them.

    Severity (error, refused): urdfdom and libsdformat reject two elements of one name.
    """
    yield from _redeclared(ctx.robot.joints, ctx.robot.joint_map, "joint")


def _redeclared(elements, first_by_name, kind: str) -> Iterator[Issue]:
    """Every element whose name an earlier element already took."""
    seen: set[str] = set()
    for element in elements:
        if element.name in seen:
            first = first_by_name[element.name]
            yield Issue(f"{kind} '{element.name}' is declared again (first at {first.loc})",
                        element.loc, element.name, hint=f"give each {kind} a unique name")
        seen.add(element.name)


@rule("S108", "link-multiple-parents", "error", "A link is the child of more than one joint.", clause="refused")
def link_multiple_parents(ctx: CheckContext) -> Iterator[Issue]:
    """In a tree every link has at most one parent joint. A second joint naming the same
    child closes a loop that URDF cannot express.

    Severity (error, refused): urdfdom rejects a link with two parents.
    """
    for child, joints in ctx.tree.extra_parents.items():
        first = ctx.tree.parent_joint[child]
        for joint in joints:
            yield Issue(f"link '{child}' is already the child of joint '{first.name}'; "
                        f"joint '{joint.name}' makes it a child again", joint.loc, joint.name,
                        hint="each link can be the child of one joint only")


@rule("S109", "kinematic-cycle", "error", "The joints form a cycle.", clause="refused")
def kinematic_cycle(ctx: CheckContext) -> Iterator[Issue]:
    """Following parent links from some link leads back to it. urdfdom reports this as
    "no root link found"; the links on the cycle are named here.

    Severity (error, refused): urdfdom and libsdformat reject a loop in the tree.
    """
    for cycle in ctx.tree.cycles:
        joint = ctx.tree.parent_joint[cycle[0]]
        yield Issue(f"links {' <- '.join(cycle + [cycle[0]])} form a cycle", joint.loc,
                    joint.name, hint="remove or re-parent one of these joints")


@rule("S110", "joint-type-invalid", "error", "A joint has an unknown type.", clause="refused")
def joint_type_invalid(ctx: CheckContext) -> Iterator[Issue]:
    """URDF joint types are revolute, continuous, prismatic, fixed, floating and planar;
    an SDF model's are SDFormat's: revolute, continuous, prismatic, fixed, ball, screw,
    universal, revolute2 and gearbox (ardupilot_gazebo's zephyr_with_parachute hangs its
    parachute on a ball joint). Each file is held to its own format, as its parser does.

    Severity (error, refused): the parser does not know the type.
    """
    types = SDF_JOINT_TYPES if ctx.robot.source_format == "sdf" else JOINT_TYPES
    for joint in ctx.robot.joints:
        if joint.type not in types:
            import difflib  # here: only a wrong type needs it, not every validate

            close = difflib.get_close_matches(joint.type, types, n=1)
            hint = f"did you mean '{close[0]}'?" if close else f"use one of {', '.join(types)}"
            what = f"type '{joint.type}'" if joint.type else "no type="
            yield Issue(f"joint '{joint.name}' has {what}", joint.loc, joint.name, hint=hint)


@rule("S111", "joint-limit-missing", "error", "A revolute or prismatic joint lacks <limit>.", clause="refused")
def joint_limit_missing(ctx: CheckContext) -> Iterator[Issue]:
    """Revolute and prismatic joints need `<limit lower= upper= effort= velocity=/>`;
    urdfdom requires effort and velocity and rejects the joint without them. A spinning
    joint (a wheel, a rotor) should be `continuous` instead.

    Severity (error, refused): urdfdom rejects a revolute or prismatic joint without
    effort and velocity limits.
    """
    for joint in ctx.robot.joints:
        if joint.type not in _LIMITED_JOINTS:
            continue
        if joint.limit is None:
            yield Issue(f"{joint.type} joint '{joint.name}' has no <limit>", joint.loc,
                        joint.name, hint="add <limit lower=\"..\" upper=\"..\" effort=\"..\" "
                                         "velocity=\"..\"/>, or make it continuous")
            continue
        missing = [a for a in ("effort", "velocity") if getattr(joint.limit, a) is None]
        if missing:
            yield Issue(f"{joint.type} joint '{joint.name}': <limit> has no "
                        f"{' or '.join(m + '=' for m in missing)}", joint.limit.loc, joint.name,
                        hint="urdfdom requires both effort= and velocity=")


@rule("S112", "joint-limit-inverted", "error", "A joint's lower limit is above its upper limit.", clause="cannot-fly")
def joint_limit_inverted(ctx: CheckContext) -> Iterator[Issue]:
    """With lower > upper the allowed range is empty; simulators pin the joint or
    behave erratically.

    Severity (error, cannot-fly): the joint cannot move between its limits.
    """
    for joint in ctx.robot.joints:
        limit = joint.limit
        if joint.type in _LIMITED_JOINTS and limit is not None and limit.lower is not None \
                and limit.upper is not None and limit.lower > limit.upper \
                and math.isfinite(limit.lower) and math.isfinite(limit.upper):  # else S102
            yield Issue(f"joint '{joint.name}': lower limit {limit.lower:g} > upper limit "
                        f"{limit.upper:g}", limit.loc, joint.name, hint="swap lower and upper")


@rule("S113", "joint-axis-zero", "error", "A moving joint's axis is the zero vector.", clause="refused")
def joint_axis_zero(ctx: CheckContext) -> Iterator[Issue]:
    """Revolute, continuous, prismatic and planar joints move along or about their
    `<axis xyz=>`, which must not be zero (it is normalised by every consumer).

    Severity (error, refused): libsdformat refuses an axis whose norm is zero.
    """
    for joint in ctx.robot.joints:
        axis = np.asarray(joint.axis, dtype=float)
        if joint.type in _PER_AXIS_JOINTS and np.all(np.isfinite(axis)) \
                and np.linalg.norm(axis) < 1e-12:
            yield Issue(f"joint '{joint.name}' has axis 0 0 0", joint.axis_loc or joint.loc,
                        joint.name, hint="give a unit axis, e.g. xyz=\"0 0 1\"")


@rule("S114", "gazebo-reference-missing", "warning",
      "A <gazebo reference=> names no link or joint.", clause="suspicious")
def gazebo_reference_missing(ctx: CheckContext) -> Iterator[Issue]:
    """A `<gazebo reference="NAME">` block applies to the link or joint called NAME.
    When there is none, Gazebo ignores the block silently: its material, friction or
    sensor never appears.

    Severity (warning, suspicious): Gazebo ignores the block and the model loads; the
    settings meant for it are lost.
    """
    names = set(ctx.robot.link_map) | set(ctx.robot.joint_map)
    for block in ctx.robot.gazebo:
        if block.reference is not None and block.reference not in names:
            yield Issue(f"<gazebo reference=\"{block.reference}\">: no link or joint is "
                        f"named '{block.reference}'", block.loc, block.reference,
                        hint=_closest_hint(block.reference, names))


def mesh_shapes(ctx: CheckContext) -> Iterator[tuple]:
    """(link, kind, shape, mesh) for every mesh reference, each shape once.

    Shapes are compared by identity: two visuals naming the same mesh file are two shapes.
    """
    for link in ctx.robot.links:
        for kind, shapes in (("visual", link.visuals), ("collision", link.collisions)):
            for shape in shapes:
                if isinstance(shape.geometry, Mesh) and shape.geometry.uri:
                    yield link, kind, shape, shape.geometry


def _refused(ctx: CheckContext, mesh: Mesh) -> bool:
    """Reported by S131 or S130: no point saying it is also missing or unreadable."""
    from reedtool.io.meshes import format_problem
    from reedtool.resolve.references import uri_problem

    return bool(uri_problem(mesh.uri, mesh.path) or format_problem(mesh.uri, ctx.simulator))


@rule("S115", "mesh-unresolved", "error", "A mesh file cannot be found or read.", clause="refused")
def mesh_unresolved(ctx: CheckContext) -> Iterator[Issue]:
    """Every `<mesh filename=>` must resolve to a readable file: `package://PKG/...`
    through the package search path, `file://` and plain paths relative to the model.
    Gazebo shows nothing (or fails to spawn) for a mesh it cannot find.

    An STL, COLLADA (.dae) or OBJ file must also hold a mesh Gazebo can read: a damaged
    or truncated file (not XML, a `<triangles>` index past the positions, an STL whose
    size does not match its facet count), an empty export, or one with NaN coordinates
    is reported with what is wrong with it. (glTF/GLB/FBX are only checked to exist.)

    Severity (error, refused): Gazebo classic does not report a mesh it cannot find; it
    keeps looking (its model database included) and the world never comes up (a known
    classic defect). gz-sim logs the error and spawns the model without that geometry.
    """
    from reedtool.resolve.resources import is_remote_uri

    for link, kind, shape, mesh in mesh_shapes(ctx):
        if _refused(ctx, mesh) or is_remote_uri(mesh.uri):
            continue        # a web URI Gazebo fetches: S190 says it was not checked
        if mesh.path is None:
            reason = mesh.resolve_error or "cannot be resolved"
            yield Issue(f"link '{link.name}' {kind} mesh '{mesh.uri}': {reason}",
                        shape.loc, link.name,
                        hint="pass --package-path DIR for the package that holds it")
        elif not mesh.path.is_file() or not os.access(mesh.path, os.R_OK):
            yield Issue(f"link '{link.name}' {kind} mesh '{mesh.uri}': {mesh.path} "
                        "is not a readable file", shape.loc, link.name,
                        hint="check the file name and its case")
        elif ctx.mesh_error(mesh):
            yield Issue(f"link '{link.name}' {kind} mesh '{mesh.uri}': "
                        f"{ctx.mesh_error(mesh)}", shape.loc, link.name,
                        hint=f"export the part again as {mesh.path.suffix.lstrip('.').upper()}")


@rule("S190", "remote-resource-not-checked", "info",
      "A mesh or included model comes from the web (Fuel): Gazebo fetches it, reedtool "
      "could not check it offline.", clause="explains")
def remote_resource_not_checked(ctx: CheckContext) -> Iterator[Issue]:
    """An `https://fuel.gazebosim.org/...` (or any http/https) URI in a `<mesh>` or an
    `<include>` is fetched by Gazebo when the world loads: gz-sim through gz-fuel-tools
    (into ~/.gz/fuel), Gazebo Classic through its model database. reedtool works offline,
    so the model is checked without it: an included model is left out, a mesh is not
    measured. Nothing is wrong with the model for that.

    Severity (info, explains): Gazebo loads such a model; what reedtool could not check is
    said so, once per URI. To check it, download it (`gz fuel download -u URI`) and pass
    `--package-path DIR` with the folder holding it, with the URI as a `model://` one.
    """
    from reedtool.resolve.resources import REMOTE_NOT_CHECKED, is_remote_uri

    yield from _reader_issues(ctx, "remote-uri")
    seen = set()
    for link, kind, shape, mesh in mesh_shapes(ctx):
        if is_remote_uri(mesh.uri) and mesh.uri not in seen:
            seen.add(mesh.uri)
            yield Issue(f"link '{link.name}' {kind} mesh '{mesh.uri}' {REMOTE_NOT_CHECKED}",
                        shape.loc, link.name)


@rule("S120", "sdf-link-default-inertial", "warning",
      "An SDF link has no <inertial>: sdformat gives it 1 kg and a 1 kg·m² inertia.",
      clause="suspicious")
def sdf_link_default_inertial(ctx: CheckContext) -> Iterator[Issue]:
    """libsdformat reads a `<link>` without `<inertial>` as 1 kg with a unit inertia
    tensor, and Gazebo simulates it so: a visual-only link (a trail, a marker) adds a
    kilogram to the vehicle. reedtool counts it the same way in every mass figure.

    Severity (warning: suspicious, but the model loads and flies): the element is valid
    SDF; whether the kilogram is meant cannot be told.

    A static model (`<static>true</static>`: a building, a runway, a tree) is never moved
    by the physics engine, so its mass is never used: not reported.
    """
    if ctx.robot.static:
        return
    yield from _reader_issues(
        ctx, "sdf-default-inertial",
        hint="give the link its <inertial> (mass and inertia), even a small one")


@rule("S123", "sdf-element-not-in-version", "info",
      "An element the file's declared SDF version does not define is ignored.",
      clause="explains")
def sdf_element_not_in_version(ctx: CheckContext) -> Iterator[Issue]:
    """libsdformat reads a file by the spec of the version it declares (converting older
    versions up): an element that version does not define is ignored with a warning. A
    1.7+ file's `<use_parent_model_frame>` (removed in 1.7; only a 1.6 file's is converted
    to `expressed_in="__model__"`) therefore leaves the joint axis in the joint frame, and
    reedtool reads it so too (SITL_Models' alti_transition_quad and skywalker_x8 declare
    1.7 and keep it).

    Severity (info, explains): libsdformat ignores the element the same way.
    """
    yield from _reader_issues(ctx, "sdf-undefined-element")


@rule("S124", "xml-declaration-late", "warning",
      "A comment precedes the XML declaration: gz-sim refuses the file, Gazebo classic reads it.",
      clause="suspicious")
def xml_declaration_late(ctx: CheckContext) -> Iterator[Issue]:
    """TinyXML (Gazebo classic's libsdformat 9) reads an XML declaration anywhere; TinyXML2
    5 and later (libsdformat 10+, so gz-sim) refuse one that follows a comment (PX4
    classic's generated depth_camera.sdf starts with a comment line). Blank lines before it
    are fine for both.

    Severity (warning): a model written for Gazebo classic (its plugins are classic ones)
    loads where it is meant to, so nothing is reported for it beyond S119; for gz-sim the
    file is refused, but reedtool cannot be sure which Gazebo a model without plugins is
    for.
    """
    if ctx.simulator == "classic":
        return
    yield from _reader_issues(
        ctx, "xml-declaration-late",
        hint="move the comment below the <?xml ...?> line, or drop the line")


@rule("S125", "sdf-pose-short", "warning",
      "A <pose> has 3 numbers: Gazebo classic reads a position, gz-sim refuses it.",
      clause="suspicious")
def sdf_pose_short(ctx: CheckContext) -> Iterator[Issue]:
    """A pose is six numbers (x y z roll pitch yaw). libsdformat 9, Gazebo classic's, reads
    `<pose>x y z</pose>` as a position with no rotation (its stream read has no failure
    check); libsdformat 12 and later (gz-sim) refuse the file ("must have 6 values").
    GymFC's nf1 twin is written so; reedtool reads it as libsdformat 9 does.

    Severity (warning): a model made for Gazebo classic (classic plugins) loads where it
    is meant to and is not reported; for any other model gz-sim may be its target.
    """
    if ctx.simulator == "classic":
        return
    yield from _reader_issues(ctx, "sdf-short-pose", hint="write all six numbers: x y z 0 0 0")


@rule("S191", "sdf-classic-scoped-name", "warning",
      "A joint names its own model's link by the scoped name only Gazebo Classic resolves.",
      clause="suspicious")
def sdf_classic_scoped_name(ctx: CheckContext) -> Iterator[Issue]:
    """Inside model `iris`, `<parent>iris::base_link</parent>` is `base_link`: Gazebo Classic
    (libsdformat 9, files before SDF 1.8) finds a joint's link by its scoped name in the
    world when the model has none of that name (Joint::Load falls back to
    World::BaseByName). libsdformat 12 and later (gz-sim) look in the model only and refuse
    the file ("Child frame with name[iris::base_link] ... not found"). reedtool resolves it
    as Classic does, so the tree and every computation are those Classic simulates, and
    no structure error (S104, S105) is reported for it.

    Severity (warning): a model made for Gazebo classic (classic plugins) loads where it
    is meant to and is not reported; for any other model gz-sim may be its target.
    """
    if ctx.simulator == "classic":
        return
    yield from _reader_issues(ctx, "classic-scoped-name",
                              hint="name the link without its model's name")


@rule("S130", "mesh-format-unsupported", "error",
      "A mesh file is in a format the simulator cannot load.", clause="refused")
def mesh_format_unsupported(ctx: CheckContext) -> Iterator[Issue]:
    """Gazebo picks its mesh loader by file extension. Gazebo classic loads STL, COLLADA
    (.dae) and Wavefront OBJ; gz-sim (gz-common) also loads glTF (.gltf, .glb) and FBX.
    CAD formats (`body.STEP`, `.SLDPRT`, `.IGES`) and an extensionless file load nothing:
    the link is invisible and, as a collision, falls through the world.

    The simulator is read from the model: gz-sim system plugins mean gz-sim; Gazebo
    classic plugins (`lib*.so`: gazebo_ros, RotorS, PX4 classic) and no gz system mean
    classic; a model with neither is held to gz-sim's list. Case does not matter
    (`body.STL` is an STL).

    Severity (error, refused): the simulator's mesh loader does not read the format.
    """
    from reedtool.io.meshes import format_problem
    from reedtool.resolve.references import uri_problem

    for link, kind, shape, mesh in mesh_shapes(ctx):
        if uri_problem(mesh.uri, mesh.path):
            continue   # S131
        problem = format_problem(mesh.uri, ctx.simulator)
        if problem:
            yield Issue(f"link '{link.name}' {kind} mesh '{mesh.uri}': {problem}",
                        shape.loc, link.name,
                        hint="export the part as STL or COLLADA (.dae) and reference that file")


@rule("S131", "mesh-uri-escapes", "warning",
      "A mesh reference leaves its package or points at system files.", clause="suspicious")
def mesh_uri_escapes(ctx: CheckContext) -> Iterator[Issue]:
    """A `package://PKG/../../..` or `model://` path that climbs out of its package with
    `..`, or a reference into a system directory (`file:///etc/passwd`, `/proc/...`),
    is never a mesh: it makes every machine that loads the model open files outside the
    model (a leak when the model comes from someone else) and works on no other machine.
    reedtool does not open such a file.

    Severity (warning): Gazebo follows the path and loads the model on this machine; the
    reference is suspicious, not refused.
    """
    from reedtool.resolve.references import uri_problem

    for link, kind, shape, mesh in mesh_shapes(ctx):
        problem = uri_problem(mesh.uri, mesh.path)
        if problem:
            yield Issue(f"link '{link.name}' {kind} mesh '{mesh.uri}': {problem}",
                        shape.loc, link.name,
                        hint="reference the mesh inside its package: package://PKG/meshes/NAME")


def _geometry_sizes(geometry) -> dict[str, float]:
    if isinstance(geometry, Box):
        return {f"size[{i}]": float(v) for i, v in enumerate(geometry.size_m)}
    if isinstance(geometry, Cylinder):
        return {"radius": geometry.radius_m, "length": geometry.length_m}
    if isinstance(geometry, Sphere):
        return {"radius": geometry.radius_m}
    if isinstance(geometry, Mesh):
        return {f"scale[{i}]": float(v) for i, v in enumerate(geometry.scale)}
    return {}


@rule("S116", "geometry-size-invalid", "error",
      "A geometry has a zero or negative size (a mesh: a zero scale).", clause="refused")
def geometry_size_invalid(ctx: CheckContext) -> Iterator[Issue]:
    """Box sizes, cylinder radius and length and sphere radius must be positive, and a
    mesh scale non-zero. A zero size makes a collision shape degenerate (objects fall
    through it); libsdformat refuses a non-positive box size or radius. A negative mesh
    scale is a mirror, which Gazebo draws (S121, S122).

    Severity (error, refused): libsdformat refuses a non-positive box size or radius,
    and a zero scale makes the shape degenerate.
    """
    for link in ctx.robot.links:
        for shape in [*link.visuals, *link.collisions]:
            mesh = isinstance(shape.geometry, Mesh)
            for name, value in _geometry_sizes(shape.geometry).items():
                if value is not None and math.isfinite(value) and value <= 0 \
                        and not (mesh and value < 0):
                    kind = type(shape.geometry).__name__.lower()
                    yield Issue(f"link '{link.name}': {kind} {name} is {value:g}", shape.loc,
                                link.name, hint="sizes must be positive (metres)")


def _mirrored_meshes(ctx: CheckContext, collisions: bool):
    for link in ctx.robot.links:
        for shape in (link.collisions if collisions else link.visuals):
            if not isinstance(shape.geometry, Mesh):
                continue
            scale = np.broadcast_to(np.asarray(shape.geometry.scale, dtype=float), (3,))
            axes = [f"{'xyz'[i]} {scale[i]:g}" for i in range(3)
                    if math.isfinite(scale[i]) and scale[i] < 0]
            if axes:
                yield link, shape, axes


@rule("S121", "visual-mesh-mirrored", "info",
      "A visual mesh is mirrored by a negative scale.", clause="explains")
def visual_mesh_mirrored(ctx: CheckContext) -> Iterator[Issue]:
    """A negative `<mesh scale>` component mirrors the mesh. For a visual that is a
    convention: the MRS UAV models draw their clockwise propellers as the counter-clockwise
    mesh with scale -1. Gazebo draws it mirrored.

    Severity (info, explains): a mirrored visual is drawn as written.
    """
    for link, shape, axes in _mirrored_meshes(ctx, collisions=False):
        yield Issue(f"link '{link.name}': visual mesh '{shape.geometry.uri}' is mirrored "
                    f"({', '.join(axes)})", shape.loc, link.name)


@rule("S122", "collision-mesh-mirrored", "warning",
      "A collision mesh is mirrored by a negative scale: its faces point inwards.",
      clause="suspicious")
def collision_mesh_mirrored(ctx: CheckContext) -> Iterator[Issue]:
    """A negative `<mesh scale>` on a collision mirrors the mesh and with an odd number of
    negative components turns its faces inside out: the physics engine's contacts may push
    objects into the shape rather than out of it.

    Severity (warning: the model loads and can fly): contacts only matter on the ground.
    """
    for link, shape, axes in _mirrored_meshes(ctx, collisions=True):
        yield Issue(f"link '{link.name}': collision mesh '{shape.geometry.uri}' is mirrored "
                    f"({', '.join(axes)})", shape.loc, link.name,
                    hint="mirror the file itself, or use a primitive shape for the collision")


@rule("S117", "link-dropped-by-sdf", "error",
      "A moving link has no inertial or a mass below 1e-6 kg; Gazebo drops it.", clause="refused")
def link_dropped_by_sdf(ctx: CheckContext) -> Iterator[Issue]:
    """When Gazebo converts URDF to SDF it silently drops a link that is attached by a
    non-fixed joint and has no `<inertial>` or a mass below 1e-6 kg, together with its
    joint and everything below it. A rotor link dropped this way means a motor plugin
    that cannot find its joint. Links on fixed joints are merged into their parent
    instead and need no mass of their own.

    Negative or zero masses are reported by I201. Native SDF models are not converted
    (sdformat gives a link without `<inertial>` 1 kg), so this rule reads URDF input only.

    Severity (error, refused): Gazebo's URDF to SDF conversion drops the link.
    """
    if ctx.robot.source_format != "urdf":
        return
    for link in ctx.robot.links:
        if not ctx.is_moving(link):
            continue
        joint = ctx.parent_joint(link.name)
        if link.inertial is None:
            yield Issue(f"link '{link.name}' (child of {joint.type} joint '{joint.name}') has "
                        "no <inertial>; Gazebo drops it", link.loc, link.name,
                        hint="add <inertial> with the link's mass and inertia")
        elif 0 < link.inertial.mass_kg < SDF_MIN_MASS_KG:
            yield Issue(f"link '{link.name}' has mass {link.inertial.mass_kg:g} kg < "
                        f"{SDF_MIN_MASS_KG:g} kg; Gazebo drops it",
                        link.inertial.mass_loc or link.inertial.loc, link.name,
                        hint="give the link its real mass")


# Plugin parameters that name a link Gazebo must find at run time.
_PLUGIN_LINK_PARAMS = ("linkName", "bodyName", "link_name", "body_name")
# sdformat's URDF->SDF conversion (parser_urdf.cc, ReduceSDFExtensionPluginFrameReplace)
# rewrites exactly these two elements of a <plugin> directly inside a <gazebo> block when
# it lumps the link they name, and adds the lumped offset as <xyzOffset>/<rpyOffset>.
_REWRITTEN_BY_LUMPING = ("bodyName", "frameName")
_KEEP_FIXED_JOINT = ("disableFixedJointLumping", "preserveFixedJoint")


def _keeps_fixed_joint(ctx: CheckContext, joint_name: str) -> bool:
    for block in ctx.robot.gazebo:
        if block.reference == joint_name:
            for node in block.elements:
                if node.tag in _KEEP_FIXED_JOINT and (node.text or "").strip().lower() == "true":
                    return True
    return False


@rule("S118", "plugin-link-merged", "warning",
      "A plugin names a link that fixed-joint lumping merges away.", clause="suspicious")
def plugin_link_merged(ctx: CheckContext) -> Iterator[Issue]:
    """Gazebo merges every link attached by a fixed joint into its parent when it converts
    URDF to SDF, so the link's name no longer exists in the simulation. A plugin told to
    use that link by `<linkName>` (or `<link_name>`, `<body_name>`) then fails to load or
    attaches to nothing.

    `<bodyName>` and `<frameName>` are the exception: the conversion rewrites them to the
    parent link and records the lumped link's offset in `<xyzOffset>`/`<rpyOffset>`, so a
    plugin naming a lumped link there (gazebo_ros IMU, P3D) works and is not reported.

    Keep the joint with `<gazebo reference="JOINT"><preserveFixedJoint>true</preserveFixedJoint>
    </gazebo>` (`disableFixedJointLumping` on older Gazebo), or make it a revolute joint
    with zero limits, as RotorS does for its sensor links. Native SDF models are not
    lumped, so this rule reads URDF input only.

    Severity (warning, suspicious): the model loads, and the plugin looks for a link
    that is gone.
    """
    if ctx.robot.source_format != "urdf":
        return
    for _block, plugin in ctx.robot.plugins():
        for tag in _PLUGIN_LINK_PARAMS:
            if tag in _REWRITTEN_BY_LUMPING:
                continue
            name = plugin.param(tag)
            joint = ctx.parent_joint(name) if name else None
            if joint is None or joint.moves or _keeps_fixed_joint(ctx, joint.name):
                continue
            yield Issue(f"plugin '{plugin.name}' <{tag}> names link '{name}', which fixed joint "
                        f"'{joint.name}' merges into '{joint.parent}' in Gazebo",
                        plugin.param_loc(tag), plugin.name or name,
                        hint=f"add <gazebo reference=\"{joint.name}\"><preserveFixedJoint>true"
                             "</preserveFixedJoint></gazebo>")


@rule("S119", "xml-tolerated", "info",
      "The file uses XML that Gazebo reads but strict XML tools reject.", clause="explains")
def xml_tolerated(ctx: CheckContext) -> Iterator[Issue]:
    """libsdformat parses with TinyXML2, which accepts `--` inside a comment and a
    namespace prefix (such as `gz:`) used without its `xmlns:` declaration. Gazebo loads
    such a file and reedtool reads it the same way, but XML 1.0 forbids both: xmllint,
    lxml, check_urdf-style tools and XML editors refuse the file or flag it.

    Nothing breaks in simulation. To keep other tools happy, write single hyphens in
    comments and declare the prefix on the root element (`<sdf xmlns:gz="...">`).

    Severity (info, explains): Gazebo reads the file; only strict XML tools do not.
    """
    yield from _reader_issues(
        ctx, "xml-tolerated",
        hint="single hyphens in comments; declare xmlns:PREFIX on the root")


@rule("S150", "package-name-ambiguous", "warning",
      "Two ROS packages with the same name are on the search path; one is ignored.", clause="suspicious")
def package_name_ambiguous(ctx: CheckContext) -> Iterator[Issue]:
    """`$(find pkg)` and `package://pkg/...` name a package, not a directory. When two
    packages of that name sit under one search root (a copied package, a backup next to
    the original), ROS and reedtool take one of them and the edits in the other never
    reach the simulation. The finding names both and the one used.

    Remove or rename the copy, or put the intended one first with `--package-path`.

    Severity (warning, suspicious): one package is used; edits to the other never reach
    the simulation.
    """
    yield from _reader_issues(
        ctx, "package-duplicate",
        hint="remove or rename the copy, or pass the intended package's parent first with "
             "--package-path")
