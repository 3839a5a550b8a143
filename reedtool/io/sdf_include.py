"""Expand SDF `<include>`s in place, as libsdformat does before it builds the model.

* Without `<merge>`, an include becomes a nested `<model>` named by the include's
  `<name>` (else the included model's name), posed by the include's `<pose>` (with its
  `relative_to`; with `<placement_frame>` the pose places that frame of the model), made
  static by its `<static>`. The model reader scopes its names
  (`camera::link`).
* With `merge="true"` (SDF 1.9) inside a `<model>`, the included model's links,
  joints, frames, nested models and plugins are moved into the including model under
  their own names, and a frame `_merged__NAME__model__` takes the place of the included
  model's frame: it carries the include's pose and is attached to the included model's
  canonical link, and every pose, `attached_to` and `expressed_in` that meant the
  included `__model__` (explicitly or by default) now names it.
* A merge-include directly in a `<world>` (an SDF 1.10 draft amendment) is read as a plain
  include: the model is checked on its own, which is what matters for validation.
* Includes are expanded innermost first; a file already on the include chain is a cycle
  and refused with the chain.

Every element keeps its own file: `SourceMap` maps the root of each moved subtree to the
file (and text lines) it was read from, and the reader looks up the nearest registered
ancestor. Elements written by the include itself (its `<pose>`) stay in the including file.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Sequence

from lxml import etree

from reedtool.errors import ReedtoolError
from reedtool.resolve.resources import is_remote_uri, resolve_model_uri
from reedtool.io.tolerant_xml import Tolerated, parse_tolerant
from reedtool.io.xml_lines import start_line

MODEL_FRAME = "__model__"
# Elements of an included <model> that describe the model itself, not a frame in it.
_MODEL_PROPERTIES = {"pose", "static", "self_collide", "allow_auto_disable", "enable_wind"}


@dataclass
class SourceFile:
    path: Path
    lines: list[str]


@dataclass
class UnresolvedInclude:
    """A world-level include reedtool could not read (a Fuel model, the sun, the ground)."""

    name: str | None
    uri: str
    file: Path
    line: int | None
    reason: str


@dataclass
class SourceMap:
    """Element -> the file it came from (for subtree roots; look up with `file_of`)."""

    top: SourceFile
    roots: dict = field(default_factory=dict)
    # Elements an <include> writes for the included model (<pose>, <static>): an issue
    # with them is an issue with the inclusion, so it points at the <include> line.
    lines: dict = field(default_factory=dict)
    tolerated: list[tuple[SourceFile, Tolerated]] = field(default_factory=list)
    unresolved: list[UnresolvedInclude] = field(default_factory=list)
    # (uri, file, line) of every <include> read, for what a rule says about its URI.
    include_uris: list[tuple[str, Path, int | None]] = field(default_factory=list)
    # Includes inside a model that Gazebo fetches from the web (Fuel): left out, said so.
    remote: list[UnresolvedInclude] = field(default_factory=list)

    def file_of(self, el: etree._Element) -> SourceFile:
        node = el
        while node is not None:
            found = self.roots.get(node)
            if found is not None:
                return found
            node = node.getparent()
        return self.top

    def line_of(self, el: etree._Element) -> int | None:
        node = el
        while node is not None:
            if node in self.lines:
                return self.lines[node]
            node = node.getparent()
        source = self.file_of(el)
        return start_line(el.tag, el.sourceline, source.lines) if isinstance(el.tag, str) \
            else el.sourceline


def _shown(path: Path) -> str:
    """A path as the user would type it: relative to the working directory when inside it."""
    try:
        return str(path.relative_to(Path.cwd().resolve()))
    except ValueError:
        return str(path)


def _is_true(text: str | None) -> bool:
    return (text or "").strip().lower() in ("true", "1")


def _first_link(model: etree._Element) -> str | None:
    link = model.find("link")
    if link is not None:
        return link.get("name")
    nested = model.find("model")
    if nested is not None:
        inner = _first_link(nested)
        return f"{nested.get('name')}::{inner}" if inner else None
    return None


def _retarget(el: etree._Element | None, attr: str, frame: str, *, if_missing: bool) -> None:
    if el is None:
        return
    value = el.get(attr)
    if value == MODEL_FRAME or (value is None and if_missing):
        el.set(attr, frame)


def _merge_into(parent: etree._Element, include: etree._Element, model: etree._Element,
                name: str, sources: SourceMap, including: SourceFile,
                include_line: int | None) -> None:
    frame_name = f"_merged__{name}__model__"
    frame = etree.Element("frame", name=frame_name)
    sources.lines[frame] = include_line
    canonical = model.get("canonical_link") or _first_link(model)
    if canonical:
        frame.set("attached_to", canonical)
    if model.get("placement_frame"):
        # The include's pose places this frame of the merged model (SDF 1.8 placement_frame).
        frame.set("placement_frame", model.get("placement_frame"))
    pose = model.find("pose")
    sources.roots[frame] = including
    if pose is None:
        # The merged frame is posed in the including model's frame, never in attached_to.
        pose = etree.SubElement(model, "pose")
        pose.text = "0 0 0 0 0 0"
        sources.roots[pose] = including
    sources.roots.setdefault(pose, sources.file_of(pose))
    if pose.get("relative_to") is None and pose.get("frame") is None:
        pose.set("relative_to", MODEL_FRAME)
    frame.append(pose)
    moved = [frame]
    for child in list(model):
        if not isinstance(child.tag, str) or child.tag in _MODEL_PROPERTIES:
            continue
        child_pose = child.find("pose")
        if child.tag in ("link", "model"):
            if child_pose is None:
                child_pose = etree.SubElement(child, "pose", relative_to=frame_name)
                child_pose.text = "0 0 0 0 0 0"
                sources.lines[child_pose] = sources.line_of(child)
            elif child_pose.get("frame") is None:
                _retarget(child_pose, "relative_to", frame_name, if_missing=True)
        elif child.tag == "frame":
            _retarget(child, "attached_to", frame_name, if_missing=True)
            _retarget(child_pose, "relative_to", frame_name, if_missing=False)
        elif child.tag == "joint":
            _retarget(child_pose, "relative_to", frame_name, if_missing=False)
            for axis in child.iterfind("axis"):
                xyz = axis.find("xyz")
                # SDF 1.6's <use_parent_model_frame> meant the included model's frame too.
                implied = _is_true(axis.findtext("use_parent_model_frame"))
                _retarget(xyz, "expressed_in", frame_name, if_missing=implied)
        sources.roots.setdefault(child, sources.file_of(child))
        moved.append(child)
    index = list(parent).index(include)
    parent.remove(include)
    for offset, child in enumerate(moved):
        parent.insert(index + offset, child)


def _apply_overrides(include: etree._Element, model: etree._Element, sources: SourceMap,
                     including: SourceFile, include_line: int | None) -> str:
    name = (include.findtext("name") or "").strip() or model.get("name") or ""
    model.set("name", name)
    pose = include.find("pose")
    if pose is not None:
        for old in model.findall("pose"):
            model.remove(old)
        model.insert(0, pose)
        sources.roots[pose] = including
        sources.lines[pose] = include_line
    placement = (include.findtext("placement_frame") or "").strip()
    if placement:
        model.set("placement_frame", placement)
    static = include.find("static")
    if static is not None:
        for old in model.findall("static"):
            model.remove(old)
        model.append(static)
        sources.roots[static] = including
        sources.lines[static] = include_line
    for plugin in include.findall("plugin"):
        model.append(plugin)
        sources.roots[plugin] = including
    return name


def _read(path: Path, sources: SourceMap) -> tuple[etree._Element, SourceFile]:
    from reedtool.io.fileio import read_xml_file
    from reedtool.io.sdf_jinja import is_sdf_jinja, render

    if is_sdf_jinja(path):      # an included PX4 Classic model (iris_opt_flow -> px4flow)
        text = render(path).text
    else:
        text, _encoding = read_xml_file(path, what="SDF file")
    root, tolerated = parse_tolerant(text, path)
    source = SourceFile(path, text.splitlines())
    sources.tolerated += [(source, t) for t in tolerated]
    return root, source


def expand_includes(root: etree._Element, source: SourceFile, sources: SourceMap,
                    package_paths: Sequence[Path] = (),
                    chain: tuple[Path, ...] = ()) -> None:
    """Replace every <include> under `root` (read from `source`) by what it includes."""
    chain = chain + (source.path.resolve(),)
    for include in list(root.iter("include")):
        parent = include.getparent()
        line = start_line("include", include.sourceline, source.lines)
        uri = (include.findtext("uri") or "").strip()
        in_world = parent is not None and parent.tag == "world"
        sources.include_uris.append((uri, source.path, line))
        try:
            if not uri:
                raise ReedtoolError("<include> has no <uri>")
            path = resolve_model_uri(uri, source.path, package_paths)
        except ReedtoolError as exc:
            if not in_world and is_remote_uri(uri) and parent is not None:
                # Gazebo downloads it; the model is checked without it (S190 says so).
                sources.remote.append(UnresolvedInclude(
                    (include.findtext("name") or "").strip() or None, uri, source.path, line,
                    exc.message))
                parent.remove(include)
                continue
            if in_world:
                sources.unresolved.append(UnresolvedInclude(
                    (include.findtext("name") or "").strip() or None, uri, source.path, line,
                    exc.message))
                parent.remove(include)
                continue
            raise ReedtoolError(exc.message, file=source.path, line=line,
                                hint="set GZ_SIM_RESOURCE_PATH or pass --package-path DIR "
                                     "with the directory holding the model") from None
        resolved = path.resolve()
        if resolved in chain:
            links = [*chain[chain.index(resolved):], resolved]
            raise ReedtoolError("<include> cycle: " + " -> ".join(_shown(p) for p in links),
                                file=source.path, line=line,
                                hint="a model cannot include itself")
        included_root, included = _read(path, sources)
        expand_includes(included_root, included, sources, package_paths, chain)
        model = included_root.find("model") if included_root.tag == "sdf" else None
        if model is None and in_world:
            # A world may include a light (model://sun) or an actor: nothing to check.
            sources.unresolved.append(UnresolvedInclude(
                (include.findtext("name") or "").strip() or None, uri, source.path, line,
                f"{_shown(path)} holds no <model>"))
            parent.remove(include)
            continue
        if model is None:
            raise ReedtoolError(f"included file {_shown(path)} holds no <model>",
                                file=source.path, line=line)
        sources.roots.setdefault(model, included)
        name = _apply_overrides(include, model, sources, source, line)
        merge = _is_true(include.get("merge")) or _is_true(include.findtext("merge"))
        if merge and parent is not None and parent.tag == "model":
            _merge_into(parent, include, model, name, sources, source, line)
        else:
            parent.replace(include, model)
