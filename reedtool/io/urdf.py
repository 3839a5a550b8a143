"""URDF text -> Robot model, keeping the source location of every element.

This is the only module that reads URDF XML. It never stops at the first problem in the
model's content: unreadable numbers, missing attributes and the like are collected as
ParseIssue entries for `validate` to report. Only input that is not a URDF at all
(malformed XML, wrong root element) raises ReedtoolError.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Callable, Sequence

import numpy as np
from lxml import etree

from reedtool.errors import ReedtoolError
from reedtool.io.fileio import magnitude_problem
from reedtool.frames import make_T, rpy_to_matrix
from reedtool.io.xml_lines import start_line
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
)

Locator = Callable[[etree._Element], SourceLoc]


def parse_urdf(xml_text: str, file: Path | str, *, resolver=None,
               element_locs: Sequence[SourceLoc] | None = None) -> Robot:
    """Parse URDF text read from (or expanded from) `file`.

    `element_locs`, from an xacro expansion, gives the SourceLoc of each element in
    document order; without it locations are lines of `file` itself. `resolver` resolves
    mesh URIs (reedtool.resolve.packages.PackageResolver); by default one rooted at `file`.
    """
    from reedtool.io.tolerant_xml import parse_tolerant

    file = Path(file)
    # As sdformat's URDF parser reads it (TinyXML2): see reedtool.io.tolerant_xml.
    root, tolerated = parse_tolerant(xml_text, file, line_known=element_locs is None)
    if root.tag != "robot":
        raise ReedtoolError(f"not a URDF: the root element is <{root.tag}>, expected <robot>",
                            file=file, line=root.sourceline)
    if resolver is None:
        from reedtool.resolve.packages import PackageResolver
        resolver = PackageResolver(model_path=file)
    locate = _make_locator(root, file, element_locs, xml_text.splitlines())
    robot = _RobotReader(file, locate, resolver).read(root, xml_text)
    if tolerated:
        from reedtool.io.tolerant_xml import late_declaration_issues, tolerated_message

        line = tolerated[0].line if element_locs is None else None
        robot.parse_issues.append(ParseIssue("xml-tolerated", tolerated_message(tolerated),
                                             SourceLoc(str(file), line), file.name))
        if element_locs is None:
            robot.parse_issues += late_declaration_issues(tolerated, file)
    return robot


def xml_parser() -> etree.XMLParser:
    """The parser for model text: no entity expansion, and the text is UTF-8 whatever its
    declaration says (reedtool.io.fileio.read_xml_file has already decoded it)."""
    return etree.XMLParser(remove_blank_text=False, resolve_entities=False, huge_tree=True,
                           encoding="utf-8")


def load_urdf_file(path: Path | str, *, resolver=None) -> Robot:
    from reedtool.io.fileio import read_xml_file

    path = Path(path)
    text, _encoding = read_xml_file(path, what="URDF file")
    return parse_urdf(text, path, resolver=resolver)


def _make_locator(root: etree._Element, file: Path, element_locs: Sequence[SourceLoc] | None,
                  lines: Sequence[str]) -> Locator:
    if element_locs is None:
        def locate(el: etree._Element) -> SourceLoc:
            line = start_line(el.tag, el.sourceline, lines)
            return SourceLoc(str(file), line, urdf_line=line)
        return locate
    elements = [el for el in root.iter() if isinstance(el.tag, str)]
    if len(elements) != len(element_locs):
        # A mapping that does not line up would point users at wrong lines; fall back to
        # the expanded file's own lines rather than guess.
        return lambda el: SourceLoc(str(file), None, urdf_line=el.sourceline)
    by_element = {el: loc for el, loc in zip(elements, element_locs)}
    return lambda el: by_element.get(el, SourceLoc(str(file), None, urdf_line=el.sourceline))


class _RobotReader:
    def __init__(self, file: Path, locate: Locator, resolver):
        self.file = file
        self.locate = locate
        self.resolver = resolver
        self.issues: list[ParseIssue] = []

    # ---------------------------------------------------------------- helpers
    def _issue(self, kind: str, message: str, el: etree._Element, subject: str | None) -> None:
        self.issues.append(ParseIssue(kind, message, self.locate(el), subject))

    def _floats(self, el: etree._Element | None, attr: str, count: int, default: Sequence[float],
                subject: str | None, unbounded_ok: bool = False) -> np.ndarray:
        """Read `count` numbers from an attribute; problems become ParseIssues.

        `default` stands in for an absent attribute. An unreadable one reads as NaN, not
        as the default: its finding speaks, and what is computed from it stays unknown
        (a 0 there would be a silent guess that other rules then judge)."""
        if el is None or el.get(attr) is None:
            return np.array(default, dtype=float)
        raw = el.get(attr)
        parts = raw.split()
        try:
            values = [float(p) for p in parts]
        except ValueError:
            self._issue("bad-number", f"<{el.tag} {attr}=\"{raw}\"> is not {count} number(s)",
                        el, subject)
            return np.full(count, math.nan)
        if len(values) != count:
            self._issue("bad-number", f"<{el.tag} {attr}=\"{raw}\"> has {len(values)} "
                        f"number(s), expected {count}", el, subject)
            return np.full(count, math.nan)
        values, problem = magnitude_problem(values, unbounded_ok=unbounded_ok)
        if problem is not None:
            self._issue("non-finite", f"<{el.tag} {attr}=\"{raw}\"> {problem}", el, subject)
        return np.array(values, dtype=float)

    def _float(self, el: etree._Element | None, attr: str, default: float | None,
               subject: str | None, required: bool = False,
               unbounded_ok: bool = False) -> float | None:
        if el is None:
            return default
        if el.get(attr) is None:
            if required:
                self._issue("missing-attribute", f"<{el.tag}> has no {attr}= attribute",
                            el, subject)
            return default
        fallback = [default] if default is not None else [math.nan]
        return float(self._floats(el, attr, 1, fallback, subject, unbounded_ok)[0])

    def _origin(self, el: etree._Element | None, subject: str | None) -> np.ndarray:
        if el is None:
            return np.eye(4)
        xyz = self._floats(el, "xyz", 3, (0.0, 0.0, 0.0), subject)
        rpy = self._floats(el, "rpy", 3, (0.0, 0.0, 0.0), subject)
        return make_T(rpy_to_matrix(rpy), xyz)

    def _node(self, el: etree._Element) -> XmlNode:
        children = [self._node(c) for c in el if isinstance(c.tag, str)]
        return XmlNode(tag=el.tag, attrib=dict(el.attrib), text=el.text, children=children,
                       loc=self.locate(el))

    # ---------------------------------------------------------------- elements
    def read(self, root: etree._Element, xml_text: str) -> Robot:
        robot = Robot(name=root.get("name", ""), loc=self.locate(root), source_file=self.file,
                      urdf_xml=xml_text)
        if not root.get("name"):
            # urdfdom (check_urdf, Pinocchio) refuses a robot without a name.
            self._issue("missing-attribute", "<robot> has no name= attribute", root, None)
        for el in root:
            if not isinstance(el.tag, str):
                continue
            if el.tag == "link":
                robot.links.append(self._link(el))
            elif el.tag == "joint":
                robot.joints.append(self._joint(el))
            elif el.tag == "gazebo":
                robot.gazebo.append(self._gazebo(el))
        robot.parse_issues = self.issues
        return robot

    def _link(self, el: etree._Element) -> Link:
        name = el.get("name")
        if not name:
            self._issue("missing-attribute", "<link> has no name= attribute", el, None)
            name = ""
        link = Link(name=name, loc=self.locate(el))
        inertial = el.find("inertial")
        if inertial is not None:
            link.inertial = self._inertial(inertial, name)
        for v in el.findall("visual"):
            material = v.find("material")
            link.visuals.append(Visual(geometry=self._geometry(v.find("geometry"), name),
                                       T_link_geom=self._origin(v.find("origin"), name),
                                       loc=self.locate(v), name=v.get("name"),
                                       material=material.get("name") if material is not None else None))
        for c in el.findall("collision"):
            link.collisions.append(Collision(geometry=self._geometry(c.find("geometry"), name),
                                             T_link_geom=self._origin(c.find("origin"), name),
                                             loc=self.locate(c), name=c.get("name")))
        return link

    def _inertial(self, el: etree._Element, link: str) -> Inertial:
        mass_el = el.find("mass")
        if mass_el is None:
            self._issue("missing-element", "<inertial> has no <mass>", el, link)
        mass = self._float(mass_el, "value", 0.0, link, required=True)
        inertia_el = el.find("inertia")
        if inertia_el is None:
            self._issue("missing-element", "<inertial> has no <inertia>", el, link)
        values = {k: self._float(inertia_el, k, 0.0, link, required=inertia_el is not None)
                  for k in INERTIA_KEYS}
        return Inertial(mass_kg=float(mass), T_link_com=self._origin(el.find("origin"), link),
                        inertia_kg_m2=inertia_tensor(values), loc=self.locate(el),
                        mass_loc=self.locate(mass_el) if mass_el is not None else None,
                        inertia_loc=self.locate(inertia_el) if inertia_el is not None else None)

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
            return Box(size_m=self._floats(shape, "size", 3, (math.nan,) * 3, link))
        if shape.tag == "cylinder":
            return Cylinder(radius_m=self._float(shape, "radius", math.nan, link, required=True),
                            length_m=self._float(shape, "length", math.nan, link, required=True))
        if shape.tag == "sphere":
            return Sphere(radius_m=self._float(shape, "radius", math.nan, link, required=True))
        if shape.tag == "mesh":
            return self._mesh(shape, link)
        self._issue("unknown-element", f"unknown geometry <{shape.tag}>", shape, link)
        return None

    def _mesh(self, el: etree._Element, link: str) -> Mesh:
        uri = el.get("filename", "")
        scale = self._floats(el, "scale", 3, (1.0, 1.0, 1.0), link)
        if not uri:
            self._issue("missing-attribute", "<mesh> has no filename= attribute", el, link)
            return Mesh(uri="", path=None, scale=scale, resolve_error="no filename")
        from reedtool.resolve.resources import REMOTE_NOT_CHECKED, is_remote_uri

        if is_remote_uri(uri):
            return Mesh(uri=uri, path=None, scale=scale, resolve_error=REMOTE_NOT_CHECKED)
        try:
            # Relative mesh paths are relative to the file the user passed, as in xacro.
            path = self.resolver.resolve_uri(uri, self.file.parent, requested_by=self.locate(el))
        except ReedtoolError as exc:
            return Mesh(uri=uri, path=None, scale=scale, resolve_error=exc.message)
        return Mesh(uri=uri, path=Path(path), scale=scale)

    def _joint(self, el: etree._Element) -> Joint:
        name = el.get("name") or ""
        if not name:
            self._issue("missing-attribute", "<joint> has no name= attribute", el, None)
        parent_el, child_el = el.find("parent"), el.find("child")
        parent = parent_el.get("link") if parent_el is not None else None
        child = child_el.get("link") if child_el is not None else None
        if parent is None:
            self._issue("missing-element", "<joint> has no <parent link=...>", el, name)
        if child is None:
            self._issue("missing-element", "<joint> has no <child link=...>", el, name)
        axis_el = el.find("axis")
        limit_el = el.find("limit")
        limit = None
        if limit_el is not None:
            from reedtool.io.limits import as_limit

            # DBL_MAX in a limit is "no limit" (urdfdom stores it as given); "inf" is not,
            # urdfdom refuses it (reedtool.io.limits).
            lower, upper, effort, velocity = (
                as_limit(self._float(limit_el, attr, None, name, unbounded_ok=True), attr,
                         "urdf")
                for attr in ("lower", "upper", "effort", "velocity"))
            limit = JointLimit(lower=lower, upper=upper, effort=effort, velocity=velocity,
                               loc=self.locate(limit_el))
        origin_el = el.find("origin")
        return Joint(name=name, type=el.get("type", ""), parent=parent, child=child,
                     T_parent_joint=self._origin(origin_el, name),
                     axis=self._floats(axis_el, "xyz", 3, (1.0, 0.0, 0.0), name),
                     loc=self.locate(el), limit=limit,
                     axis_loc=self.locate(axis_el) if axis_el is not None else None,
                     origin_loc=self.locate(origin_el) if origin_el is not None else None)

    def _gazebo(self, el: etree._Element) -> GazeboBlock:
        block = GazeboBlock(reference=el.get("reference"), loc=self.locate(el))
        for child in el:
            if not isinstance(child.tag, str):
                continue
            node = self._node(child)
            if child.tag == "plugin":
                block.plugins.append(Plugin(name=child.get("name"), filename=child.get("filename"),
                                            node=node, loc=node.loc))
            else:
                block.elements.append(node)
        return block
