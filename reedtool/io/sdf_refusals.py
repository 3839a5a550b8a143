"""What libsdformat refuses in an SDF document's structure, read from the expanded tree.

The SDF reader (reedtool.io.sdf) flattens a model into links and joints; the names and
frame references libsdformat checks before that (sdformat's src/parser.cc and the DOM
`Load`s of Model, Link, Joint and Frame) are judged here on the document after include
expansion, as libsdformat judges it after its own. Each check names the sdformat function
it mirrors and the SDF versions it applies to; every finding is a `ParseIssue` whose kind
starts with `sdf-refused-` (rules S160-S168, S170 and S171 report them, one kind each).

Versions: a file is read at the version its `<sdf version=>` declares. The `::` check
(`recursiveSiblingNoDoubleColonInNames`) runs from 1.8 on, over the file and everything it
includes; a name collision between a link, joint, frame or nested model (`Model::Load`)
is an error from 1.7 on and renamed with a warning below. The frame graphs are built for
every version: libsdformat converts an older file up to the latest spec as XML first, so
a 1.6 file's `relative_to`, `attached_to` and `canonical_link` are read and checked too
(Drake's parser refuses them in a 1.6 file exactly as in a 1.9 one).

Frame references may be scoped (`arm::rotor_0`, a nested model's frame), as they are in
Classic SDF 1.6 files too; a name is looked up as written first, then scope by scope.
`<plugin>` subtrees are never looked at (libsdformat's `shouldValidateElement`), nor are
namespaced elements (`gz:...`): their attributes are not SDF names.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import Callable

from lxml import etree

from reedtool.model import ParseIssue, SourceLoc

MODEL_FRAME = "__model__"
_VERSION = re.compile(r"^\s*(\d+)\.(\d+)")
# Elements that are nodes of a model's frame graphs (sdformat FrameSemantics.cc).
_FRAME_ELEMENTS = ("link", "joint", "frame", "model")
# Elements whose DOM Load refuses a reserved name (sdformat Utils.cc isReservedName).
_RESERVED_CHECKED = ("model", "link", "joint", "frame", "collision", "light")


def parse_version(text: str | None) -> tuple[int, int] | None:
    match = _VERSION.match(text or "")
    return (int(match.group(1)), int(match.group(2))) if match else None


def is_reserved_name(name: str) -> bool:
    """sdformat's isReservedName: `world`, or `__x__` (four characters or more)."""
    return name == "world" or (len(name) >= 4 and name.startswith("__") and name.endswith("__"))


def _validated(el) -> bool:
    """sdformat's shouldValidateElement: not a <plugin>, not a namespaced element."""
    return isinstance(el.tag, str) and el.tag != "plugin" and ":" not in el.tag \
        and not el.tag.startswith("{")


@dataclass
class _Context:
    loc: Callable[[etree._Element], SourceLoc]
    version_of: Callable[[etree._Element], tuple[int, int]]
    top_version: tuple[int, int]
    issues: list
    read_models: frozenset = frozenset()   # models read into robots: S105 is theirs

    def add(self, kind: str, message: str, el: etree._Element, subject: str | None) -> None:
        self.issues.append(ParseIssue(f"sdf-refused-{kind}", message, self.loc(el), subject))


def document_refusals(root: etree._Element, *, loc, version_of,
                      read_models=()) -> list[ParseIssue]:
    """Every structural refusal of the expanded `<sdf>` document `root`.

    `loc(el)`: the source location of an element; `version_of(el)`: the SDF version
    (major, minor) declared by the file the element was read from; `read_models`: the
    top-level models read into robots, whose joints naming no link S105 reports (in the
    others, a static ground plane or a model beside the vehicle, it is reported here).
    """
    issues: list[ParseIssue] = []
    declared = root.get("version")
    top_version = parse_version(declared)
    ctx = _Context(loc, version_of, top_version or (1, 6), issues, frozenset(read_models))
    if top_version is None:
        # parser.cc readDoc: "<sdf> element has no version" and the file is not read.
        ctx.add("version", "<sdf> has no version=: libsdformat does not read the file"
                if declared is None else
                f"<sdf version=\"{declared}\"> is not a version: libsdformat does not read "
                "the file", root, None)
    _double_colons(root, ctx)
    _material_scripts(root, ctx)
    for world in root.iterfind("world"):
        _sibling_names(world, ctx, "world")
        _world_frames(world, ctx)
        for model in world.iterfind("model"):
            _model(model, ctx)
    _root_elements(root, ctx)
    for model in root.iterfind("model"):
        _model(model, ctx)
        _top_model_pose(model, ctx)
    return issues


