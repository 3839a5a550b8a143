"""libsdformat's structural refusals (S160-S168, S170, S171) and machine-bound file URIs
(S169).

Gazebo reads SDF through libsdformat, which refuses a file whose names or frame
references break SDFormat's rules before any physics is built. reedtool.io.sdf_refusals
finds them on the expanded document, each check mirroring one sdformat function at the
versions it applies to; these rules report them. tests/test_sdformat_parity.py holds
validate to libsdformat itself (through Drake's parser) on a corpus of mutated models:
a file libsdformat refuses is never called clean.
"""

from __future__ import annotations

from typing import Iterator

from reedtool.checks.context import CheckContext
from reedtool.checks.finding import Issue
from reedtool.checks.registry import rule


def _has_gz_system(ctx: CheckContext) -> bool:
    for _block, plugin in ctx.robot.plugins():
        text = f"{plugin.filename or ''} {plugin.name or ''}".lower()
        if any(mark in text for mark in ("gz-sim", "gz::sim", "ignition-gazebo",
                                         "ignition::gazebo")):
            return True
    return False


def _refusals(ctx: CheckContext, kind: str, hint: str) -> Iterator[Issue]:
    for issue in ctx.robot.parse_issues:
        if issue.kind == f"sdf-refused-{kind}":
            yield Issue(issue.message, issue.loc, issue.subject, hint=hint)


@rule("S160", "sdf-name-double-colon", "error",
      "A name holds '::' in an SDF 1.8+ file: libsdformat refuses it.", clause="refused")
def sdf_name_double_colon(ctx: CheckContext) -> Iterator[Issue]:
    """From SDF 1.8 `::` is the scope delimiter (`arm::rotor_0` is the link `rotor_0` of
    the nested model `arm`), so no name may hold it: libsdformat's
    `recursiveSiblingNoDoubleColonInNames` (parser.cc, run by `readDoc` when the declared
    version is 1.8 or later) refuses the file, and Gazebo Sim does not load it. A flattened
    include (`gps0::link`) written into a 1.9 file is the usual cause.

    Every element with a `name=` is checked, in the file and in what it includes, except
    `<plugin>` subtrees and namespaced elements (`gz:...`), which libsdformat does not
    validate. Classic SDF (1.6, 1.7) allows `::` in names and is not reported.

    Applies from: SDF 1.8.

    Severity (error, refused): libsdformat refuses the file.
    """
    yield from _refusals(ctx, "double-colon",
                         "rename it without '::' (e.g. gps0_link), or nest a <model "
                         "name=\"gps0\"> holding the link")


@rule("S161", "sdf-name-collision", "error",
      "Two frames of one SDF model, or two visuals, collisions or sensors of one link, "
      "share a name.",
      clause="refused")
def sdf_name_collision(ctx: CheckContext) -> Iterator[Issue]:
    """Links, joints, frames and nested models of one model are all frames, and a frame
    reference (`<parent>`, `relative_to`, `attached_to`) must name exactly one of them.
    `Model::Load` (Model.cc) refuses a second frame, nested model or world-level model of
    a name already taken ("already exists"), and from SDF 1.7 also a link, joint or frame
    that takes the name of a sibling of another type ("has a name collision"); below 1.7
    it renames the newcomer with a warning (`NAME_link`), which is not reported. Two links
    or two joints of one name are S106 and S107. Within a link, two visuals, collisions,
    sensors or lights of one name are refused too (Link.cc's `loadUniqueRepeated`); a
    visual and a collision may share one.

    Applies from: every version for one type; SDF 1.7 across types.

    Severity (error, refused): libsdformat refuses the model.
    """
    yield from _refusals(ctx, "name-collision", "give each link, joint, frame and nested "
                                                "model of the model its own name")


@rule("S162", "sdf-name-reserved", "error",
      "A model, link, joint, frame or collision is named 'world' or '__NAME__'.",
      clause="refused")
def sdf_name_reserved(ctx: CheckContext) -> Iterator[Issue]:
    """libsdformat reserves `world` (the world frame) and every name of the form `__x__`
    (`__model__`, `__root__`): `isReservedName` (Utils.cc) is checked by the `Load` of
    Model, Link, Joint, Frame, Collision and Light, and the element is refused.

    Applies from: every version.

    Severity (error, refused): libsdformat refuses the element.
    """
    yield from _refusals(ctx, "reserved-name", "choose another name")


