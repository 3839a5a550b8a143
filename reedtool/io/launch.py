"""The model and xacro arguments a launch file would use, read without ROS.

`--launch FILE` lets `validate` check a model with the arguments the robot is actually
launched with. Three launch formats are read, none of them executed:

- roslaunch XML (ROS 1): `<arg>`s, the xacro call in
  `<param name="robot_description" command="$(find xacro)/xacro MODEL name:=value ...">`,
  and `<include file="...">` with its `<arg name value>`s (RotorS's
  mav_hovering_example.launch includes spawn_mav.launch, which holds the xacro call).
- ROS 2 XML: `<arg>`s and `$(command 'xacro MODEL name:=value')` in any attribute.
- ROS 2 Python: parsed with `ast`; `DeclareLaunchArgument`, `Command([...])` holding xacro
  and `xacro.process_file(MODEL, mappings={...})`, with string constants, names assigned
  earlier, `os.path.join`, `get_package_share_directory`, `FindPackageShare`,
  `PathJoinSubstitution` and `LaunchConfiguration` evaluated statically.

Substitutions that need a running system (`$(eval)`, environment lookups) leave the
argument out rather than guessing its value.
"""

from __future__ import annotations

import ast
import os
import re
import shlex
from dataclasses import dataclass, field
from pathlib import Path
from typing import Sequence

from reedtool.errors import ReedtoolError
from reedtool.resolve.mappings import MAPPING_SEPARATOR
from reedtool.resolve.packages import PackageResolver
from reedtool.model import SourceLoc

_MAX_INCLUDE_DEPTH = 10
_XACRO_EXECUTABLES = ("xacro", "xacro.py")


@dataclass
class LaunchCall:
    """One xacro call found in a launch file."""

    model: Path | None                                   # None: could not be evaluated
    mappings: dict[str, str] = field(default_factory=dict)
    locs: dict[str, SourceLoc] = field(default_factory=dict)   # argument -> where written
    loc: SourceLoc | None = None                         # the xacro call itself


class _Unresolved(Exception):
    """A substitution that cannot be evaluated without a running ROS system."""


def _display(path: Path) -> str:
    try:
        return os.path.relpath(path) if path.resolve().is_relative_to(Path.cwd().resolve()) \
            else str(path)
    except (ValueError, OSError):
        return str(path)


# ----------------------------------------------------------------- substitutions

_SUBST = re.compile(r"\$\(([^()]*)\)")


_UNKNOWN = "\x00unresolved\x00"


def _substitute(text: str, values: dict[str, str], resolver: PackageResolver,
                loc: SourceLoc, *, lenient: bool = False) -> str:
    """roslaunch/ROS 2 XML `$(...)` substitutions, innermost first.

    `lenient`: a substitution that cannot be evaluated becomes a marker (`_UNKNOWN`)
    instead of raising, so the rest of a command line can still be read.
    """

    def one(match: re.Match) -> str:
        if not lenient:
            return strict(match)
        try:
            return strict(match)
        except (_Unresolved, ReedtoolError):
            return _UNKNOWN

    def strict(match: re.Match) -> str:
        command, _, rest = match.group(1).strip().partition(" ")
        rest = rest.strip().strip("'\"")
        if command in ("arg", "var"):
            if rest in values and values[rest] is None:
                raise _Unresolved(match.group(0))   # its own value could not be evaluated
            if rest not in values:
                raise ReedtoolError(f"launch argument '{rest}' is used but never declared",
                                    file=loc.file, line=loc.line,
                                    hint="declare it with <arg name=... default=...>")
            return values[rest]
        if command in ("find", "find-pkg-share", "find-pkg-prefix"):
            return str(resolver.find(rest, requested_by=loc))
        if command == "dirname":
            return str(Path(loc.file).resolve().parent)
        if command == "optenv":
            name, _, default = rest.partition(" ")
            return os.environ.get(name, default.strip())
        raise _Unresolved(match.group(0))

    for _ in range(20):   # nested substitutions resolve inside out
        new = _SUBST.sub(one, text)
        if new == text:
            return new
        text = new
    return text


