"""SDF text -> the same Robot model urdf_io builds, keeping the source line of every element.

Supported subset (SDF 1.6 to 1.11, the shape of Gazebo's own multirotor models):

* `<include>`s are expanded first (reedtool.io.sdf_include): `model://NAME`, relative and
  absolute URIs, model.config, `<name>`/`<pose>`/`<static>` overrides and SDF 1.9
  `merge="true"`; every element keeps the file and line it was read from. Text that
  TinyXML2 accepts and strict XML does not is read (reedtool.io.tolerant_xml), with an
  "xml-tolerated" parse issue.
* The model read is the `<model>` directly under `<sdf>`, else a model of a `<world>`:
  the one named by `model_name` (`--model`), else the only non-static one with a
  motor-model plugin, else the only non-static one; several are refused, naming them
  (`load_sdf_models` returns them all).
  Nested `<model>`s are flattened with scoped names (`arm::rotor_0`); a plugin of a nested
  model names that model's joints and links, so its jointName/linkName are scoped too. A
  joint's `<parent>`/`<child>` naming a nested model is that model's canonical link (its
  `canonical_link=`, else its first link); naming a `<frame>`, the link it is attached to.
* Frames (SDF 1.7 semantics, which 1.6 files also follow when they use no `frame=`):
  a link's `<pose>` is relative to the model frame; a joint's `<pose>` is relative to its
  CHILD link; a `<frame>`'s pose is relative to its `attached_to` (default the model);
  `relative_to=` (or 1.6's `frame=`) overrides any of them and may name a link, joint,
  frame, nested model or `__model__`. Poses may be `degrees="true"` or
  `rotation_format="quat_xyzw"` (SDF 1.9+). The top model's own `<pose>` is its spawn pose
  and is ignored: the model frame is the base frame.
* URDF has no separate joint frame: the joint frame is the child link frame. So here
  `T_parent_joint` is the child link's pose in the parent link, and the axis is rotated
  from the frame it is expressed in (`expressed_in=`, 1.6's `<use_parent_model_frame>`,
  default the SDF joint frame) into the child link frame. A joint posed away from its
  child's origin keeps that pose as `Joint.T_child_jointframe` (the axis line passes
  there; `migrate` writes it back); zero-configuration poses, which everything else in
  reedtool uses, do not depend on it.
* Joint types: `revolute` with no `<limit>` or with limits at +-1e16 (sdformat's
  "unbounded", which is how sdformat writes a URDF continuous joint) is `continuous`;
  revolute, prismatic, continuous and fixed map one to one; ball, universal, revolute2,
  screw and gearbox keep their SDF type, which `validate` reports (S110). A parent named
  `world` is kept as written (a model welded to the world).
* A link without `<inertial>`, or an `<inertial>` without `<mass>`/`<inertia>`, gets
  sdformat's defaults (1 kg, 1 kg*m^2 on the diagonal), as Gazebo simulates it, and a
  parse issue. `<inertial auto="true">` (SDF 1.11) is not computed: a parse issue.
* Geometry: box, cylinder, sphere and mesh (uri, scale). `model://NAME/...` resolves
  as includes do (reedtool.resolve.resources: the naming file's directory and its parent,
  --package-path, GZ_SIM_RESOURCE_PATH, IGN_GAZEBO_RESOURCE_PATH, SDF_PATH,
  GAZEBO_MODEL_PATH); `package://` through the package resolver; Fuel
  (http/https) URIs are not fetched. Planes, capsules, ellipsoids, heightmaps and
  polylines are kept as "no geometry".
* `<plugin>` elements under a `<model>` (or a nested one) become one GazeboBlock(reference=None), so
  rotor discovery reads gz-sim MulticopterMotorModel systems exactly as it reads URDF
  `<gazebo>` plugins. The `<sensor>`s of a link become a GazeboBlock(reference=LINK)
  holding them (plugins inside a sensor stay inside it), as URDF's `<gazebo
  reference="LINK"><sensor>` is read.

`Robot.urdf_xml` is set to an equivalent URDF (links, inertials, primitive geometry,
joints) so URDF-only consumers such as the Pinocchio cross-check see the same model.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from lxml import etree

from reedtool.errors import ReedtoolError
from reedtool.io.fileio import magnitude_problem
from reedtool.frames import make_T, rpy_to_matrix
from reedtool.resolve.references import machine_path
from reedtool.resolve.resources import REMOTE_NOT_CHECKED, is_remote_uri, resolve_model_file_uri
from reedtool.io.sdf_include import SourceFile, SourceMap, expand_includes
from reedtool.io.sdf_refusals import document_refusals, parse_version
from reedtool.io.tolerant_xml import (
    late_declaration_issues,
    local_tag,
    parse_tolerant,
    tolerated_message,
)
from reedtool.io.urdf_write import equivalent_urdf
from reedtool.model import (
    INERTIA_KEYS,
    Box,
    Collision,
    Cylinder,
    GazeboBlock,
    Inertial,
    Joint,
    JointLimit,
    Link,
    Mesh,
    ParseIssue,
    Plugin,
    Robot,
    SourceLoc,
    Sphere,
    Visual,
    XmlNode,
    inertia_tensor,
    motor_plugin_family,
)

MODEL_FRAME = "__model__"
# Plugin parameters that name a joint or link of the plugin's own model: a plugin of a
# nested (not merged) model reads them in that model's scope.
_SCOPED_PLUGIN_PARAMS = {"jointName", "linkName", "joint_name", "link_name", "bodyName",
                         "body_name"}
_SDF_VERSION = re.compile(r"<sdf\b[^>]*\bversion\s*=\s*[\"']([\d.]+)[\"']")
SDF_DEFAULT_MASS_KG = 1.0


def load_sdf_file(path: Path | str, *, resolver=None, model_name: str | None = None) -> Robot:
    """Read an SDF file (a model.sdf, or a world) into the Robot of one model."""
    from reedtool.io.fileio import read_xml_file

    path = Path(path)
    text, _encoding = read_xml_file(path, what="SDF file")
    return parse_sdf(text, path, resolver=resolver, model_name=model_name)


def load_sdf_models(path: Path | str, *, resolver=None) -> list[Robot]:
    """Every model `validate` checks in an SDF file: the model of a model file; in a world,
    each model with motor plugins, else each non-static model."""
    from reedtool.io.fileio import read_xml_file

    path = Path(path)
    text, _encoding = read_xml_file(path, what="SDF file")
    root, sources, resolver = _document(text, path, resolver)
    models = _candidate_models(root, path, sources)
    with_motors = [m for m in models if _has_motor_plugin(m)]
    read = with_motors or models
    robots = [_read_model(m, path, resolver, sources) for m in read]
    # What libsdformat refuses refuses the whole file: said once, with the first model.
    robots[0].parse_issues += _refusals(root, sources, read)
    return robots


def parse_sdf(xml_text: str, file: Path | str, *, resolver=None,
              model_name: str | None = None) -> Robot:
    file = Path(file)
    root, sources, resolver = _document(xml_text, file, resolver)
    model = _pick_model(root, file, sources, model_name)
    robot = _read_model(model, file, resolver, sources)
    robot.parse_issues += _refusals(root, sources, [model])
    return robot


def _refusals(root: etree._Element, sources: SourceMap, read) -> list[ParseIssue]:
    """libsdformat's structural refusals of the expanded document (reedtool.io.sdf_refusals);
    `read`: the models read into robots, whose own rules (S105) report a joint's missing
    parent or child."""
    versions: dict[Path, tuple[int, int]] = {}

    def version_of(el: etree._Element) -> tuple[int, int]:
        source = sources.file_of(el)
        if source.path not in versions:
            match = _SDF_VERSION.search("\n".join(source.lines[:200]))
            versions[source.path] = parse_version(match.group(1) if match else None) or (1, 6)
        return versions[source.path]

    def loc(el: etree._Element) -> SourceLoc:
        return SourceLoc(str(sources.file_of(el).path), sources.line_of(el))

    issues = document_refusals(root, loc=loc, version_of=version_of, read_models=read)
    for uri, file, line in sources.include_uris:
        if machine_path(uri):
            issues.append(ParseIssue("absolute-uri", f"<include> <uri>{uri}</uri> names a "
                                     "file by its absolute path", SourceLoc(str(file), line),
                                     uri))
    return issues


def _document(xml_text: str, file: Path, resolver):
    """(root with every <include> expanded, its SourceMap, the resolver)."""
    root, tolerated = parse_tolerant(xml_text, file)
    if root.tag != "sdf":
        raise ReedtoolError(f"not an SDF file: the root element is <{root.tag}>, expected <sdf>",
                            file=file, line=root.sourceline)
    if resolver is None:
        from reedtool.resolve.packages import PackageResolver
        resolver = PackageResolver(model_path=file)
    top = SourceFile(file, xml_text.splitlines())
    sources = SourceMap(top)
    sources.tolerated += [(top, t) for t in tolerated]
    expand_includes(root, top, sources, getattr(resolver, "package_paths", ()))
    return root, sources, resolver


def _read_model(model: etree._Element, file: Path, resolver, sources: SourceMap) -> Robot:
    robot = _ModelReader(file, resolver, sources).read(model)
    # Includes Gazebo fetches from the web (Fuel): left out here, and said so (S190).
    for include in sources.remote:
        if is_remote_uri(include.uri):
            robot.parse_issues.append(ParseIssue(
                "remote-uri", f"<include> '{include.uri}' {REMOTE_NOT_CHECKED}",
                SourceLoc(str(include.file), include.line), include.name))
    robot.urdf_xml = equivalent_urdf(robot)
    return robot


def _children(el: etree._Element, tag: str) -> list[etree._Element]:
    return [c for c in el if c.tag == tag]


def _is_static(model: etree._Element) -> bool:
    """A static model, or one whose every body is in static nested models (a world's
    `<model><include>` of a static warehouse floor): Gazebo moves none of it."""
    static = model.find("static")
    if static is not None and (static.text or "").strip().lower() in ("true", "1"):
        return True
    nested = _children(model, "model")
    return not _children(model, "link") and bool(nested) and all(map(_is_static, nested))


def _has_motor_plugin(model: etree._Element) -> bool:
    """A motor-model plugin as rotor discovery reads it (model.MOTOR_PLUGINS)."""
    return any(motor_plugin_family(p.get("filename"), p.get("name")) for p in model.iter("plugin"))


def _candidate_models(root: etree._Element, file: Path,
                      sources: SourceMap) -> list[etree._Element]:
    """The models a file holds: its top <model>, else the non-static models of its world."""
    models = _children(root, "model")
    if models:
        return models[:1]
    candidates = [m for world in _children(root, "world") for m in _children(world, "model")
                  if not _is_static(m)]
    if candidates:
        return candidates
    if sources.unresolved:
        first = sources.unresolved[0]
        raise ReedtoolError(f"the world's <include> could not be read: {first.reason}",
                            file=first.file, line=first.line,
                            hint=("download it (gz fuel download -u URI) and pass "
                                  "--package-path DIR to check it" if is_remote_uri(first.uri)
                                  else "set GZ_SIM_RESOURCE_PATH or pass --package-path DIR"))
    if _children(root, "world"):
        raise ReedtoolError("no <model> found in the world but static ones: a launch file "
                            "spawns the robot into such a world", file=file, line=root.sourceline,
                            hint="name the robot's model file, or its launch file with "
                                 "--launch FILE")
    raise ReedtoolError("no <model> found in the SDF file", file=file, line=root.sourceline,
                        hint="pass an SDF file that contains a <model>")


def _pick_model(root: etree._Element, file: Path, sources: SourceMap,
                model_name: str | None = None) -> etree._Element:
    if model_name is not None:
        everything = _children(root, "model") + [
            m for world in _children(root, "world") for m in _children(world, "model")]
        for model in everything:
            if model.get("name") == model_name:
                return model
        for include in sources.unresolved:
            if include.name == model_name or include.uri.rstrip("/").endswith("/" + model_name):
                raise ReedtoolError(f"model '{model_name}' could not be read: {include.reason}",
                                    file=include.file, line=include.line)
        names = ", ".join(repr(m.get("name")) for m in everything) or "none"
        raise ReedtoolError(f"--model {model_name}: no such model in the file (models: {names})",
                            file=file, hint="pass one of the model names listed")
    candidates = _candidate_models(root, file, sources)
    with_motors = [m for m in candidates if _has_motor_plugin(m)]
    chosen = with_motors or candidates
    if len(chosen) > 1:
        # Taking the first would silently compute on a vehicle the user may not have meant.
        names = ", ".join(repr(m.get("name")) for m in chosen)
        raise ReedtoolError(f"the world holds {len(chosen)} models ({names}); this command "
                            "reads one model at a time", file=file,
                            hint="name one with --model NAME (`reedtool validate` checks "
                                 "them all in one run)")
    return chosen[0]


# ------------------------------------------------------------------ frames

@dataclass
class _FrameEntry:
    relative_to: str          # scoped name of the frame the pose is expressed in
    T_rel_frame: np.ndarray   # pose of this frame in `relative_to`
    el: etree._Element
    # SDF 1.8 placement_frame (scoped): the pose places this frame, not the model frame.
    placement: str | None = None


class _ModelReader:
    def __init__(self, file: Path, resolver, sources: SourceMap):
        self.file = file
        self.sources = sources
        self.resolver = resolver
        self.issues: list[ParseIssue] = []
        self._versions: dict[Path, str] = {}
        self.frames: dict[str, _FrameEntry] = {}
        self._resolved: dict[str, np.ndarray] = {MODEL_FRAME: np.eye(4)}
        self.link_els: list[tuple[str, str, etree._Element]] = []   # (scoped name, scope, el)
        self.joint_els: list[tuple[str, str, etree._Element]] = []
        self.plugin_els: list[tuple[str, etree._Element]] = []      # (scope, el)
        self.model_els: dict[str, etree._Element] = {}              # scope "a::" -> <model>
        self.attached_to: dict[str, str] = {}                       # frame -> what it is on
        self.canonical: str | None = None
        self.sensor_blocks: list[GazeboBlock] = []                   # <sensor>s per link
        self.model_name: str = ""

    # ------------------------------------------------------------ helpers
    def loc(self, el: etree._Element) -> SourceLoc:
        return SourceLoc(str(self.sources.file_of(el).path), self.sources.line_of(el))

    def file_of(self, el: etree._Element) -> Path:
        return self.sources.file_of(el).path

    def _version_text(self, el: etree._Element) -> str:
        """The SDF version declared by the file the element was read from."""
        source = self.sources.file_of(el)
        cached = self._versions.get(source.path)
        if cached is None:
            match = _SDF_VERSION.search("\n".join(source.lines[:200]))
            cached = self._versions[source.path] = match.group(1) if match else "1.6"
        return cached

    def _version(self, el: etree._Element) -> tuple[int, ...]:
        try:
            return tuple(int(part) for part in self._version_text(el).split("."))
        except ValueError:
            return (1, 6)

    def _issue(self, kind: str, message: str, el: etree._Element, subject: str | None) -> None:
        self.issues.append(ParseIssue(kind, message, self.loc(el), subject))

    def _numbers(self, el: etree._Element | None, counts: tuple[int, ...], default,
                 subject: str | None, unbounded_ok: bool = False) -> np.ndarray:
        if el is None or el.text is None or not el.text.strip():
            return np.array(default, dtype=float)
        raw = " ".join(el.text.split())
        try:
            values = [float(v) for v in raw.split()]
        except ValueError:
            self._issue("bad-number", f"<{el.tag}>{raw}</{el.tag}> is not a list of numbers",
                        el, subject)
            return np.full(len(default), math.nan)    # unknown, not sdformat's default
        if len(values) not in counts:
            expected = " or ".join(str(c) for c in counts)
            self._issue("bad-number", f"<{el.tag}>{raw}</{el.tag}> has {len(values)} number(s), "
                        f"expected {expected}", el, subject)
            return np.full(len(default), math.nan)
        # libsdformat parses "inf": in a limit that is "no limit" (reedtool.io.limits).
        values, problem = magnitude_problem(values, unbounded_ok=unbounded_ok,
                                            infinity_ok=unbounded_ok)
        if problem is not None:
            self._issue("non-finite", f"<{el.tag}>{raw}</{el.tag}> {problem}", el, subject)
        return np.array(values, dtype=float)

    def _number(self, parent: etree._Element | None, tag: str, default: float,
                subject: str | None, required: bool = False,
                unbounded_ok: bool = False) -> float:
        el = parent.find(tag) if parent is not None else None
        if el is None and required and parent is not None:
            self._issue("missing-element", f"<{parent.tag}> has no <{tag}>; sdformat uses "
                        f"{default:g}", parent, subject)
        return float(self._numbers(el, (1,), [default], subject, unbounded_ok)[0])

    def _pose(self, el: etree._Element | None,
              subject: str | None) -> tuple[np.ndarray, str | None]:
        """(T, relative_to as written) of a <pose>; identity and None when absent."""
        if el is None:
            return np.eye(4), None
        relative_to = el.get("relative_to") or el.get("frame") or None
        if (el.get("rotation_format") or "euler_rpy") == "quat_xyzw":
            v = self._numbers(el, (7,), [0, 0, 0, 0, 0, 0, 1], subject)
            x, y, z, w = v[3:]
            norm = math.sqrt(x * x + y * y + z * z + w * w) or 1.0
            x, y, z, w = x / norm, y / norm, z / norm, w / norm
            R = np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                          [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                          [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])
            return make_T(R, v[:3]), relative_to
        v = self._numbers(el, (6, 3), [0, 0, 0, 0, 0, 0], subject)
        if len(v) == 3:
            # libsdformat 9 (Gazebo classic) reads "x y z" as a position with no rotation
            # (`ss >> pose` without a fail check); 12 and later refuse it (S125).
            self._issue("sdf-short-pose", f"<pose>{' '.join(el.text.split())}</pose> has 3 "
                        "numbers: Gazebo classic reads a position without rotation, "
                        "libsdformat 12+ (gz-sim) refuses it", el, subject)
            v = np.concatenate([v, np.zeros(3)])
        rpy = np.radians(v[3:]) if (el.get("degrees") or "").lower() in ("true", "1") else v[3:]
        return make_T(rpy_to_matrix(rpy), v[:3]), relative_to

    @staticmethod
    def _scoped(scope: str, name: str | None) -> str:
        if not name or name == MODEL_FRAME:
            return scope + MODEL_FRAME
        if name == "world":
            return "world"
        return scope + name

    def T_model(self, name: str, el: etree._Element, subject: str | None,
                _seen: tuple[str, ...] = ()) -> np.ndarray:
        """Pose of frame `name` (scoped) in the top model frame at zero joint positions."""
        if name in self._resolved:
            return self._resolved[name]
        entry = self.frames.get(name)
        if entry is None and name + "::" + MODEL_FRAME in self.frames:
            # A nested model's name stands for its model frame.
            return self.T_model(name + "::" + MODEL_FRAME, el, subject, _seen)
        if entry is None or name in _seen:
            what = "is part of a cycle of relative_to frames" if name in _seen else \
                "names no link, joint, frame or model"
            self._issue("unknown-frame", f"frame '{name}' {what}; using the model frame", el,
                        subject)
            self._resolved[name] = np.eye(4)
            return self._resolved[name]
        T = self.T_model(entry.relative_to, entry.el, subject, _seen + (name,)) @ entry.T_rel_frame
        if entry.placement:
            # The pose is that of the placement frame: T_rel_model = X @ inv(T_model_placement).
            T = T @ np.linalg.inv(self._T_within(entry.placement, name, entry.el, subject))
        self._resolved[name] = T
        return T

    def _T_within(self, name: str, base: str, el: etree._Element, subject: str | None,
                  _seen: tuple[str, ...] = ()) -> np.ndarray:
        """Pose of frame `name` in frame `base`, following relative_to inside `base`'s model."""
        if name == base:
            return np.eye(4)
        entry = self.frames.get(name)
        if entry is None and name + "::" + MODEL_FRAME in self.frames:
            return self._T_within(name + "::" + MODEL_FRAME, base, el, subject, _seen)
        if entry is None or name in _seen or entry.placement:
            self._issue("unknown-frame", f"placement frame '{name}' is not posed within "
                        f"'{base}'; the placement is ignored", el, subject)
            return np.eye(4)
        return self._T_within(entry.relative_to, base, el, subject, _seen + (name,)) \
            @ entry.T_rel_frame

    def _node(self, el: etree._Element, scope: str = "") -> XmlNode:
        children = [self._node(c, scope) for c in el if isinstance(c.tag, str)]
        tag = local_tag(el)
        text = el.text
        if scope and tag in _SCOPED_PLUGIN_PARAMS and text and text.strip() \
                and not text.strip().startswith(scope):
            # A plugin of a nested model names the joints and links of that model.
            text = scope + text.strip()
        attrib = {local_tag(etree.Element(k)) if k.startswith("{") else k: v
                  for k, v in el.attrib.items()}
        return XmlNode(tag=tag, attrib=attrib, text=text, children=children, loc=self.loc(el))

    def canonical_link(self, scoped_model: str) -> str | None:
        """The link a nested model's name resolves to (SDF 1.8+ joint parent/child)."""
        model = self.model_els.get(scoped_model + "::")
        if model is None:
            return None
        scope = scoped_model + "::"
        if model.get("canonical_link"):
            return self._scoped(scope, model.get("canonical_link"))
        for name, link_scope, _el in self.link_els:
            if link_scope == scope:
                return name
        for nested_scope in self.model_els:
            if nested_scope.startswith(scope) and nested_scope.count("::") == scope.count("::") + 1:
                return self.canonical_link(nested_scope[:-2])
        return None

    def _top_canonical(self) -> str | None:
        """The top model's canonical link: its canonical_link=, else its first link."""
        if self.canonical:
            return self.canonical
        return next((name for name, scope, _el in self.link_els if scope == ""), None)

    def body_of(self, name: str | None, _seen: tuple[str, ...] = ()) -> str | None:
        """A joint's parent/child as a link: a nested model -> its canonical link, a frame
        -> the link it is attached to; links and unknown names stay as written."""
        if name is None or name == "world" or name in _seen:
            return name
        if name == MODEL_FRAME or name.endswith("::" + MODEL_FRAME):
            # A joint naming its model's frame is attached to the model's canonical link.
            scoped = name[:-len(MODEL_FRAME) - 2]
            return (self.canonical_link(scoped) if scoped else self._top_canonical()) or name
        if name + "::" + MODEL_FRAME in self.frames:
            return self.canonical_link(name) or name
        if name in self.attached_to:
            return self.body_of(self.attached_to[name], _seen + (name,))
        return name

    # ------------------------------------------------------------ collect
    def _renamed(self, scope: str, name: str, el: etree._Element) -> str:
        """The name libsdformat gives a joint or frame: below SDF 1.7 one that takes a
        sibling's name is renamed NAME_joint / NAME_frame with a warning (Model.cc), and
        references to NAME keep meaning the first (1.7 on refuses it: S161)."""
        if scope + name not in self.frames or self._version(el) >= (1, 7):
            return name
        renamed, i = f"{name}_{el.tag}", 0
        while scope + renamed in self.frames:
            renamed, i = f"{name}_{el.tag}{i}", i + 1
        return renamed

    def _collect(self, model: etree._Element, scope: str) -> None:
        """Register every frame of `model` (and its nested models) under scoped names."""
        for el in model:
            if not isinstance(el.tag, str):
                continue
            name = el.get("name") or ""
            if el.tag == "link":
                T, rel = self._pose(el.find("pose"), name)
                earlier = self.frames.get(scope + name)
                self.frames[scope + name] = _FrameEntry(self._scoped(scope, rel), T, el)
                self.link_els.append((scope + name, scope, el))
            elif el.tag == "joint":
                name = self._renamed(scope, name, el)
                T, rel = self._pose(el.find("pose"), name)
                child = (el.findtext("child") or "").strip()
                self.joint_els.append((scope + name, scope, el))
                if scope + name in self.frames:
                    # A joint named like a link (or frame) of its model (from SDF 1.7
                    # libsdformat refuses it: S161). The link keeps the name as a frame,
                    # so the joint is not read as a frame relative to itself.
                    continue
                self.frames[scope + name] = _FrameEntry(
                    self._scoped(scope, rel) if rel else self._scoped(scope, child), T, el)
            elif el.tag == "frame":
                name = self._renamed(scope, name, el)
                T, rel = self._pose(el.find("pose"), name)
                placement = el.get("placement_frame")   # set on merged-include proxy frames
                self.frames[scope + name] = _FrameEntry(
                    self._scoped(scope, rel or el.get("attached_to")), T, el,
                    scope + placement if placement else None)
                self.attached_to[scope + name] = self._scoped(scope, el.get("attached_to"))
            elif el.tag == "model":
                T, rel = self._pose(el.find("pose"), name)
                nested = scope + name + "::"
                placement = el.get("placement_frame")
                self.frames[nested + MODEL_FRAME] = _FrameEntry(
                    self._scoped(scope, rel), T, el, nested + placement if placement else None)
                self.model_els[nested] = el
                self._collect(el, nested)
            elif el.tag == "plugin":
                self.plugin_els.append((scope, el))

    # ------------------------------------------------------------ elements
    def read(self, model: etree._Element) -> Robot:
        name = model.get("name", "")
        self.canonical = model.get("canonical_link")
        self.model_name = name
        # The model's own pose places it in the world, which nothing here computes; its
        # numbers are still read, so one the loader refuses is a finding like any other.
        self._pose(model.find("pose"), name or None)
        self._collect(model, "")
        canonical = model.get("canonical_link")
        robot = Robot(name=name, loc=self.loc(model), source_file=self.file,
                      source_format="sdf", static=_is_static(model))
        for scoped, scope, el in self.link_els:
            robot.links.append(self._link(scoped, scope, el))
        for scoped, scope, el in self.joint_els:
            robot.joints.append(self._joint(scoped, scope, el))
        # The canonical link is the model's base; keep it first so it is the root found first.
        if canonical and canonical in robot.link_map:
            robot.links.sort(key=lambda link: link.name != canonical)
            robot.__dict__.pop("link_map", None)
        if self.plugin_els:
            block = GazeboBlock(reference=None, loc=self.loc(self.plugin_els[0][1]))
            for scope, el in self.plugin_els:
                node = self._node(el, scope)
                block.plugins.append(Plugin(name=el.get("name"), filename=el.get("filename"),
                                            node=node, loc=node.loc))
            robot.gazebo.append(block)
        robot.gazebo += self.sensor_blocks
        self._tolerated_issues()
        robot.parse_issues = self.issues
        return robot

    def _tolerated_issues(self) -> None:
        """One information issue per file read with TinyXML2's tolerance."""
        by_file: dict[Path, list] = {}
        for source, tolerated in self.sources.tolerated:
            by_file.setdefault(source.path, []).append(tolerated)
        for path, items in by_file.items():
            items = sorted(set(items), key=lambda t: t.line)   # a file included twice
            self.issues.append(ParseIssue("xml-tolerated", tolerated_message(items),
                                          SourceLoc(str(path), items[0].line), path.name))
            self.issues += late_declaration_issues(items, path)

    def _T_link_X(self, link_scoped: str, scope: str, pose_el: etree._Element | None,
                  subject: str) -> np.ndarray:
        """Pose of a <visual>/<collision>/<inertial> frame in its link frame."""
        T, rel = self._pose(pose_el, subject)
        if not rel or self._scoped(scope, rel) == link_scoped:
            return T
        T_model_link = self.T_model(link_scoped, pose_el, subject)
        T_model_rel = self.T_model(self._scoped(scope, rel), pose_el, subject)
        return np.linalg.inv(T_model_link) @ T_model_rel @ T

    def _link(self, scoped: str, scope: str, el: etree._Element) -> Link:
        link = Link(name=scoped, loc=self.loc(el))
        if not el.get("name"):
            self._issue("missing-attribute", "<link> has no name= attribute", el, None)
        inertial_el = el.find("inertial")
        if inertial_el is None:
            self._issue("sdf-default-inertial", f"link '{scoped}' has no <inertial>: sdformat "
                        "gives it a mass of 1 kg and an inertia of 1 kg*m^2", el, scoped)
            link.inertial = Inertial(SDF_DEFAULT_MASS_KG, np.eye(4), np.eye(3), self.loc(el))
        else:
            link.inertial = self._inertial(scoped, scope, inertial_el)
        for v in _children(el, "visual"):
            material = v.find("material")
            script = material.findtext("script/name") if material is not None else None
            link.visuals.append(Visual(
                geometry=self._geometry(v.find("geometry"), scoped),
                T_link_geom=self._T_link_X(scoped, scope, v.find("pose"), scoped),
                loc=self.loc(v), name=v.get("name"), material=script))
        for c in _children(el, "collision"):
            link.collisions.append(Collision(
                geometry=self._geometry(c.find("geometry"), scoped),
                T_link_geom=self._T_link_X(scoped, scope, c.find("pose"), scoped),
                loc=self.loc(c), name=c.get("name")))
        sensors = _children(el, "sensor")
        if sensors:
            # As URDF writes them: a <gazebo reference="LINK"> block holding the sensors.
            block = GazeboBlock(reference=scoped, loc=self.loc(sensors[0]))
            block.elements += [self._node(sensor) for sensor in sensors]
            self.sensor_blocks.append(block)
        return link

    def _inertial(self, link: str, scope: str, el: etree._Element) -> Inertial:
        if (el.get("auto") or "").lower() in ("true", "1"):
            self._issue("sdf-auto-inertial", f"link '{link}': <inertial auto=\"true\"> is not "
                        "computed by reedtool; write the mass and inertia out", el, link)
        mass_el = el.find("mass")
        mass = self._number(el, "mass", SDF_DEFAULT_MASS_KG, link, required=True)
        inertia_el = el.find("inertia")
        if inertia_el is None:
            self._issue("missing-element", f"link '{link}': <inertial> has no <inertia>; "
                        "sdformat uses 1 kg*m^2 on the diagonal", el, link)
        # sdformat's defaults: 1 kg*m^2 on the diagonal, 0 off it.
        v = {k: self._number(inertia_el, k, 1.0 if k in ("ixx", "iyy", "izz") else 0.0, link)
             for k in INERTIA_KEYS}
        tensor = inertia_tensor(v)
        return Inertial(mass_kg=mass, T_link_com=self._T_link_X(link, scope, el.find("pose"), link),
                        inertia_kg_m2=tensor, loc=self.loc(el),
                        mass_loc=self.loc(mass_el) if mass_el is not None else None,
                        inertia_loc=self.loc(inertia_el) if inertia_el is not None else None)

    def _geometry(self, el: etree._Element | None, link: str):
        """The shape, or None when it is absent or any of its numbers could not be read
        (the reader's finding speaks; no rule measures a box of NaN metres)."""
        start = len(self.issues)
        geometry = self._shape(el, link)
        return geometry if len(self.issues) == start else None

    def _shape(self, el: etree._Element | None, link: str):
        if el is None:
            return None
        shape = next((c for c in el if isinstance(c.tag, str)), None)
        if shape is None:
            self._issue("missing-element", "<geometry> is empty", el, link)
            return None
        if shape.tag == "box":
            return Box(size_m=self._numbers(shape.find("size"), (3,), [1.0, 1.0, 1.0], link))
        if shape.tag == "cylinder":
            return Cylinder(radius_m=self._number(shape, "radius", 1.0, link, required=True),
                            length_m=self._number(shape, "length", 1.0, link, required=True))
        if shape.tag == "sphere":
            return Sphere(radius_m=self._number(shape, "radius", 1.0, link, required=True))
        if shape.tag == "mesh":
            return self._mesh(shape, link)
        return None  # plane, capsule, ellipsoid, heightmap, polyline: not modelled

    def _mesh(self, el: etree._Element, link: str) -> Mesh:
        uri = (el.findtext("uri") or "").strip()
        scale = self._numbers(el.find("scale"), (3,), [1.0, 1.0, 1.0], link)
        if not uri:
            self._issue("missing-element", "<mesh> has no <uri>", el, link)
            return Mesh(uri="", path=None, scale=scale, resolve_error="no uri")
        try:
            return Mesh(uri=uri, path=self._resolve_uri(uri, el), scale=scale)
        except ReedtoolError as exc:
            return Mesh(uri=uri, path=None, scale=scale, resolve_error=exc.message)

    def _resolve_uri(self, uri: str, el: etree._Element) -> Path:
        file = self.file_of(el)   # the file that names the URI, which may be an included one
        if uri.startswith("model://"):
            return resolve_model_file_uri(uri, file, getattr(self.resolver, "package_paths", ()))
        if is_remote_uri(uri):
            raise ReedtoolError(REMOTE_NOT_CHECKED)
        return Path(self.resolver.resolve_uri(uri, file.parent))

    def _reference(self, scope: str, text: str, el: etree._Element, subject: str) -> str:
        """A joint's <parent>/<child> as a scoped frame name.

        Gazebo Classic (libsdformat 9, files before SDF 1.8) also finds a link by its
        scoped name in the world: `iris::base_link` written inside model `iris` is its own
        `base_link` (Joint::Load falls back to World::BaseByName). libsdformat 12+ refuses
        that ("not found in model"): resolved as Classic does, and said so (S191)."""
        name = self._scoped(scope, text)
        if name in self.frames or text == "world" or self._version(el) >= (1, 8):
            return name
        own = (scope[:-2].rsplit("::", 1)[-1] if scope else self.model_name) or ""
        prefix = own + "::"
        if own and text.startswith(prefix) and self._scoped(scope, text[len(prefix):]) in self.frames:
            self._issue("classic-scoped-name",
                        f"joint '{subject}' names '{text}', its own model's '{text[len(prefix):]}' "
                        "by the scoped name Gazebo Classic finds in the world; libsdformat 12+ "
                        "(gz-sim) refuses it", el, subject)
            return self._scoped(scope, text[len(prefix):])
        return name

    def _joint(self, scoped: str, scope: str, el: etree._Element) -> Joint:
        sdf_type = el.get("type", "")
        parent_text, child_text = el.findtext("parent"), el.findtext("child")
        parent = self.body_of(self._reference(scope, parent_text.strip(), el, scoped)) \
            if parent_text else None
        child = self.body_of(self._reference(scope, child_text.strip(), el, scoped)) \
            if child_text else None
        if parent is None:
            self._issue("missing-element", f"joint '{scoped}' has no <parent>", el, scoped)
        if child is None:
            self._issue("missing-element", f"joint '{scoped}' has no <child>", el, scoped)

        # URDF-style joint frame = child link frame.
        T_parent_child = np.eye(4)
        if parent and child and child in self.frames:
            T_model_parent = np.eye(4) if parent == "world" else self.T_model(parent, el, scoped)
            T_parent_child = np.linalg.inv(T_model_parent) @ self.T_model(child, el, scoped)

        axis_el = el.find("axis")
        xyz_el = axis_el.find("xyz") if axis_el is not None else None
        axis = self._numbers(xyz_el, (3,), [0.0, 0.0, 1.0], scoped)
        if xyz_el is not None and child in self.frames:
            expressed_in = xyz_el.get("expressed_in")
            parent_frame_el = axis_el.find("use_parent_model_frame")
            if parent_frame_el is not None and self._version(parent_frame_el) >= (1, 7):
                # SDF 1.7 dropped the element (1_6.convert rewrites it only when a 1.6 file
                # is upgraded): in a 1.7+ file libsdformat ignores it with a warning.
                self._issue("sdf-undefined-element", f"<use_parent_model_frame> of joint "
                            f"'{scoped}' is not part of SDF {self._version_text(parent_frame_el)}"
                            ": ignored, as libsdformat does (the axis is in the joint frame)",
                            parent_frame_el, scoped)
            elif expressed_in is None and (parent_frame_el is not None) \
                    and (parent_frame_el.text or "").strip().lower() in ("true", "1"):
                expressed_in = MODEL_FRAME
            frame = self._scoped(scope, expressed_in) if expressed_in else scoped
            R_child_frame = (np.linalg.inv(self.T_model(child, el, scoped))
                             @ self.T_model(frame, xyz_el, scoped))[:3, :3]
            axis = R_child_frame @ axis

        limit_el = axis_el.find("limit") if axis_el is not None else None
        joint_type, limit = self._joint_type(sdf_type, limit_el, scoped)
        # T_parent_joint is written in the child link's <pose> (URDF writes it in <origin>).
        child_entry = self.frames.get(child or "")
        pose_el = child_entry.el.find("pose") if child_entry is not None else None
        T_child_jointframe = None
        if child in self.frames and el.find("pose") is not None:
            T_child_jointframe = np.linalg.inv(self.T_model(child, el, scoped)) \
                @ self.T_model(scoped, el, scoped)
        return Joint(name=scoped, type=joint_type, parent=parent, child=child,
                     T_child_jointframe=T_child_jointframe,
                     T_parent_joint=T_parent_child, axis=axis, loc=self.loc(el), limit=limit,
                     axis_loc=self.loc(xyz_el) if xyz_el is not None else None,
                     origin_loc=self.loc(pose_el) if pose_el is not None else None)

    def _joint_type(self, sdf_type: str, limit_el: etree._Element | None,
                    name: str) -> tuple[str, JointLimit | None]:
        if sdf_type not in ("revolute", "prismatic", "continuous"):
            return sdf_type, None
        from reedtool.io.limits import as_limit, unbounded

        # Every "no limit" spelling libsdformat reads (+-inf, DBL_MAX, +-1e16, -1 for
        # effort and velocity) becomes +-inf here: reedtool.io.limits.
        lower, upper, effort, velocity = (
            as_limit(self._number(limit_el, tag, default, name, unbounded_ok=True), tag, "sdf")
            for tag, default in (("lower", -1e16), ("upper", 1e16), ("effort", -1.0),
                                 ("velocity", -1.0)))
        limit = JointLimit(lower=lower, upper=upper, effort=effort, velocity=velocity,
                           loc=self.loc(limit_el) if limit_el is not None else SourceLoc(
                               str(self.file)))
        if sdf_type == "continuous" or (sdf_type == "revolute" and unbounded(lower, upper)):
            return "continuous", limit if limit_el is not None else None
        return sdf_type, limit