def _top_model_pose(model: etree._Element, ctx: _Context) -> None:
    """Model.cc Load, every version: the file's top model has no frame around it to be
    posed relative to ("Attribute //pose[@relative_to] of top level model must be left
    empty")."""
    pose = model.find("pose")
    if pose is not None and pose.get("relative_to"):
        ctx.add("relative-to", f"model '{model.get('name')}' is the file's top model: its "
                f"<pose relative_to=\"{pose.get('relative_to')}\"> must be left out", pose,
                model.get("name"))


def _root_elements(root: etree._Element, ctx: _Context) -> None:
    """Root.cc Load, every version: an `<sdf>` holds one model, light or actor (or
    worlds): "Root object can only contain one model"."""
    elements = [el for el in root if isinstance(el.tag, str)
                and el.tag in ("model", "light", "actor")]
    for el in elements[1:]:
        ctx.add("root-elements", f"<{el.tag} name=\"{el.get('name')}\"> is a second "
                f"top-level element (the first: <{elements[0].tag} name=\""
                f"{elements[0].get('name')}\">): libsdformat reads one model, light or "
                "actor per file", el, el.get("name"))


# ------------------------------------------------------------------ names

def _double_colons(root: etree._Element, ctx: _Context) -> None:
    """parser.cc recursiveSiblingNoDoubleColonInNames, from SDF 1.8: a name holding the
    scope delimiter `::`. Checked for the top file's version over the whole expanded tree,
    and again for each included file at its own version (libsdformat reads it so too)."""
    def walk(el):
        if not _validated(el):
            return
        name = el.get("name")
        if name and "::" in name and max(ctx.top_version, ctx.version_of(el)) >= (1, 8):
            ctx.add("double-colon", f"<{el.tag} name=\"{name}\">: '::' is the scope "
                    "delimiter; libsdformat refuses it in a name from SDF 1.8 on", el, name)
        for child in el:
            walk(child)

    walk(root)


def _material_scripts(root: etree._Element, ctx: _Context) -> None:
    """Material.cc Load (the DOM gz-sim loads through), every version: a material
    `<script>` without a `<uri>` ("A <script> element is missing a child <uri> element").
    Gazebo classic reads the script by name from its own media paths and does not care."""
    for script in root.iter("script"):
        if script.getparent() is None or script.getparent().tag != "material" \
                or _inside_plugin(script):
            continue
        if not (script.findtext("uri") or "").strip():
            name = (script.findtext("name") or "").strip()
            ctx.add("script-uri", f"material <script> '{name}' has no <uri>: the libsdformat "
                    "DOM that gz-sim loads refuses it", script, name or None)


def _inside_plugin(el: etree._Element) -> bool:
    node = el.getparent()
    while node is not None:
        if not _validated(node):
            return True
        node = node.getparent()
    return False


def _sibling_names(parent: etree._Element, ctx: _Context, what: str,
                   unread: bool = False) -> None:
    """World.cc/Model.cc Load: two frame-graph siblings of one name. Same-type duplicates
    are errors in every version ("already exists"); a link, joint, frame or model sharing
    a name with a sibling of another type is an error from SDF 1.7 on (below, libsdformat
    renames it with a warning). Links and joints of one name are S106/S107's in the models
    validate reads."""
    seen: dict[str, etree._Element] = {}
    types = _FRAME_ELEMENTS if what == "model" else ("model", "frame", "light")
    for el in parent:
        if not isinstance(el.tag, str) or el.tag not in types:
            continue
        name = el.get("name") or ""
        first = seen.get(name)
        if first is None:
            seen[name] = el
            continue
        if first.tag == el.tag and el.tag in ("link", "joint") and what == "model" \
                and not unread:
            continue   # S106 / S107
        if first.tag != el.tag and (ctx.version_of(el) < (1, 7) or "light" in (first.tag,
                                                                               el.tag)):
            continue   # renamed below 1.7; a light is no frame (World.cc only warns)
        ctx.add("name-collision", f"<{el.tag} name=\"{name}\"> in {what} "
                f"'{parent.get('name')}' takes the name of a <{first.tag}> (line "
                f"{ctx.loc(first).line}): libsdformat refuses two frames of one name",
                el, name)


