"""Where a model's file reference may point: not out of its package, not into a system
directory, not to one machine's absolute path; and whether a resolved file lies inside the
model's own packages (the ROS package or Gazebo model directory holding it).

Used by validate's mesh rules, migrate (which files travel with a port) and the view.
Pure path arithmetic on the reference's text and the resolved path: nothing is read.
"""

from __future__ import annotations

from pathlib import Path

# Where no model's mesh belongs: reading them is a leak (a model shared as a package that
# makes the simulator open /etc/passwd), and they hold no mesh anyway. Deliberately short:
# workspaces do live under /root, /var/lib/jenkins, /opt or /usr/share.
SYSTEM_DIRS = ("/etc", "/proc", "/sys", "/dev", "/boot", "/bin", "/sbin", "/usr/bin",
               "/usr/sbin")


def _package_relative(text: str) -> tuple[bool, str | None]:
    """(whether `text` is a `package://` or `model://` path, the path within the package
    when it climbs out of it with `..` or starts at `/`, else None)."""
    import posixpath

    for scheme in ("package://", "model://"):
        if text.startswith(scheme):
            _name, _, rel = text[len(scheme):].partition("/")
            normal = posixpath.normpath(rel) if rel else ""
            climbs = normal == ".." or normal.startswith("../") or rel.startswith("/")
            return True, rel if climbs else None
    return False, None


def uri_problem(uri: str, path: Path | None = None) -> str | None:
    """Why a mesh reference must not be followed, or None.

    A `package://` or `model://` path that climbs out of its package with `..`, and any
    reference (`file://`, absolute, or what a package path resolves to) inside a system
    directory.
    """
    import posixpath
    from urllib.parse import unquote, urlparse

    text = unquote(uri.strip())
    _package_path, climbing = _package_relative(text)
    if climbing is not None:
        return f"the path climbs out of its package ('{climbing}')"
    if text.startswith("file://"):
        text = urlparse(text).path
    candidates = [posixpath.normpath(text)] if text.startswith("/") else []
    if path is not None:
        candidates.append(posixpath.normpath(str(path)))
    for candidate in candidates:
        for system in SYSTEM_DIRS:
            if candidate == system or candidate.startswith(system + "/"):
                return f"it points into the system directory {system}"
    return None


def machine_path(uri: str) -> str | None:
    """The absolute path an absolute `file://` URI or plain absolute path names, else None
    (`package://`, `model://`, relative paths and URLs travel with the model)."""
    from urllib.parse import unquote, urlparse

    text = unquote(uri.strip())
    if text.startswith("file://"):
        text = urlparse(text).path
    return text if text.startswith("/") else None


# ------------------------------------------------------------ files from outside

# What marks the root of a model's own files: a ROS package or a Gazebo model directory.
PACKAGE_MARKERS = ("package.xml", "model.config")


def package_root(file: str | Path) -> Path | None:
    """The ROS package or Gazebo model directory holding `file` (the nearest ancestor with
    a package.xml or model.config), None when there is none."""
    for directory in Path(file).resolve().parents:
        if any((directory / marker).is_file() for marker in PACKAGE_MARKERS):
            return directory
    return None


def outside_reason(uri: str, path: Path | None, referencing_file: str | Path,
                   default_root: Path) -> str | None:
    """Why the mesh file `path` (resolved from `uri`, named in `referencing_file`) lies
    outside the model's packages, or None when it is one of the model's own files.

    `package://` and `model://` references stay inside the package they name unless they
    climb out of it with `..`; any other reference (absolute, `file://`, relative) is
    inside when the file lies in the package or model directory of the file naming it,
    else in `default_root` (the model directory the user gave)."""
    from urllib.parse import unquote

    if path is None:
        return None
    text = unquote(uri.strip())
    package_path, climbing = _package_relative(text)
    if climbing is not None:
        return f"'{uri}' climbs out of its package"
    if package_path:
        return None
    root = package_root(referencing_file) or Path(default_root).resolve()
    real = Path(path).resolve()
    if real == root or root in real.parents:
        return None
    how = "an absolute reference" if text.startswith(("file://", "/")) else \
        "a relative path that climbs out"
    return f"{how} to {real}, outside the model's package {root}"
