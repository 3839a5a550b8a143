"""What the paths on a command line mean: files, directories, globs, ROS packages.

pre-commit passes every changed file; CI passes a directory or a glob. Each target becomes
a list of model files:

- a file: itself when it is a model (issue 18: arguments mean "this model"). A xacro file
  given arguments (`name:=value`, `--launch`, a per-file table of the config) is validated
  as itself; without them, a file that expands alone (with the config's repository-wide
  `args`) into a robot with links is too. Only a file that
  cannot stand alone (a macro library, or a part that needs the arguments of the model
  that includes it) is checked through a model beside it that includes it, preferring one
  that loads; that model's failure is reported against it, naming the part;
- a configuration file (pyproject.toml with `[tool.reedtool]`, reedtool.toml): the models
  of its directory, since the xacro arguments it carries reach all of them (pre-commit
  passes it when it changes);
- a directory holding `model.sdf`: that SDF model;
- a ROS package (a directory with `package.xml`): the top-level models of its `urdf/`
  (and `models/`, `sdf/`, `worlds/` for SDF; with none of those, anywhere in it),
  skipping xacro macro libraries and worlds that hold no vehicle (only static models:
  the launch file spawns the robot);
- any other directory: the top-level models below it, recursively;
- a glob (`urdf/*.xacro`, `**/*.urdf`): the matching files, sorted.

A top-level model is one that a robot can be built from: its root is `<robot>` (or
`<sdf>`) and it does more than define macros, properties and arguments; a file that
another candidate includes is part of that model, not a model of its own. An include whose
file name uses an argument without a value (`$(arg mav_name)_base.xacro`) may include
every file its name matches, so `*_base.xacro` beside such a top file is a part of it.
A target that names nothing is an input error for that target alone.
"""

from __future__ import annotations

import fnmatch
import glob as globmod
import os
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Callable, Mapping, Sequence

from reedtool.errors import ReedtoolError

# Every model file a ROS/Gazebo package uses (`.urdf.xacro` ends in `.xacro`). RotorS keeps
# its top-level models in `.gazebo` files (mav_generic_odometry_sensor.gazebo includes
# <mav>_base.xacro); worlds are `.world`. .pre-commit-hooks.yaml matches the same list.
MODEL_SUFFIXES = (".urdf", ".xacro", ".gazebo", ".sdf", ".world")
PACKAGE_SUFFIXES = MODEL_SUFFIXES
# Files that xacro expands: a part of one of them may be checked through another.
XACRO_SUFFIXES = (".xacro", ".gazebo")
# Configuration files that carry xacro arguments (reedtool.config).
CONFIG_NAMES = ("pyproject.toml", "reedtool.toml")
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
    checked_for: str | None = None   # the named part this model is checked for (display)


def _xml_root(path: Path):
    """The file's root element (comments dropped, no entities, no network), or None where
    it is not readable XML: the loader reports that, with its line."""
    from lxml import etree

    try:
        return etree.parse(str(path), etree.XMLParser(remove_comments=True,
                                                      resolve_entities=False,
                                                      no_network=True)).getroot()
    except (etree.XMLSyntaxError, OSError):
        return None


def _root_and_children(path: Path) -> tuple[str | None, list[str]]:
    """The root tag and its element children's tags (prefix kept), without expanding."""
    from lxml import etree

    root = _xml_root(path)
    if root is None:
        return None, []

    def tag(el) -> str:
        qname = etree.QName(el)
        return f"{el.prefix}:{qname.localname}" if el.prefix else qname.localname

    return tag(root), [tag(c) for c in root if isinstance(c.tag, str)]


def is_macro_library(path: Path) -> bool:
    """A xacro file that only defines macros, properties and arguments (and includes)."""
    return _library_by_text(*_root_and_children(path))


def _library_by_text(root: str | None, children: list[str]) -> bool:
    if root is None:
        return False     # unreadable: let the loader report it
    if root not in ("robot", "sdf"):
        return True
    if root == "robot" and children and all(c == "gazebo" for c in children):
        return True     # only <gazebo> extensions: a fragment another file includes
    return bool(children) and all(c in _LIBRARY_CHILDREN for c in children)


def _includes_files(children: list[str]) -> bool:
    """The file includes others (so its expansion may hold links its own text lacks)."""
    return any(tag in ("include", "xacro:include") for tag in children)