# Element -> the children libsdformat loads with loadUniqueRepeated (Link.cc, Joint.cc).
_UNIQUE_CHILDREN = {
    "link": ("visual", "collision", "sensor", "light", "particle_emitter", "projector"),
    "joint": ("sensor",),
}


def _same_type_names(parent: etree._Element, ctx: _Context) -> None:
    """Link.cc/Joint.cc Load (loadUniqueRepeated), every version: two visuals, collisions,
    sensors, lights, ... of one link (a joint's sensors) with one name ("already exists").
    A visual and a collision may share a name."""
    for tag in _UNIQUE_CHILDREN[parent.tag]:
        seen: dict[str, etree._Element] = {}
        for el in parent.iterfind(tag):
            name = el.get("name") or ""
            if name in seen:
                ctx.add("name-collision", f"<{tag} name=\"{name}\"> of {parent.tag} "
                        f"'{parent.get('name')}' is declared again (first at line "
                        f"{ctx.loc(seen[name]).line}): libsdformat refuses it", el, name)
            else:
                seen[name] = el


def _reserved_names(model: etree._Element, ctx: _Context) -> None:
    """Model.cc/Link.cc/Joint.cc/Frame.cc/Collision.cc Load, every version: a name that
    isReservedName refuses (`world`, `__x__`), among the model's own elements (a nested
    model's are checked with it)."""
    for el in model.iter(*_RESERVED_CHECKED):
        if el is model or _inside_plugin_or_nested(el, model):
            continue
        name = el.get("name")
        if name is not None and is_reserved_name(name):
            ctx.add("reserved-name", f"<{el.tag} name=\"{name}\">: libsdformat reserves "
                    "'world' and names of the form __x__", el, name)


def _inside_plugin_or_nested(el: etree._Element, model: etree._Element) -> bool:
    node = el.getparent()
    while node is not None and node is not model:
        if node.tag in ("model", "plugin") or not _validated(node):
            return True
        node = node.getparent()
    return False


# ------------------------------------------------------------------ frame graphs

