"""What the paths on a command line mean: files, directories, globs, ROS packages.

pre-commit passes every changed file; CI passes a directory or a glob. Each target becomes
a list of model files:

- a file: itself, unless it is a xacro part that a model beside it includes (pre-commit
  passes the changed part alone): then that model, which is what the part is checked in;
- a directory holding `model.sdf`: that SDF model;
- a ROS package (a directory with `package.xml`): the top-level models of its `urdf/`
  (and `models/`, `sdf/` for SDF), skipping xacro macro libraries;
- any other directory: the top-level models below it, recursively;
- a glob (`urdf/*.xacro`, `**/*.urdf`): the matching files, sorted.

A top-level model is one that a robot can be built from: its root is `<robot>` (or
`<sdf>`) and it does more than define macros, properties and arguments; a file that
another candidate includes is part of that model, not a model of its own.
A target that names nothing is an input error for that target alone.
"""

from __future__ import annotations

import glob as globmod
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Callable, Mapping, Sequence

MODEL_SUFFIXES = (".urdf", ".xacro", ".sdf", ".world")
# In a package, RotorS keeps its top-level models in `.gazebo` files (mav_generic_odometry_
# sensor.gazebo includes <mav>_base.xacro), so a package's urdf/ is searched for them too.
PACKAGE_SUFFIXES = (*MODEL_SUFFIXES, ".gazebo")
PACKAGE_MODEL_DIRS = ("urdf", "models", "sdf", "worlds")
_GLOB_CHARS = re.compile(r"[*?\[]")
_LIBRARY_CHILDREN = {"macro", "property", "arg", "include", "xacro:macro", "xacro:property",
                     "xacro:arg", "xacro:include"}


@dataclass(frozen=True)
class Target:
    """One model to check, or a target that named none (`error`)."""

    name: str                # as shown to the user
    path: Path | None
    error: str | None = None
    skipped: str | None = None   # why a named file is not checked (a macro library)


def _root_and_children(path: Path) -> tuple[str | None, list[str]]:
    """The root tag and its element children's tags (prefix kept), without expanding."""
    from lxml import etree

    try:
        root = etree.parse(str(path), etree.XMLParser(remove_comments=True,
                                                     resolve_entities=False,
                                                     no_network=True)).getroot()
    except (etree.XMLSyntaxError, OSError):
        return None, []

    def tag(el) -> str:
        qname = etree.QName(el)
        return f"{el.prefix}:{qname.localname}" if el.prefix else qname.localname

    return tag(root), [tag(c) for c in root if isinstance(c.tag, str)]


def is_macro_library(path: Path) -> bool:
    """A xacro file that only defines macros, properties and arguments (and includes)."""
    root, children = _root_and_children(path)
    if root is None:
        return False     # unreadable: let the loader report it
    if root not in ("robot", "sdf"):
        return True
    return bool(children) and all(c in _LIBRARY_CHILDREN for c in children)


def _top_level(files: list[Path], include_tree: Callable[[Path], Sequence[Path]]) -> list[Path]:
    candidates = [f for f in files if not is_macro_library(f)]
    included: set[Path] = set()
    for candidate in candidates:
        # SDF is not xacro, and a .urdf is read as written: neither includes a xacro part.
        if candidate.suffix.lower() not in (".sdf", ".world", ".urdf"):
            included.update(p.resolve() for p in include_tree(candidate)[1:])
    return [c for c in candidates if c.resolve() not in included]


def _model_files(directory: Path, recursive: bool,
                 suffixes: Sequence[str] = MODEL_SUFFIXES) -> list[Path]:
    pattern = "**/*" if recursive else "*"
    return sorted(p for p in directory.glob(pattern)
                  if p.is_file() and p.suffix.lower() in suffixes
                  and not any(part.startswith(".") for part in p.relative_to(directory).parts))


# Neighbours larger than this are not followed: a model that includes a part is a small
# hand-written file, and a huge neighbour must not slow the check of the named one.
SIBLING_MAX_BYTES = 1024 * 1024


def _includer(path: Path, include_tree: Callable[[Path], Sequence[Path]]) -> Path | None:
    """A top-level model in the same directory whose includes read `path`, if any."""
    key = path.resolve()
    siblings = [f for f in _model_files(path.parent, recursive=False,
                                        suffixes=PACKAGE_SUFFIXES)
                if f.resolve() != key and f.stat().st_size <= SIBLING_MAX_BYTES]
    for sibling in _top_level(siblings, include_tree):
        if key in {p.resolve() for p in include_tree(sibling)[1:]}:
            return sibling
    return None


def expand_targets(targets: Sequence[str], include_tree: Callable[[Path], Sequence[Path]],
                   display: Callable[[Path], str] = str) -> list[Target]:
    """Every model the targets name, in order, each once.

    `include_tree(path)` lists the files a xacro model reads (itself first); it decides
    which files of a directory are parts of another model.
    """
    out: list[Target] = []
    seen: set[Path] = set()

    def add(path: Path) -> None:
        key = path.resolve()
        if key not in seen:
            seen.add(key)
            out.append(Target(display(path), path))

    for raw in targets:
        path = Path(raw)
        if path.exists() and not path.is_dir():
            if path.is_file() and path.suffix.lower() == ".xacro" and is_macro_library(path):
                # pre-commit passes every changed file: a macro library has no robot of its
                # own; the models that include it are where its mistakes show.
                out.append(Target(display(path), None, skipped="a xacro macro library (no "
                                  "robot of its own); validate the models that include it"))
                continue
            includer = (_includer(path, include_tree)
                        if path.is_file() and path.suffix.lower() == ".xacro" else None)
            if includer is not None:
                out.append(Target(display(path), None,
                                  skipped=f"part of {display(includer)}, checked through it"))
                add(includer)
                continue
            add(path)     # a device or a pipe too: the loader says what is wrong with it
        elif path.is_dir():
            if (path / "model.sdf").is_file():
                add(path)
                continue
            if (path / "package.xml").is_file():
                files = [f for sub in PACKAGE_MODEL_DIRS if (path / sub).is_dir()
                         for f in _model_files(path / sub, recursive=sub != "urdf",
                                               suffixes=PACKAGE_SUFFIXES)]
            else:
                files = _model_files(path, recursive=True)
            models = _top_level(files, include_tree)
            if not models:
                out.append(Target(raw, None, "no .urdf, .xacro or .sdf model found in this "
                                             "directory"))
            for model in models:
                add(model)
        elif _GLOB_CHARS.search(raw):
            matches = sorted(Path(m) for m in globmod.glob(raw, recursive=True))
            files = [m for m in matches if m.is_file()]
            if not files:
                out.append(Target(raw, None, "no file matches this pattern"))
            for match in files:
                add(match)
        else:
            out.append(Target(raw, None, "file not found"))
    return out


def include_tree_of(mappings_for: Callable[[Path], Mapping[str, str]],
                    package_paths: Sequence[Path]) -> Callable[[Path], Sequence[Path]]:
    """An `include_tree` for expand_targets, following includes statically."""

    def tree(path: Path) -> Sequence[Path]:
        # Only directories and parts need it; a single model does not import xacro for it.
        from reedtool.io.xacro_expand import include_texts

        try:
            return list(include_texts(path, dict(mappings_for(path)), package_paths)) or [path]
        except Exception:  # noqa: BLE001 - a broken file is reported when it is loaded
            return [path]

    return tree