def is_scene_world(path: Path) -> bool:
    """An SDF world with no vehicle in it: only static models, lights and systems, no
    `<include>` (the launch file spawns the robot into it, as `new-package` writes them).
    Found in a directory it is the stage, not a model; named on its own it is still read
    (and says it has no model)."""
    if path.suffix.lower() not in (".sdf", ".world"):
        return False
    root = _xml_root(path)
    if root is None:
        return False     # unreadable: let the loader report it
    worlds = root.findall("world")
    if root.tag != "sdf" or root.find("model") is not None or not worlds:
        return False
    for world in worlds:
        if world.find("include") is not None:
            return False
        for model in world.findall("model"):
            if (model.findtext("static") or "").strip().lower() not in ("true", "1"):
                return False
    return True


def _top_level(files: list[Path], include_tree: Callable[[Path], Sequence[Path]],
               include_globs: Callable[[Path], Sequence[str]] | None = None) -> list[Path]:
    candidates = [f for f in files if not is_macro_library(f) and not is_scene_world(f)]
    included: set[Path] = set()
    # Every file's includes count, a library's too: a file that only includes the vehicle
    # picked by `$(arg mav_name)` reads like a library and still makes it a part. SDF is
    # not xacro, and a .urdf is read as written: neither includes a xacro part.
    for file in files:
        if file.suffix.lower() not in (".sdf", ".world", ".urdf") and not _is_sdf_template(file):
            included.update(p.resolve() for p in include_tree(file)[1:])
            for pattern in (include_globs(file) if include_globs else ()):
                included.update(c.resolve() for c in candidates
                                if c != file and _matches(c, pattern))
    return [c for c in candidates if c.resolve() not in included]


def _matches(path: Path, pattern: str) -> bool:
    """Does `path` match an include pattern (a directory, then a file-name glob)?"""
    wanted = Path(pattern)
    try:
        return (path.resolve().parent == wanted.parent.resolve()
                and fnmatch.fnmatchcase(path.name, wanted.name))
    except OSError:
        return False


def _model_files(directory: Path, recursive: bool,
                 suffixes: Sequence[str] = MODEL_SUFFIXES) -> list[Path]:
    pattern = "**/*" if recursive else "*"
    return sorted(p for p in directory.glob(pattern)
                  if p.is_file() and (p.suffix.lower() in suffixes
                                      or (".sdf" in suffixes and _is_sdf_template(p)))
                  and not any(part.startswith(".") for part in p.relative_to(directory).parts))


def _template_model_dir(path: Path) -> bool:
    """A PX4 Classic model directory: model.config naming X.sdf, and X.sdf.jinja beside it."""
    if not (path / "model.config").is_file():
        return False
    from reedtool.resolve.resources import model_sdf_in_dir

    try:
        return _is_sdf_template(model_sdf_in_dir(path))
    except ReedtoolError:   # an unreadable model.config: the loader says what is wrong
        return False


def _is_sdf_template(path: Path) -> bool:
    """PX4's Classic models are `*.sdf.jinja` templates (io.sdf_jinja renders them); the
    `.sdf` a build renders beside one is the same model, and the template is what the
    user edits."""
    from reedtool.io.sdf_jinja import is_sdf_jinja

    return is_sdf_jinja(path)


# Neighbours larger than this are not followed: a model that includes a part is a small
# hand-written file, and a huge neighbour must not slow the check of the named one.
SIBLING_MAX_BYTES = 1024 * 1024


def _includers(path: Path, include_tree: Callable[[Path], Sequence[Path]],
               include_globs: Callable[[Path], Sequence[str]] | None = None) -> list[Path]:
    """The models in the same directory whose includes read `path`, top-level ones first
    (a `<mav>_base.xacro` that a .gazebo file picks by argument still includes its parts)."""
    key = path.resolve()
    siblings = [f for f in _model_files(path.parent, recursive=False,
                                        suffixes=PACKAGE_SUFFIXES)
                if f.resolve() != key and f.stat().st_size <= SIBLING_MAX_BYTES]
    includers = [sibling for sibling in siblings if not is_macro_library(sibling)
                 and key in {p.resolve() for p in include_tree(sibling)[1:]}]
    if len(includers) < 2:
        return includers       # nothing to order: the siblings' own models are not needed
    top = set(_top_level(siblings, include_tree, include_globs))
    return sorted(includers, key=lambda sibling: sibling not in top)


def _memo(function: Callable[[Path], Sequence]) -> Callable[[Path], Sequence]:
    cache: dict[Path, Sequence] = {}

    def cached(path: Path) -> Sequence:
        key = path.resolve()
        if key not in cache:
            cache[key] = function(path)
        return cache[key]

    return cached


def _never(_path: Path) -> bool:
    return False


def _not_excluded(_path: Path, _walked: Path | None) -> str | None:
    return None