@rule("S163", "sdf-canonical-link-missing", "error",
      "A model's canonical_link names no link of the model.", clause="refused")
def sdf_canonical_link_missing(ctx: CheckContext) -> Iterator[Issue]:
    """`<model canonical_link="NAME">` picks the link the model frame is attached to; it
    must name a link of that model (from SDF 1.8 a nested model's link, scoped as
    `child::link`). libsdformat's `checkCanonicalLinkNames` (parser.cc) refuses the model
    otherwise.

    Applies from: every version (libsdformat converts a 1.6 file up and checks it too).

    Severity (error, refused): libsdformat refuses the model.
    """
    yield from _refusals(ctx, "canonical-link", "name a link of the model, or drop the "
                                                "attribute (the first link is canonical)")


@rule("S164", "sdf-frame-attached-to-invalid", "error",
      "A <frame attached_to=> names nothing, itself, or closes a cycle.", clause="refused")
def sdf_frame_attached_to_invalid(ctx: CheckContext) -> Iterator[Issue]:
    """A `<frame>` is attached to a link, joint, frame or nested model of its model, and
    following `attached_to` must end on a link. libsdformat's `checkFrameAttachedToNames`
    refuses a name that is not in the model or is the frame itself;
    `checkFrameAttachedToGraph` (parser.cc, through FrameSemantics.cc) refuses a cycle of
    frames attached to one another.

    Applies from: every version (libsdformat converts a 1.6 file up and checks it too).

    Severity (error, refused): libsdformat refuses the model.
    """
    yield from _refusals(ctx, "attached-to", "attach the frame to a link (or a frame, joint "
                                             "or nested model that ends on one)")


@rule("S165", "sdf-pose-relative-to-invalid", "error",
      "A <pose relative_to=> names no frame, or poses close a cycle.", clause="refused")
def sdf_pose_relative_to_invalid(ctx: CheckContext) -> Iterator[Issue]:
    """A pose's `relative_to` must name a frame of the model (a link, joint, frame, nested
    model or `__model__`), and following the poses must end at the model frame: a link
    posed relative to its own joint, whose pose is relative to that link (a joint's
    default), is a cycle. libsdformat's `checkPoseRelativeToGraph` (parser.cc; the graph
    is built by Model.cc's `buildPoseRelativeToGraph`) refuses both, and `Model::Load`
    refuses a `relative_to` on the file's top model, which has no frame to refer to. In a
    world, models and frames are posed relative to the world's models and frames.

    Applies from: every version (libsdformat converts a 1.6 file up and checks it too).

    Severity (error, refused): libsdformat refuses the model.
    """
    yield from _refusals(ctx, "relative-to", "pose it relative to a frame that does not "
                                             "depend on it")


@rule("S166", "sdf-joint-frames-invalid", "error",
      "A joint's parent and child are the same link, the world as child, or the joint.",
      clause="refused")
def sdf_joint_frames_invalid(ctx: CheckContext) -> Iterator[Issue]:
    """A joint moves its child relative to its parent, so the two must resolve to
    different links; the child cannot be `world`, and neither may be the joint itself.
    libsdformat's `checkJointParentChildNames` (parser.cc; Joint.cc's `Load` for a `world`
    child) refuses the model. A parent or child naming nothing is S105 (here for models
    validate does not read as vehicles, and for a world's joints, SDF 1.10).

    Applies from: every version.

    Severity (error, refused): libsdformat refuses the model.
    """
    yield from _refusals(ctx, "joint-frames", "make the parent and the child two different "
                                              "links of the model")


@rule("S167", "sdf-model-without-link", "error",
      "A model (or nested model) that is not static has no link.", clause="refused")
def sdf_model_without_link(ctx: CheckContext) -> Iterator[Issue]:
    """A model frame is attached to the model's canonical link, so a model that is not
    static needs a link or a nested model. `Model::Load` (Model.cc) refuses it with "A
    model must have at least one link".

    Applies from: every version.

    Severity (error, refused): libsdformat refuses the model.
    """
    yield from _refusals(ctx, "model-without-link", "add a link, or mark the model "
                                                    "<static>true</static>")