def _world_frames(world: etree._Element, ctx: _Context) -> None:
    """parser.cc checkFrameAttachedToNames/Graph and checkPoseRelativeToGraph for a world,
    every version: a world <frame attached_to=> or a model's or frame's <pose relative_to=>
    naming no model or frame of the world (`model::frame` reaches into a model), naming
    itself, or closing a cycle."""
    scopes = {el.get("name"): _Scope(el, ctx) for el in world.iterfind("model")}
    frames = {el.get("name"): el for el in world.iterfind("frame")}

    def known(ref: str) -> bool:
        if ref == "world" or ref in scopes or ref in frames:
            return True
        head, sep, rest = ref.partition("::")
        return bool(sep) and head in scopes and scopes[head].find(rest) is not None

    edges: dict[str, tuple[str, etree._Element]] = {}
    for el in [*world.iterfind("model"), *world.iterfind("frame")]:
        name = el.get("name") or ""
        attached = el.get("attached_to") if el.tag == "frame" else None
        if attached:
            if attached == name:
                ctx.add("attached-to", f"world frame '{name}' is attached to itself", el, name)
            elif not known(attached):
                ctx.add("attached-to", f"world frame '{name}' attached_to=\"{attached}\" names "
                        "no model or frame of the world", el, name)
            else:
                edges[name] = (attached, el)
        pose = el.find("pose")
        relative_to = pose.get("relative_to") if pose is not None else None
        if relative_to:
            if relative_to == name:
                ctx.add("relative-to", f"<{el.tag} name=\"{name}\"> is posed relative_to "
                        "itself", pose, name)
            elif not known(relative_to):
                ctx.add("relative-to", f"<{el.tag} name=\"{name}\">: <pose relative_to="
                        f"\"{relative_to}\"> names no model or frame of the world", pose, name)
            else:
                edges[name] = (relative_to, pose)
    _cycles(edges, ctx, "attached_to/relative_to")

    def link_of(ref: str, seen: tuple = ()):
        """The link (element) or "world" a world-level reference is attached to."""
        if ref in ("", "world") or ref in seen:
            return "world" if ref in ("", "world") else None
        if ref in frames:
            return link_of(frames[ref].get("attached_to") or "world", seen + (ref,))
        head, sep, rest = ref.partition("::")
        scope = scopes.get(ref) or (scopes.get(head) if sep else None)
        if scope is None:
            return None
        return _link_of(scope, rest if sep and ref not in scopes else MODEL_FRAME)[0]

    # World joints (SDF 1.10): World.cc Load and checkScopedJointParentChildNames.
    for el in world.iterfind("joint"):
        name = el.get("name") or ""
        parent = (el.findtext("parent") or "").strip()
        child = (el.findtext("child") or "").strip()
        problems = []
        for role, ref in (("parent", parent), ("child", child)):
            if ref == name:
                problems.append(f"its {role} is the joint itself")
            elif not known(ref):
                problems.append(f"its {role} '{ref}' names no model or frame of the world")
        if child == "world":
            problems.append("its child is 'world'")
        elif not problems:
            parent_link, child_link = link_of(parent), link_of(child)
            if child_link == "world":
                problems.append(f"its child '{child}' is attached to the world")
            elif parent_link is not None and parent_link is child_link:
                problems.append(f"its parent '{parent}' and child '{child}' are on one link")
        for problem in problems:
            ctx.add("joint-frames", f"world joint '{name}': {problem}", el, name)


class _Scope:
    """One <model>'s frame-graph nodes, with scoped lookup into nested models."""

    def __init__(self, model: etree._Element, ctx: _Context):
        self.model = model
        self.ctx = ctx
        self.elements: dict[str, etree._Element] = {}
        # Below SDF 1.7 libsdformat renames a link, joint or frame that takes a sibling's
        # name (`NAME_joint`, Model.cc): references to NAME mean the first one.
        self.own_name: dict[etree._Element, str] = {}
        for el in model:
            if isinstance(el.tag, str) and el.tag in _FRAME_ELEMENTS and el.get("name"):
                name = el.get("name")
                first = self.elements.setdefault(name, el)
                renamed = first is not el and first.tag != el.tag \
                    and ctx.version_of(el) < (1, 7)
                self.own_name[el] = f"{name}_{el.tag}" if renamed else name
        self.nested = {name: _Scope(el, ctx) for name, el in self.elements.items()
                       if el.tag == "model"}

    def find(self, name: str) -> tuple[_Scope, etree._Element | None] | None:
        """(scope, element) a reference names; element None for the scope's __model__."""
        if name == MODEL_FRAME:
            return self, None
        if name in self.elements:
            return self, self.elements[name]
        head, sep, rest = name.partition("::")
        if sep and head in self.nested:
            return self.nested[head].find(rest)
        return None

    def links(self) -> list[etree._Element]:
        return [el for el in self.model if isinstance(el.tag, str) and el.tag == "link"]

    def canonical(self) -> str | None:
        """The link the model frame is attached to, as a reference in this scope."""
        named = self.model.get("canonical_link")
        if named:
            return named
        links = self.links()
        if links:
            return links[0].get("name")
        for name, nested in self.nested.items():
            inner = nested.canonical()
            if inner:
                return f"{name}::{inner}"
        return None


