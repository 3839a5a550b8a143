"""Render a template tree into a new directory: all of it, or none of it.

Conventions, after cookiecutter:
- a template set is a directory under the templates root; every path segment is itself a
  jinja2 template (`urdf/{{ name }}.xacro.j2` -> `urdf/reed_gazebo.xacro`);
- files ending in `.j2` are rendered (StrictUndefined: an undefined variable is an error,
  never an empty string) and lose the suffix; every other file is copied byte for byte,
  so binary files (meshes, images) are never run through the template engine;
- directories and files whose name starts with `_` are partials for `{% include %}`, not
  output.

Writing is all-or-nothing: the whole tree is rendered in memory, written into a hidden
temporary directory beside the target, then renamed into place. Without `force`, a
target that exists and is not empty is refused before anything is written. With `force`,
the new tree is the old one with the generated files laid over it (files reedtool does
not generate are kept), and the swap is two renames: the old tree is kept whole as
`NAME.bak` (or `NAME.bak.1`, ...) beside it, so nothing is ever deleted.
"""

from __future__ import annotations

import contextlib
import os
import shutil
import tempfile
from dataclasses import dataclass
from pathlib import Path, PurePosixPath
from typing import Mapping

from reedtool.errors import ReedtoolError, os_error
from reedtool.io.fileio import current_umask, free_backup_name

TEMPLATE_SUFFIX = ".j2"


def templates_root() -> Path:
    """The templates directory: bundled in a wheel, or the repository's in a checkout.

    pyproject force-includes `templates/` as `reedtool/_data/templates` in the wheel; an
    editable or source checkout has it at the repository root next to `reedtool/`.
    """
    package_dir = Path(__file__).resolve().parents[1]
    for candidate in (package_dir / "_data" / "templates", package_dir.parent / "templates"):
        if (candidate / "ros1").is_dir():
            return candidate
    raise ReedtoolError("reedtool's package templates are missing from this installation",
                        file=package_dir, hint="reinstall reedtool")


@dataclass(frozen=True)
class RenderedFile:
    path: PurePosixPath        # relative to the package root
    data: bytes
    mode: int                  # permission bits, from the template file


def _environment(root: Path):
    import jinja2

    return jinja2.Environment(
        loader=jinja2.FileSystemLoader(str(root)),
        undefined=jinja2.StrictUndefined,
        keep_trailing_newline=True,
        trim_blocks=True,
        lstrip_blocks=True,
        # package.xml carries the user's description and maintainer: "&" or "<" there
        # must be escaped, or the manifest is not XML. Other templates hold only checked
        # names and numbers, and are not all XML (CMake, Python, Markdown).
        autoescape=jinja2.select_autoescape(enabled_extensions=("xml.j2",),
                                            default_for_string=False, default=False),
    )


def render_tree(template_dirs: list[str], context: Mapping[str, object],
                root: Path | None = None) -> list[RenderedFile]:
    """Render every file of the given template sets (later sets override earlier ones)."""
    import jinja2

    root = root or templates_root()
    env = _environment(root)
    out: dict[PurePosixPath, RenderedFile] = {}
    for template_dir in template_dirs:
        base = root / template_dir
        if not base.is_dir():
            raise ValueError(f"no template set '{template_dir}' under {root}")
        for src in sorted(base.rglob("*")):
            rel = src.relative_to(base)
            if src.is_dir() or any(part.startswith("_") for part in rel.parts) \
                    or src.name == ".keep":
                continue
            try:
                rel_out = PurePosixPath(*(env.from_string(part).render(context)
                                          for part in rel.parts))
                if src.name.endswith(TEMPLATE_SUFFIX):
                    rel_out = rel_out.with_name(rel_out.name[:-len(TEMPLATE_SUFFIX)])
                    template = env.get_template(PurePosixPath(template_dir, *rel.parts).as_posix())
                    data = template.render(context).encode("utf-8")
                else:
                    data = src.read_bytes()
            except jinja2.TemplateError as exc:
                # A template bug, not a user mistake: say which template, loudly.
                raise RuntimeError(f"template {template_dir}/{rel}: {exc}") from exc
            out[rel_out] = RenderedFile(rel_out, data, src.stat().st_mode & 0o777)
    return [out[key] for key in sorted(out)]