@rule("S168", "sdf-version-missing", "error",
      "The <sdf> element declares no version.", clause="refused")
def sdf_version_missing(ctx: CheckContext) -> Iterator[Issue]:
    """libsdformat reads a file by the spec of its `<sdf version=>`; without one
    (`readDoc`, parser.cc) it does not read the file. reedtool reads it as SDF 1.6.

    Applies from: every version.

    Severity (error, refused): libsdformat does not read the file.
    """
    yield from _refusals(ctx, "version", "declare the version the file is written in, e.g. "
                                         "<sdf version=\"1.9\">")


@rule("S170", "sdf-material-script-uri", "error",
      "A material <script> has no <uri>: gz-sim's libsdformat refuses it.", clause="refused")
def sdf_material_script_uri(ctx: CheckContext) -> Iterator[Issue]:
    """Gazebo classic names a material by an OGRE script it finds in its own media paths
    (`<script><name>Gazebo/Black</name></script>`). The libsdformat DOM that gz-sim loads
    (Material.cc's `Load`) requires the script's `<uri>` and refuses the file without it,
    so a Classic model's materials written into a gz model stop it from loading. Write
    `<ambient>`/`<diffuse>` colours (what gz-sim draws) instead, or give the `<uri>`.

    Reported for models made for gz-sim (a gz-sim system among their plugins): a Classic
    model loads where it is meant to, and one without plugins (PX4 Classic's land_pad,
    boxes and shelves) may be for either.

    Applies from: every version (libsdformat 9's DOM already refused it; Gazebo classic
    does not load materials through the DOM).

    Severity (error, refused): gz-sim refuses the model.
    """
    if not _has_gz_system(ctx):
        return
    yield from _refusals(ctx, "script-uri", "replace the <script> with <ambient> and "
                                            "<diffuse> colours, or give its <uri>")


@rule("S171", "sdf-root-several-models", "error",
      "An SDF file holds more than one top-level model, light or actor.", clause="refused")
def sdf_root_several_models(ctx: CheckContext) -> Iterator[Issue]:
    """Outside a `<world>`, an SDF file describes one thing: a model, a light or an actor.
    libsdformat's `Root::Load` (Root.cc) refuses a second one ("Root object can only
    contain one model"); several models belong in a world. reedtool reads the first.

    Applies from: every version.

    Severity (error, refused): libsdformat refuses the file.
    """
    yield from _refusals(ctx, "root-elements", "put the models in a <world>, or in files "
                                               "of their own")


@rule("S169", "file-uri-absolute", "warning",
      "A mesh or include names a file by its absolute path: it works on this machine only.",
      clause="suspicious")
def file_uri_absolute(ctx: CheckContext) -> Iterator[Issue]:
    """`file:///home/me/meshes/arm.stl` (or a plain `/home/me/...`) loads where that file
    exists, on the machine it was written on: a colleague, a CI runner or a container
    lacks it and the mesh or included model is missing. Reference the file inside the
    package or model (`package://PKG/meshes/arm.stl`, `model://NAME/meshes/arm.stl`, or a
    path relative to the model file). References into system directories are S131.

    Severity (warning, suspicious): the model loads here; elsewhere it does not.
    """
    from reedtool.resolve.references import machine_path, uri_problem
    from reedtool.checks.structure import mesh_shapes

    hint = ("copy the file into the package and name it package://PKG/... or "
            "model://NAME/..., or by a path relative to the model file")
    for link, kind, shape, mesh in mesh_shapes(ctx):
        if machine_path(mesh.uri) and not uri_problem(mesh.uri, mesh.path):
            yield Issue(f"link '{link.name}' {kind} mesh '{mesh.uri}' is named by its "
                        "absolute path", shape.loc, link.name, hint=hint)
    for issue in ctx.robot.parse_issues:
        if issue.kind == "absolute-uri" and not uri_problem(issue.subject or ""):
            yield Issue(issue.message, issue.loc, issue.subject, hint=hint)
