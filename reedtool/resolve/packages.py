"""Find ROS packages and resolve `package://` URIs without ROS.

A package is a directory whose package.xml declares that <name>. Roots are searched in
the order ROS users expect (issue 2, item 4):

1. `--package-path` directories,
2. `ROS_PACKAGE_PATH` entries (catkin workspaces, roslib's search path),
3. `AMENT_PREFIX_PATH` prefixes, as `<prefix>/share/<pkg>` (ament's install layout),
4. the package that contains the model (walk up from the model file to a package.xml),
5. reedtool's bundled packages (reedtool/ros_packages), last, so a real
   rotors_description anywhere earlier always wins.

Each root may itself be a package or hold packages a few levels down (a catkin `src/`
with `repo/pkg/package.xml`). Like rospack, the crawl stops descending at a package,
skips hidden directories and honours CATKIN_IGNORE/COLCON_IGNORE/AMENT_IGNORE markers.
"""

from __future__ import annotations

import contextlib
import functools
import os
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path
from typing import Sequence
from urllib.parse import unquote, urlparse

from reedtool.errors import ReedtoolError
from reedtool.model import SourceLoc

BUNDLED_PACKAGES_DIR = Path(__file__).resolve().parents[1] / "ros_packages"

# How deep below a root a package.xml is looked for: root/src/repo/group/pkg is 4.
MAX_CRAWL_DEPTH = 5
# How many directories one root may make us visit: a workspace has hundreds; `/` has
# millions, and scanning them silently took seconds (issue 14). Past this, stop and say so.
MAX_CRAWL_DIRS = 20_000
_IGNORE_MARKERS = ("CATKIN_IGNORE", "COLCON_IGNORE", "AMENT_IGNORE")


@dataclass(frozen=True)
class SearchRoot:
    origin: str        # why this root is searched, e.g. "--package-path", "ROS_PACKAGE_PATH"
    path: Path
    ament: bool = False  # an AMENT_PREFIX_PATH prefix: packages live in <prefix>/share/<pkg>

    def describe(self) -> str:
        where = self.path / "share" if self.ament else self.path
        return f"{where} ({self.origin})"


def package_name(package_xml: Path) -> str | None:
    """The <name> a package.xml declares, or None when it cannot be read."""
    try:
        root = ET.parse(package_xml).getroot()
    except (ET.ParseError, OSError):
        return None
    name = root.findtext("name")
    return name.strip() if name else None


def enclosing_package(path: Path) -> Path | None:
    """The nearest directory at or above `path` that holds a package.xml."""
    path = Path(path).resolve()
    for candidate in [path, *path.parents] if path.is_dir() else path.parents:
        if (candidate / "package.xml").is_file():
            return candidate
    return None


def is_bundled(path: str | Path) -> bool:
    """True for files of reedtool's own bundled packages (never the user's to edit)."""
    return _is_bundled(str(path), os.getcwd())


@functools.lru_cache(maxsize=1024)
def _is_bundled(path: str, cwd: str) -> bool:
    # Asked for every expanded element about a handful of files; resolve() is a syscall chain.
    try:
        (Path(cwd) / path).resolve().relative_to(BUNDLED_PACKAGES_DIR)
    except ValueError:
        return False
    return True


def _is_dir(entry: os.DirEntry) -> bool:
    try:
        return entry.is_dir()
    except OSError:
        return False


def bundled_package_names() -> set[str]:
    """Names of the packages reedtool bundles (a new package must not shadow them)."""
    return set(_crawl(BUNDLED_PACKAGES_DIR))


def _same_directory(a: Path, b: Path) -> bool:
    """Whether two paths are one directory on disk (symlinks resolved)."""
    try:
        return os.path.samefile(a, b)
    except OSError:
        return os.path.realpath(a) == os.path.realpath(b)


def _crawl(root: Path, duplicates: list[tuple[str, Path, Path]] | None = None,
           origin: str = "") -> dict[str, Path]:
    """All packages under `root` (root included), first found per name wins."""
    found: dict[str, Path] = {}
    if not root.is_dir():
        return found
    visited = [0]

    def visit(directory: Path, depth: int) -> None:
        visited[0] += 1
        if visited[0] > MAX_CRAWL_DIRS:
            raise ReedtoolError(f"searching {origin or 'a package root'} {root} for packages "
                                f"visited more than {MAX_CRAWL_DIRS} directories; stopped",
                                hint="point --package-path (or ROS_PACKAGE_PATH) at a "
                                     "workspace's src directory, not a whole filesystem")
        # One directory listing per visit (scandir's entry types need no extra stat).
        try:
            with os.scandir(directory) as listing:
                entries = list(listing)
        except OSError:
            return
        names = {entry.name: entry for entry in entries}
        if any(marker in names for marker in _IGNORE_MARKERS):
            return
        manifest = names.get("package.xml")
        if manifest is not None and manifest.is_file():
            name = package_name(directory / "package.xml")
            if name:
                # One directory reached twice (an install space's share/ symlinked to the
                # sources) is one package, not two of the same name.
                if name in found and duplicates is not None \
                        and not _same_directory(found[name], directory):
                    duplicates.append((name, found[name], directory))
                found.setdefault(name, directory)
            return  # packages do not nest (rospack/catkin rule)
        if depth >= MAX_CRAWL_DEPTH:
            return
        children = sorted(Path(entry.path) for entry in entries
                          if not entry.name.startswith(".") and _is_dir(entry))
        for child in children:
            visit(child, depth + 1)

    visit(root, 0)
    return found