def _model(model: etree._Element, ctx: _Context) -> None:
    name = model.get("name") or ""
    if is_reserved_name(name):
        ctx.add("reserved-name", f"<model name=\"{name}\">: libsdformat reserves 'world' and "
                "names of the form __x__", model, name)
    _check_scope(_Scope(model, ctx), ctx, unread=model not in ctx.read_models)


def _check_scope(scope: _Scope, ctx: _Context, unread: bool = False) -> None:
    before = len(ctx.issues)
    _sibling_names(scope.model, ctx, "model", unread)
    _reserved_names(scope.model, ctx)
    for el in scope.model:
        if isinstance(el.tag, str) and el.tag in _UNIQUE_CHILDREN:
            _same_type_names(el, ctx)
    if any(issue.kind == "sdf-refused-name-collision" for issue in ctx.issues[before:]):
        # parser.cc checks names before it builds a frame graph and stops there: a name
        # two frames share would otherwise read as a cycle or a joint to itself.
        return
    _without_link(scope, ctx)
    _canonical_link(scope, ctx)
    _attached_to(scope, ctx)
    _joint_frames(scope, ctx, unread)
    _relative_to(scope, ctx)
    for nested in scope.nested.values():
        _check_scope(nested, ctx, unread)


def _is_true(text: str | None) -> bool:
    return (text or "").strip().lower() in ("true", "1")


def _without_link(scope: _Scope, ctx: _Context) -> None:
    """Model.cc Load, every version: a model that is not static and has no link and no
    nested model ("A model must have at least one link")."""
    model = scope.model
    if _is_true(model.findtext("static")) or scope.links() or scope.nested:
        return
    ctx.add("model-without-link", f"model '{model.get('name')}' has no <link> and no nested "
            "model: libsdformat refuses a model that is not static without one", model,
            model.get("name"))


def _resolves_to_link(scope: _Scope, ref: str) -> bool:
    found = scope.find(ref)
    return found is not None and found[1] is not None and found[1].tag == "link"


def _canonical_link(scope: _Scope, ctx: _Context) -> None:
    """parser.cc checkCanonicalLinkNames, every version: canonical_link= naming no link of
    the model (a nested model's link written scoped, `child::link`, from 1.8)."""
    model = scope.model
    named = model.get("canonical_link")
    if named is not None and not _resolves_to_link(scope, named):
        ctx.add("canonical-link", f"model '{model.get('name')}': canonical_link=\"{named}\" "
                "names no link of the model", model, model.get("name"))


def _link_of(scope: _Scope, ref: str, seen: tuple = ()):
    """(link element or "world", None), or (None, why not): follow attached_to edges from
    `ref` to a link (sdformat's FrameAttachedToGraph): a frame to its attached_to (default
    the model frame), a joint to its child, a model frame to its canonical link."""
    if ref == "world":
        return "world", None
    found = scope.find(ref)
    if found is None:
        return None, f"'{ref}' names no link, joint, frame or nested model"
    owner, el = found
    key = (id(owner), id(el))
    if key in seen:
        return None, "cycle"
    seen = seen + (key,)
    if el is None or el.tag == "model":
        inner = owner if el is None else owner.nested[el.get("name")]
        canonical = inner.canonical()
        if canonical is None or not _resolves_to_link(inner, canonical):
            return None, None   # no link, or canonical_link naming nothing: reported alone
        return _link_of(inner, canonical, seen)
    if el.tag == "link":
        return el, None
    if el.tag == "joint":
        return _link_of(owner, (el.findtext("child") or "").strip(), seen)
    return _link_of(owner, el.get("attached_to") or MODEL_FRAME, seen)


def _attached_to(scope: _Scope, ctx: _Context) -> None:
    """parser.cc checkFrameAttachedToNames and checkFrameAttachedToGraph, every version:
    a <frame attached_to=> that names nothing, itself, or starts a cycle."""
    for el in scope.model.iterfind("frame"):
        name = scope.own_name.get(el, el.get("name") or "")
        attached = el.get("attached_to")
        if not attached or attached == MODEL_FRAME:
            continue
        if attached == name:
            problem = "is attached to itself"
        else:
            link, problem = _link_of(scope, attached, ((id(scope), id(el)),))
            if problem == "cycle":
                problem = "closes a cycle of attached_to frames"
            elif link == "world":
                problem = "a model's frame cannot be attached to the world"
        if problem:
            ctx.add("attached-to", f"frame '{name}' attached_to=\"{attached}\": {problem}",
                    el, name)