def expand_targets(targets: Sequence[str], include_tree: Callable[[Path], Sequence[Path]],
                   display: Callable[[Path], str] = str, *,
                   include_globs: Callable[[Path], Sequence[str]] | None = None,
                   has_arguments: Callable[[Path], bool] = _never,
                   stands_alone: Callable[[Path], bool] = _never,
                   configures_models: Callable[[Path], bool] = _never,
                   excluded: Callable[[Path, Path | None], str | None] = _not_excluded
                   ) -> list[Target]:
    """Every model the targets name, in order, each once.

    `include_tree(path)` lists the files a xacro model reads (itself first); it decides
    which files of a directory are parts of another model. `include_globs(path)` adds the
    includes whose file names use an argument without a value, as glob patterns.
    `has_arguments(path)`: the user gave this file arguments (command line, --launch or a
    per-file table of the config). `stands_alone(path)`: the file loads alone into a robot
    with links (the caller may keep what it loaded). `configures_models(path)`: the file is
    a reedtool configuration (its directory's models are checked when it changes).
    `excluded(path, walked)`: why a file found walking directory `walked` (None: a file
    named on the command line) is left out, or None (the configuration's `exclude`).
    """
    include_tree = _memo(include_tree)
    include_globs = _memo(include_globs) if include_globs is not None else None
    out: list[Target] = []
    seen: set[Path] = set()

    def add(path: Path, checked_for: str | None = None) -> None:
        key = path.resolve()
        if key not in seen:
            seen.add(key)
            out.append(Target(display(path), path, checked_for=checked_for))

    def add_directory(path: Path, raw: str) -> None:
        if (path / "package.xml").is_file():
            files = [f for sub in PACKAGE_MODEL_DIRS if (path / sub).is_dir()
                     for f in _model_files(path / sub, recursive=sub != "urdf",
                                           suffixes=PACKAGE_SUFFIXES)]
            if not files:
                # Models kept elsewhere in the package (ntnu-arl's rmf_gz: resources/).
                files = _model_files(path, recursive=True, suffixes=PACKAGE_SUFFIXES)
        else:
            files = _model_files(path, recursive=True)
        templates = {f.with_name(f.name[:-len(".jinja")]) for f in files if _is_sdf_template(f)}
        files = [f for f in files if f not in templates]
        files = [f for f in files if excluded(f, path) is None]
        models = _top_level(files, include_tree, include_globs)
        if not models:
            out.append(Target(raw, None, "no model file (" + ", ".join(MODEL_SUFFIXES)
                              + ") found in this directory"))
        for model in models:
            add(model)

    def add_file(path: Path) -> None:
        why = excluded(path, None)
        if why is not None:
            out.append(Target(display(path), None, skipped=why))
            return
        xacro = path.is_file() and path.suffix.lower() in XACRO_SUFFIXES
        includers = _includers(path, include_tree, include_globs) if xacro else []
        root, children = _root_and_children(path) if xacro else (None, [])
        library = xacro and _library_by_text(root, children)
        if library:
            # A library that includes itself breaks every model that includes it: an
            # error with the chain, not a skip.
            from reedtool.io.xacro_expand import include_cycle

            cycle = include_cycle(path)
            if cycle is not None:
                chain = " -> ".join(p.name for p in cycle)
                out.append(Target(display(path), None,
                                  error=f"include cycle: {chain} (remove one of the "
                                        "includes; a file cannot include itself)"))
                return
        if library and (has_arguments(path)
                        or (_includes_files(children) and stands_alone(path))):
            # Only includes by its text, but the user gave it arguments, or the files it
            # includes lay out a robot when it is expanded alone (hector's
            # quadrotor.gazebo.xacro): a model, judged by its expansion.
            add(path)
            return
        if library and not includers:
            # pre-commit passes every changed file: a macro library has no robot of its
            # own; the models that include it are where its mistakes show.
            out.append(Target(display(path), None, skipped="a xacro macro library (no "
                              "robot of its own); validate the models that include it"))
            return
        if not library and (not includers or has_arguments(path) or stands_alone(path)):
            add(path)     # a device or a pipe too: the loader says what is wrong with it
            return
        # A part that cannot stand alone: checked in a model that includes it, one that
        # loads if there is one, so a broken sibling does not stand in for the part.
        includer = next((i for i in includers if stands_alone(i)), includers[0])
        out.append(Target(display(path), None,
                          skipped=f"part of {display(includer)}, checked through it"))
        add(includer, checked_for=display(path))

    for raw in targets:
        path = Path(raw)
        if path.is_file() and path.name == "package.xml":
            # The manifest names the package; its models are in the directory beside it.
            out.append(Target(display(path), None, error=PACKAGE_XML_MESSAGE.format(
                directory=display(path.parent) if str(path.parent) != "." else ".")))
        elif path.is_file() and path.name in CONFIG_NAMES:
            if configures_models(path):
                add_directory(path.parent, raw)
            else:
                out.append(Target(display(path), None, skipped="not a model, and no "
                                  "reedtool configuration in it"))
        elif path.exists() and not path.is_dir():
            add_file(path)
        elif path.is_dir():
            if (path / "model.sdf").is_file() or _template_model_dir(path):
                add(path)
            else:
                add_directory(path, raw)
        elif _GLOB_CHARS.search(raw):
            matches = sorted(Path(m) for m in globmod.glob(raw, recursive=True))
            files = [m for m in matches if m.is_file()]
            if not files:
                out.append(Target(raw, None, "no file matches this pattern"))
            for match in files:
                why = excluded(match, None)
                if why is not None:
                    out.append(Target(display(match), None, skipped=why))
                else:
                    add(match)
        else:
            out.append(Target(raw, None, not_found_message(raw)))
    return out


