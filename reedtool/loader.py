"""Path -> Robot: URDF read directly, everything else expanded with xacro first."""

from __future__ import annotations

from pathlib import Path
from typing import Mapping, Sequence

from .errors import ReedtoolError
from .model import ParseIssue, Robot, SourceLoc

URDF_SUFFIXES = {".urdf"}
MAPPING_SEPARATOR = ":="


def parse_mappings(args: Sequence[str]) -> dict[str, str]:
    """`name:=value` command-line arguments, as roslaunch and xacro take them.

    Shared by every command that loads a model, so all of them accept and refuse the same
    arguments. A second `:=` is refused, as xacro does, rather than guessing which is meant.
    """
    mappings: dict[str, str] = {}
    for arg in args:
        name, sep, value = arg.partition(MAPPING_SEPARATOR)
        name = name.strip()
        if not sep or not name or MAPPING_SEPARATOR in value or any(c.isspace() for c in name):
            raise ReedtoolError(f"cannot read argument '{arg}'",
                                hint="xacro arguments are written name:=value, one per word, "
                                     "after the model")
        mappings[name] = value
    return mappings

SDF_SUFFIXES = {".sdf", ".world"}


def load_robot(path: Path | str, mappings: Mapping[str, str] | None = None,
               package_paths: Sequence[Path] = ()) -> Robot:
    """Load a model, with source locations pointing at the files the user edits.

    Legacy xacro tags found during expansion are kept as ParseIssues ("legacy-xacro")
    so that `validate` can report them with the rest.
    """
    from .packages import PackageResolver
    from .urdf_io import load_urdf_file, parse_urdf

    path = Path(path)
    if not path.exists():
        raise ReedtoolError("file not found", file=path, hint="check the model path")
    if path.is_dir():
        if not (path / "model.sdf").is_file():
            raise ReedtoolError("is a directory, expected a .urdf, .xacro or .sdf file "
                                "(or a model directory holding model.sdf)", file=path)
        path = path / "model.sdf"
    if path.suffix.lower() in SDF_SUFFIXES:
        from .sdf_io import load_sdf_file

        return load_sdf_file(path, resolver=PackageResolver(package_paths, model_path=path))
    if path.suffix.lower() in URDF_SUFFIXES:
        return load_urdf_file(path, resolver=PackageResolver(package_paths, model_path=path))

    from .expand import expand_xacro

    expansion = expand_xacro(path, dict(mappings or {}), package_paths)
    robot = parse_urdf(expansion.urdf_xml, path, resolver=expansion.resolver,
                       element_locs=expansion.element_locs)
    for tag in expansion.legacy:
        what = "macro call" if tag.kind == "macro-call" else "legacy xacro tag"
        robot.parse_issues.append(ParseIssue(
            kind="legacy-xacro", message=f"{what} <{tag.tag}> (write <{tag.modern}>)",
            loc=SourceLoc(str(tag.file), tag.line), subject=tag.tag))
    return robot