def _joint_frames(scope: _Scope, ctx: _Context, unread: bool = False) -> None:
    """parser.cc checkScopedJointParentChildNames and Joint.cc Load, every version: a
    joint's child that is `world` or the joint itself, a parent that is the joint itself,
    a parent or child naming no frame (in a model validate does not read; S105 reports
    it in the others), and a parent and child resolving to one link."""
    for el in scope.model.iterfind("joint"):
        name = scope.own_name.get(el, el.get("name") or "")
        parent = (el.findtext("parent") or "").strip()
        child = (el.findtext("child") or "").strip()
        if not parent or not child:
            continue   # the reader reports a missing <parent>/<child>
        problems = []
        if child == "world":
            problems.append("its child is 'world'")
        for role, ref in (("parent", parent), ("child", child)):
            if ref == name:
                problems.append(f"its {role} is the joint itself")
            elif ref == "__root__":
                problems.append(f"its {role} '__root__' is not a frame")
            elif unread and ref != "world" and ref.rpartition("::")[2] != MODEL_FRAME \
                    and scope.find(ref) is None:
                problems.append(f"its {role} '{ref}' names no link, joint, frame or model")
        if not problems and child != name and parent != name:
            parent_link, _ = _link_of(scope, parent)
            child_link, _ = _link_of(scope, child)
            if parent_link is not None and parent_link is child_link:
                on = parent_link if parent_link == "world" else parent_link.get("name")
                problems.append(f"its parent '{parent}' and child '{child}' are both on "
                                f"'{on}'")
            elif child_link == "world":
                problems.append(f"its child '{child}' is attached to the world")
        for problem in problems:
            ctx.add("joint-frames", f"joint '{name}': {problem}", el, name)


def _relative_to(scope: _Scope, ctx: _Context) -> None:
    """parser.cc checkPoseRelativeToGraph (Model.cc buildPoseRelativeToGraph), every
    version: a <pose relative_to=> naming no frame, and a cycle of pose frames (defaults
    included: a joint's pose is relative to its child, a frame's to its attached_to)."""
    edges: dict[str, tuple[str, etree._Element]] = {}
    for el in scope.model:
        if not isinstance(el.tag, str) or el.tag not in _FRAME_ELEMENTS:
            continue
        name = scope.own_name.get(el, el.get("name") or "")
        pose = el.find("pose")
        explicit = pose.get("relative_to") if pose is not None else None
        if explicit:
            if explicit == name:
                ctx.add("relative-to", f"<{el.tag} name=\"{name}\"> is posed relative_to "
                        "itself", pose, name)
                continue
            if explicit != MODEL_FRAME and scope.find(explicit) is None:
                ctx.add("relative-to", f"<{el.tag} name=\"{name}\">: <pose relative_to="
                        f"\"{explicit}\"> names no link, joint, frame or nested model",
                        pose, name)
                continue
            edges[name] = (explicit, pose)
        elif el.tag == "joint":
            edges[name] = ((el.findtext("child") or "").strip(), el)
        elif el.tag == "frame" and el.get("attached_to"):
            edges[name] = (el.get("attached_to"), el)
    _cycles(edges, ctx, "relative_to")


def _cycles(edges: dict[str, tuple[str, etree._Element]], ctx: _Context, what: str) -> None:
    """Each cycle of `edges` (name -> (the name it depends on, element)) once."""
    reported: set[str] = set()
    for start in edges:
        path = [start]
        node = start
        while node in edges:
            node = edges[node][0]
            if node in path:
                cycle = path[path.index(node):]
                if not reported.intersection(cycle):
                    reported.update(cycle)
                    _target, el = edges[cycle[0]]
                    ctx.add("relative-to", f"poses {what} one another in a cycle: "
                            + " -> ".join([*cycle, node]), el, cycle[0])
                break
            path.append(node)