def _line_of(lines: Sequence[str], start: int, needle: str) -> int:
    for number in range(max(start, 1), len(lines) + 1):
        if needle in lines[number - 1]:
            return number
    return start


def _xacro_call(command: str, values: dict[str, str], resolver: PackageResolver,
                loc: SourceLoc, lines: Sequence[str]) -> LaunchCall | None:
    """`.../xacro MODEL a:=b ...` -> LaunchCall; None when the command is not xacro."""
    command = _substitute(command, values, resolver, loc, lenient=True)
    try:
        words = shlex.split(command)
    except ValueError:
        words = command.split()
    for index, word in enumerate(words):
        if Path(word.rstrip("'\"")).name in _XACRO_EXECUTABLES:
            break
    else:
        return None
    call = LaunchCall(model=None, loc=loc)
    for word in words[index + 1:]:
        name, sep, value = word.partition(MAPPING_SEPARATOR)
        if not sep:
            if word.startswith("-") or call.model is not None:
                continue     # xacro options (--inorder, -o FILE) do not name the model
            if _UNKNOWN not in word:
                call.model = Path(word)
            continue
        if _UNKNOWN in value:
            continue     # e.g. $(eval ...): the model's default applies, as we cannot know
        call.mappings[name] = value
        call.locs[name] = SourceLoc(loc.file,
                                    _line_of(lines, loc.line or 1, name + MAPPING_SEPARATOR))
    return call


# ----------------------------------------------------------------- XML launch files

def _read_xml_launch(path: Path, given: dict[str, str], resolver: PackageResolver,
                     depth: int) -> LaunchCall | None:
    from reedtool.io.fileio import read_xml_file
    from reedtool.io.tolerant_xml import parse_tolerant
    from reedtool.io.xml_lines import start_line

    text, _encoding = read_xml_file(path, what="launch file")
    lines = text.splitlines()
    # roslaunch and ROS 2 launch read XML leniently too; what TinyXML2 accepts is read
    # (reedtool.io.tolerant_xml).
    root, _tolerated = parse_tolerant(text, _display(path), remove_comments=True,
                                      error="not a launch file",
                                      hint="fix the XML syntax at that position")
    if root.tag != "launch":
        raise ReedtoolError(f"not a launch file: the root element is <{root.tag}>, "
                            "expected <launch>", file=_display(path), line=root.sourceline)

    def loc_of(element) -> SourceLoc:
        return SourceLoc(_display(path), start_line(element.tag, element.sourceline, lines))

    values: dict[str, str] = {}
    found: LaunchCall | None = None
    for element in root.iter():
        if not isinstance(element.tag, str):
            continue
        loc = loc_of(element)
        # <arg> directly in <launch> or a <group>: a declaration of this file.
        if element.tag == "arg" and element.getparent().tag != "include":
            name = element.get("name")
            if name is None:
                continue
            try:
                if given.get(name) is not None:
                    values[name] = given[name]
                elif element.get("value") is not None:
                    values[name] = _substitute(element.get("value"), values, resolver, loc)
                elif element.get("default") is not None:
                    values[name] = _substitute(element.get("default"), values, resolver, loc)
                else:
                    values[name] = None     # required: given by an including file
            except (_Unresolved, ReedtoolError):
                # A package not installed here (gazebo_ros) or $(eval): unknown, and only
                # an error if the xacro call needs it.
                values[name] = None
            continue
        if found is not None:
            continue
        for attribute in ("command", "value"):
            raw = element.get(attribute)
            if raw is None or "xacro" not in raw:
                continue
            command = raw
            inner = re.search(r"\$\(command\s+(['\"])(.*)\1\s*\)", raw, re.S)
            if inner:
                command = inner.group(2)
            elif attribute == "value":
                continue
            call = _xacro_call(command, values, resolver, loc, lines)
            if call is not None:
                found = call
                break
        if found is None and element.tag == "include" and depth < _MAX_INCLUDE_DEPTH:
            try:
                target = Path(_substitute(element.get("file", ""), values, resolver, loc))
            except (_Unresolved, ReedtoolError):
                continue     # e.g. gazebo_ros's empty_world.launch: not needed, not here
            passed: dict[str, str] = {}
            if element.get("pass_all_args", "").lower() == "true":
                passed.update({k: v for k, v in values.items() if v is not None})
            for arg in element.findall("arg"):
                try:
                    passed[arg.get("name")] = _substitute(arg.get("value", arg.get("default", "")),
                                                          values, resolver, loc_of(arg))
                except (_Unresolved, ReedtoolError):
                    passed[arg.get("name")] = None
            if target.is_file():
                found = read_launch(target, resolver=resolver, given=passed, depth=depth + 1)
    return found