# Within one run (`shared_crawls()`), each search root is crawled once: a repository's
# models are resolved against the same roots, and a workspace holds hundreds of packages.
_crawls: dict[tuple[str, str], tuple[dict[str, Path], list]] | None = None


@contextlib.contextmanager
def shared_crawls():
    """Share package crawls between the resolvers created inside (one command's run)."""
    global _crawls
    outer = _crawls
    if outer is None:
        _crawls = {}
    try:
        yield
    finally:
        if outer is None:
            _crawls = None


def _crawl_root(root: SearchRoot) -> tuple[dict[str, Path], list[tuple[str, Path, Path]]]:
    key = (str(root.path.absolute()), root.origin)
    if _crawls is not None and key in _crawls:
        return _crawls[key]
    duplicates: list[tuple[str, Path, Path]] = []
    found = _crawl(root.path, duplicates, root.origin)
    if _crawls is not None:
        _crawls[key] = (found, duplicates)
    return found, duplicates


class PackageResolver:
    """Resolves package names and mesh/include URIs the way ROS would, without ROS."""

    def __init__(self, package_paths: Sequence[Path] = (), model_path: Path | None = None):
        self.package_paths = [Path(p) for p in package_paths]
        for directory in self.package_paths:
            if not directory.is_dir():
                raise ReedtoolError("--package-path directory " + (
                    "not found" if not directory.exists() else "is not a directory"),
                    file=directory, hint="check the path")
        self.notes: list[str] = []   # e.g. two packages with one name: which one is used
        # (name, used directory, ignored directory, where both were found)
        self.duplicates: list[tuple[str, Path, Path, str]] = []
        self.model_path = Path(model_path) if model_path is not None else None
        self._roots: list[SearchRoot] | None = None
        self._index: dict[SearchRoot, dict[str, Path]] = {}
        self._found: dict[str, Path] = {}

    # ------------------------------------------------------------ roots
    @property
    def roots(self) -> list[SearchRoot]:
        if self._roots is None:
            self._roots = self._search_roots()
        return self._roots

    def _search_roots(self) -> list[SearchRoot]:
        roots = [SearchRoot("--package-path", p) for p in self.package_paths]
        for entry in os.environ.get("ROS_PACKAGE_PATH", "").split(os.pathsep):
            if entry:
                roots.append(SearchRoot("ROS_PACKAGE_PATH", Path(entry)))
        for entry in os.environ.get("AMENT_PREFIX_PATH", "").split(os.pathsep):
            if entry:
                roots.append(SearchRoot("AMENT_PREFIX_PATH", Path(entry), ament=True))
        if self.model_path is not None:
            own = enclosing_package(self.model_path)
            if own is not None:
                roots.append(SearchRoot("package containing the model", own))
        roots.append(SearchRoot("bundled with reedtool", BUNDLED_PACKAGES_DIR))
        return roots

    def _lookup(self, root: SearchRoot, name: str) -> Path | None:
        if root.ament:
            candidate = root.path / "share" / name
            manifest = candidate / "package.xml"
            if manifest.is_file() and package_name(manifest) == name:
                return candidate
            return None
        if root not in self._index:
            self._index[root], duplicates = _crawl_root(root)
            for dup_name, used, ignored in duplicates:
                self.duplicates.append((dup_name, used, ignored, root.describe()))
                self.notes.append(f"two packages named '{dup_name}' under {root.describe()}: "
                                  f"using {used}, ignoring {ignored}")
        return self._index[root].get(name)

    # ------------------------------------------------------------ api
    @property
    def resolved_names(self) -> set[str]:
        """The packages this resolver has found so far (those a model read)."""
        return set(self._found)

    def find(self, name: str, *, requested_by: SourceLoc | None = None) -> Path:
        """The directory of package `name`; ReedtoolError naming what was searched."""
        if name in self._found:
            return self._found[name]
        for root in self.roots:
            hit = self._lookup(root, name)
            if hit is not None:
                hit = hit.absolute()   # xacro reads relative paths against the including file
                self._found[name] = hit
                return hit
        searched = "; ".join(root.describe() for root in self.roots)
        raise ReedtoolError(
            f"package '{name}' not found; searched {searched}",
            file=requested_by.file if requested_by else None,
            line=requested_by.line if requested_by else None,
            hint="add the directory that contains it with --package-path DIR")

    def resolve_uri(self, uri: str, base_dir: Path, *,
                    requested_by: SourceLoc | None = None) -> Path:
        """Map a URDF/xacro file reference to a path. Existence is the caller's check.

        Handles package://pkg/rel, file:///abs, absolute and relative (to `base_dir`) paths.
        """
        uri = uri.strip()
        if uri.startswith("package://"):
            rest = uri[len("package://"):]
            name, _, rel = rest.partition("/")
            if not name:
                raise ReedtoolError(f"malformed package URI '{uri}'",
                                    file=requested_by.file if requested_by else None,
                                    line=requested_by.line if requested_by else None,
                                    hint="write package://PACKAGE/relative/path")
            return self.find(name, requested_by=requested_by) / unquote(rel)
        if uri.startswith("file://"):
            return Path(unquote(urlparse(uri).path))
        if "://" in uri:
            scheme = uri.split("://", 1)[0]
            raise ReedtoolError(f"unsupported URI scheme '{scheme}://' in '{uri}'",
                                file=requested_by.file if requested_by else None,
                                line=requested_by.line if requested_by else None,
                                hint="use package://, file:// or a file path")
        path = Path(uri)
        return path if path.is_absolute() else Path(base_dir) / path