# ------------------------------------------------------------------ writing

def check_target(target: Path, force: bool, *,
                 force_does: str = "regenerate it; the old tree is kept as NAME.bak") -> None:
    """Refuse a target directory we must not touch, before any work is done; `force_does`
    says what --force would do to it."""
    if target.is_symlink() or (target.exists() and not target.is_dir()):
        raise ReedtoolError("target exists and is not a directory", file=target,
                            hint="choose another name or -o directory")
    if target.is_dir() and any(target.iterdir()) and not force:
        raise ReedtoolError("target directory exists and is not empty", file=target,
                            hint=f"choose another name or -o directory, or pass --force to "
                                 f"{force_does}")


def write_tree(target: Path, files: list[RenderedFile], *, force: bool = False) -> Path | None:
    """Write `files` as the directory `target`, atomically. Returns the backup dir, if any."""
    with staged_tree(target, files, force=force) as staged:
        pass
    return staged.backup


@dataclass
class StagedTree:
    path: Path                 # the hidden directory holding the new tree until the swap
    backup: Path | None = None


@contextlib.contextmanager
def staged_tree(target: Path, files: list[RenderedFile], *, force: bool = False):
    """Stage `files` as the new tree of `target` in a hidden directory beside it, let the
    caller look at it (migrate reads its port back there), then swap it into place. If the
    caller raises, the staging directory is removed and `target` is untouched."""
    target = Path(target).absolute()
    check_target(target, force)
    parent = target.parent
    created = [p for p in (parent, *parent.parents) if not p.exists()]
    try:
        parent.mkdir(parents=True, exist_ok=True)
        staging = Path(tempfile.mkdtemp(prefix=f".{target.name}.", suffix=".reedtool-tmp",
                                        dir=parent))
    except OSError as exc:
        raise os_error(exc, parent, action="create a directory in") from exc
    replacing = target.is_dir() and any(target.iterdir())
    staged = StagedTree(staging)
    swapped = False
    try:
        try:
            if replacing:
                # Start from a copy of the old tree so files reedtool does not generate survive.
                shutil.rmtree(staging)
                shutil.copytree(target, staging, symlinks=True)
            for item in files:
                dest = staging.joinpath(*item.path.parts)
                dest.parent.mkdir(parents=True, exist_ok=True)
                if dest.is_symlink() or dest.is_file():
                    dest.unlink()
                dest.write_bytes(item.data)
                os.chmod(dest, item.mode)
            os.chmod(staging, 0o777 & ~current_umask())
        except OSError as exc:
            raise _unchanged(exc, target) from exc
        yield staged
        try:
            if replacing:
                staged.backup = free_backup_name(target)
                os.rename(target, staged.backup)
                try:
                    os.rename(staging, target)
                except OSError:
                    os.rename(staged.backup, target)  # put the old tree back
                    raise
            else:
                os.rename(staging, target)     # POSIX rename also replaces an empty directory
            swapped = True
        except OSError as exc:
            raise _unchanged(exc, target) from exc
    finally:
        if staging.exists():
            shutil.rmtree(staging, ignore_errors=True)
        if not swapped:
            for directory in created:      # innermost first: the ones this call made
                try:
                    directory.rmdir()
                except OSError:
                    break


def _unchanged(exc: OSError, target: Path) -> ReedtoolError:
    """The write's error, saying the package on disk was left as it was."""
    error = os_error(exc, target, action="write package")
    error.hint = f"{error.hint}; nothing was changed" if error.hint else "nothing was changed"
    return error