# ----------------------------------------------------------------- Python launch files

class _PyEval:
    """Static evaluation of the few expressions launch files build xacro calls from."""

    def __init__(self, resolver: PackageResolver, path: Path):
        self.resolver = resolver
        self.path = path
        self.names: dict[str, object] = {}
        self.defaults: dict[str, str] = {}

    def loc(self, node: ast.AST) -> SourceLoc:
        return SourceLoc(_display(self.path), getattr(node, "lineno", None))

    def value(self, node: ast.AST):
        if isinstance(node, ast.Constant) and isinstance(node.value, (str, int, float)):
            return str(node.value)
        if isinstance(node, ast.Name):
            if node.id in self.names:
                return self.names[node.id]
            raise _Unresolved(node.id)
        if isinstance(node, ast.JoinedStr):
            return "".join(self.value(v.value if isinstance(v, ast.FormattedValue) else v)
                           for v in node.values)
        if isinstance(node, (ast.List, ast.Tuple)):
            return [self.value(v) for v in node.elts]
        if isinstance(node, ast.BinOp) and isinstance(node.op, ast.Add):
            left, right = self.value(node.left), self.value(node.right)
            if isinstance(left, list) or isinstance(right, list):
                return (left if isinstance(left, list) else [left]) + \
                    (right if isinstance(right, list) else [right])
            return left + right
        if isinstance(node, ast.Dict):
            return {self.value(k): self.value(v) for k, v in zip(node.keys, node.values)}
        if isinstance(node, ast.Call):
            return self.call(node)
        raise _Unresolved(ast.dump(node)[:40])

    def _arg(self, node: ast.Call, index: int, keyword: str):
        if len(node.args) > index:
            return self.value(node.args[index])
        for kw in node.keywords:
            if kw.arg == keyword:
                return self.value(kw.value)
        raise _Unresolved(keyword)

    def call(self, node: ast.Call):
        func = node.func
        name = func.attr if isinstance(func, ast.Attribute) else getattr(func, "id", "")
        if name == "join" and isinstance(func, ast.Attribute):
            if isinstance(func.value, ast.Attribute) and func.value.attr == "path":
                return os.path.join(*(str(self.value(a)) for a in node.args))
            if isinstance(func.value, ast.Constant):            # "".join([...])
                return func.value.value.join(str(v) for v in self.value(node.args[0]))
        if name in ("get_package_share_directory", "get_package_prefix"):
            return str(self.resolver.find(self._arg(node, 0, "package_name"),
                                          requested_by=self.loc(node)))
        if name == "FindPackageShare":
            return str(self.resolver.find(self._arg(node, 0, "package"),
                                          requested_by=self.loc(node)))
        if name == "PathJoinSubstitution":
            parts = self.value(node.args[0])
            return os.path.join(*(str(p) for p in parts))
        if name == "LaunchConfiguration":
            arg = self._arg(node, 0, "variable_name")
            # No default: given at launch time; the words using it are left out.
            return self.defaults.get(arg, _UNKNOWN)
        if name == "Path":
            return os.path.join(*(str(self.value(a)) for a in node.args))
        if name == "str" and node.args:
            return str(self.value(node.args[0]))
        raise _Unresolved(name)