PACKAGE_XML_MESSAGE = ("package.xml is the package's manifest, not a model; pass the package "
                       "directory: reedtool validate {directory}")


def not_found_message(word: str) -> str:
    """"file not found", and what the word looks like it meant: an argument without `:=`,
    or a file or directory whose name is close to it."""
    from reedtool.resolve.mappings import suggest_mapping

    suggestion = suggest_mapping(word)
    if suggestion is not None:
        return (f"file not found; xacro arguments are written name:=value: did you mean "
                f"'{suggestion}'?")
    nearby = suggest_path(word)
    if nearby is not None:
        return f"file not found; did you mean '{nearby}'?"
    return "file not found"


def suggest_path(word: str) -> str | None:
    """The existing path nearest a mistyped one, component by component from the deepest
    directory that exists (`urdf/mav_generic_odometry_sensr.gazebo` ->
    `urdf/mav_generic_odometry_sensor.gazebo`), or None when no name is close."""
    from difflib import get_close_matches

    path = Path(word)
    parts = path.parts
    if not parts:
        return None
    # The longest prefix that exists; every component after it gets its nearest name.
    start = 0
    base = Path(parts[0]) if path.is_absolute() else Path(".")
    if path.is_absolute():
        start = 1
    while start < len(parts) and (base / parts[start]).exists():
        base, start = base / parts[start], start + 1
    if start == len(parts):
        return None        # it exists (a race, or a dangling link): nothing to suggest
    for part in parts[start:]:
        try:
            names = sorted(entry.name for entry in base.iterdir()
                           if not entry.name.startswith("."))
        except OSError:
            return None
        # 0.75: a slip or two in a name (`sensr`, `urfd`), not another file of the same
        # pattern (`missing.urdf` is 0.52 from `broken.urdf`).
        close = get_close_matches(part, names, n=1, cutoff=0.75)
        if not close:
            return None
        base = base / close[0]
    return str(base) if path.is_absolute() else os.path.normpath(str(base))


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


_ARG = re.compile(r"\$\(\s*arg\s+([^)\s]+)\s*\)")
_FIND = re.compile(r"\$\(\s*find\s+([^)\s]+)\s*\)")


def include_globs_of(mappings_for: Callable[[Path], Mapping[str, str]],
                     package_paths: Sequence[Path]) -> Callable[[Path], Sequence[str]]:
    """An `include_globs` for expand_targets: includes of a file (its own, not followed)
    whose names use an argument without a value, that argument read as `*`. RotorS's
    `$(find pkg)/urdf/$(arg mav_name)_base.xacro` becomes `.../urdf/*_base.xacro`."""

    def globs(path: Path) -> Sequence[str]:
        from reedtool.io.legacy_xacro import include_specs
        from reedtool.resolve.packages import PackageResolver

        try:
            text = path.read_text(encoding="utf-8")
        except (OSError, UnicodeDecodeError):
            return []
        mappings = dict(mappings_for(path))
        resolver = PackageResolver(package_paths, model_path=path)
        out = []
        for spec in include_specs(text):
            names = _ARG.findall(spec)
            if not any(name not in mappings for name in names):
                continue     # resolved exactly, or not at all, by the include tree
            try:
                pattern = _FIND.sub(lambda m: str(resolver.find(m.group(1))), spec)
            except Exception:  # noqa: BLE001 - an unknown package: nothing to match
                continue
            pattern = _ARG.sub(lambda m: mappings.get(m.group(1), "*"), pattern)
            if "$" in pattern or not Path(pattern).name.replace("*", ""):
                continue     # other substitutions, or a name that is only a wildcard
            full = Path(pattern) if Path(pattern).is_absolute() else path.parent / pattern
            out.append(str(full))
        return out

    return globs