def _read_python_launch(path: Path, resolver: PackageResolver) -> LaunchCall | None:
    from reedtool.io.fileio import read_text_file

    text = read_text_file(path, what="launch file")
    try:
        tree = ast.parse(text, filename=str(path))
    except SyntaxError as exc:
        raise ReedtoolError(f"not a Python launch file: {exc.msg}", file=_display(path),
                            line=exc.lineno) from None
    lines = text.splitlines()
    ev = _PyEval(resolver, path)
    found: LaunchCall | None = None
    # Statements in source order: names are known once assigned, as when the file runs.
    nodes = sorted((n for n in ast.walk(tree) if isinstance(n, (ast.Assign, ast.Call))),
                   key=lambda n: (n.lineno, n.col_offset))
    # Launch arguments first: a LaunchConfiguration is often built before its declaration.
    for node in nodes:
        if isinstance(node, ast.Call) and _call_name(node) == "DeclareLaunchArgument":
            try:
                arg = ev._arg(node, 0, "name")
                for kw in node.keywords:
                    if kw.arg == "default_value":
                        ev.defaults[arg] = "".join(map(str, _flat(ev.value(kw.value))))
            except (_Unresolved, TypeError, AttributeError, IndexError, ReedtoolError):
                continue
    for node in nodes:
        if isinstance(node, ast.Assign):
            for target in node.targets:
                if isinstance(target, ast.Name):
                    try:
                        ev.names[target.id] = ev.value(node.value)
                    except (_Unresolved, ReedtoolError, TypeError):
                        ev.names.pop(target.id, None)
            continue
        name = _call_name(node)
        try:
            if found is None and name == "Command":
                parts = _flat(ev.value(node.args[0] if node.args else node.keywords[0].value))
                call = _xacro_call("".join(map(str, parts)), {}, resolver, ev.loc(node), lines)
                found = call or found
            elif found is None and name == "process_file":
                model = Path(str(ev._arg(node, 0, "input_file_name")))
                mappings = {}
                for kw in node.keywords:
                    if kw.arg == "mappings":
                        mappings = {str(k): str(v) for k, v in ev.value(kw.value).items()}
                call = LaunchCall(model=model, mappings=mappings, loc=ev.loc(node))
                call.locs = {k: SourceLoc(ev.loc(node).file,
                                          _line_of(lines, node.lineno, f"'{k}'")
                                          if any(f"'{k}'" in ln for ln in lines)
                                          else _line_of(lines, node.lineno, f'"{k}"'))
                             for k in mappings}
                found = call
        except (_Unresolved, TypeError, AttributeError, IndexError):
            continue
    if found is not None and found.model is not None and _UNKNOWN in str(found.model):
        found.model = None
    for name in [k for k, v in (found.mappings.items() if found else ()) if _UNKNOWN in v]:
        del found.mappings[name]
        found.locs.pop(name, None)
    return found


def _call_name(node: ast.Call) -> str:
    func = node.func
    return func.attr if isinstance(func, ast.Attribute) else getattr(func, "id", "")


def _flat(value) -> list:
    if isinstance(value, list):
        return [item for v in value for item in _flat(v)]
    return [value]


# ----------------------------------------------------------------- api

def read_launch(path: Path, *, resolver: PackageResolver | None = None,
                package_paths: Sequence[Path] = (), given: dict[str, str] | None = None,
                depth: int = 0) -> LaunchCall:
    """The xacro call a launch file makes (following `<include>`s); ReedtoolError if none."""
    path = Path(path)
    resolver = resolver or PackageResolver(package_paths, model_path=path)
    if path.suffix == ".py":
        call = _read_python_launch(path, resolver)
    else:
        call = _read_xml_launch(path, dict(given or {}), resolver, depth)
    if call is None and depth == 0:
        raise ReedtoolError("no xacro call found in the launch file", file=_display(path),
                            hint="reedtool reads <param name=\"robot_description\" "
                                 "command=\"$(find xacro)/xacro ...\">, $(command 'xacro ...') "
                                 "and Command([... 'xacro' ...]); or give the arguments in "
                                 "[tool.reedtool] args")
    return call
