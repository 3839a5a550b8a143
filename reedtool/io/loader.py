"""Path -> Robot: URDF read directly, everything else expanded with xacro first."""

from __future__ import annotations

from pathlib import Path
from typing import Mapping, Sequence

from reedtool.errors import ReedtoolError
from reedtool.model import ParseIssue, Robot, SourceLoc

URDF_SUFFIXES = {".urdf"}
SDF_SUFFIXES = {".sdf", ".world"}


def load_robots(path: Path | str, mappings: Mapping[str, str] | None = None,
                package_paths: Sequence[Path] = (), model_name: str | None = None) -> list[Robot]:
    """The models `validate` checks: one for URDF/xacro, a model file or `model_name`; for
    an SDF world, each multirotor model (each model when none has motor plugins)."""
    path = Path(path)
    refuse_mesh(path)
    if model_name is None and _sdf_path(path) is not None and not _is_template(_sdf_path(path)):
        from reedtool.resolve.packages import PackageResolver
        from reedtool.io.sdf import load_sdf_models

        from reedtool.io.sdf_jinja import relocate_rendered, take_rendered

        sdf = _sdf_path(path)
        resolver = PackageResolver(package_paths, model_path=sdf)
        robots = load_sdf_models(sdf, resolver=resolver)
        maps = take_rendered()
        return [_with_package_notes(relocate_rendered(robot, maps), resolver)
                for robot in robots]
    return [load_robot(path, mappings, package_paths, model_name=model_name)]


def refuse_mesh(path: Path) -> None:
    """A mesh named where a model belongs: say so, and how a mesh becomes part of one
    (read as XML it would only be "malformed XML at column 1")."""
    from reedtool.io.meshes import GZ_MESH_SUFFIXES

    suffix = path.suffix.lower()
    if suffix in GZ_MESH_SUFFIXES and not path.is_dir():
        raise ReedtoolError(
            f"is a mesh ({suffix[1:].upper()}), not a robot model (.urdf, .xacro, .gazebo, "
            ".sdf or .world)", file=path,
            hint=f"`reedtool import-stl {path.name} --package DIR` puts it in a package in "
                 "metres and FLU with its inertia, and prints the <link> that uses it")


def _with_package_notes(robot: Robot, resolver) -> Robot:
    """The resolver's ambiguities (two packages with one name) as ParseIssues for S150:
    only those of packages the model read; another package's twin cannot change it."""
    read = resolver.resolved_names
    for name, used, ignored, where in resolver.duplicates:
        if name not in read:
            continue
        robot.parse_issues.append(ParseIssue(
            kind="package-duplicate",
            message=f"two packages named '{name}' under {where}: using {used}, ignoring "
                    f"{ignored}",
            loc=SourceLoc(str(robot.source_file or "")), subject=name))
    return robot


def _model_dir_sdf(path: Path) -> Path:
    """The SDF file of a Gazebo model directory (model.config, else model.sdf)."""
    from reedtool.resolve.resources import model_sdf_in_dir

    if not (path / "model.config").is_file() and not (path / "model.sdf").is_file():
        raise ReedtoolError("is a directory, expected a .urdf, .xacro or .sdf file "
                            "(or a model directory holding model.config or model.sdf)",
                            file=path)
    try:
        return model_sdf_in_dir(path)
    except ReedtoolError as exc:
        raise ReedtoolError(exc.message, file=path) from None


def _sdf_path(path: Path) -> Path | None:
    if path.is_dir():
        return _model_dir_sdf(path)
    return path if path.suffix.lower() in SDF_SUFFIXES or _is_template(path) else None


def _is_template(path: Path) -> bool:
    """PX4's Gazebo Classic `*.sdf.jinja` (io.sdf_jinja renders it as PX4 does)."""
    from reedtool.io.sdf_jinja import is_sdf_jinja

    return is_sdf_jinja(path)


def load_robot(path: Path | str, mappings: Mapping[str, str] | None = None,
               package_paths: Sequence[Path] = (), model_name: str | None = None) -> Robot:
    """Load a model, with source locations pointing at the files the user edits.

    Legacy xacro tags found during expansion are kept as ParseIssues ("legacy-xacro")
    so that `validate` can report them with the rest.
    """
    from reedtool.resolve.packages import PackageResolver
    from reedtool.io.urdf import load_urdf_file, parse_urdf

    path = Path(path)
    if not path.exists():
        raise ReedtoolError("file not found", file=path, hint="check the model path")
    refuse_mesh(path)
    if path.is_dir():
        path = _model_dir_sdf(path)
    if _is_template(path):
        from reedtool.io.sdf import parse_sdf
        from reedtool.io.sdf_jinja import relocate_rendered, render

        resolver = PackageResolver(package_paths, model_path=path)
        rendered = render(path)
        try:
            robot = parse_sdf(rendered.text, path, resolver=resolver, model_name=model_name)
        except ReedtoolError as exc:     # at the template's line, as every finding is
            if exc.file != str(path) or not exc.line or exc.line > len(rendered.template_line):
                raise
            raise ReedtoolError(exc.message, file=exc.file,
                                line=rendered.template_line[exc.line - 1],
                                hint=exc.hint) from None
        return _with_package_notes(relocate_rendered(robot), resolver)
    if path.suffix.lower() in SDF_SUFFIXES:
        from reedtool.io.sdf import load_sdf_file
        from reedtool.io.sdf_jinja import relocate_rendered

        resolver = PackageResolver(package_paths, model_path=path)
        return _with_package_notes(relocate_rendered(load_sdf_file(
            path, resolver=resolver, model_name=model_name)), resolver)
    if model_name is not None:
        raise ReedtoolError("--model picks a model of an SDF file; this file is not SDF",
                            file=path, hint="drop --model")
    if path.suffix.lower() in URDF_SUFFIXES:
        resolver = PackageResolver(package_paths, model_path=path)
        return _with_package_notes(load_urdf_file(path, resolver=resolver), resolver)

    from reedtool.io.xacro_expand import expand_xacro

    expansion = expand_xacro(path, dict(mappings or {}), package_paths)
    robot = parse_urdf(expansion.urdf_xml, path, resolver=expansion.resolver,
                       element_locs=expansion.element_locs)
    for tag in expansion.legacy:
        what = "macro call" if tag.kind == "macro-call" else "legacy xacro tag"
        robot.parse_issues.append(ParseIssue(
            kind="legacy-xacro", message=f"{what} <{tag.tag}> (write <{tag.modern}>)",
            loc=SourceLoc(str(tag.file), tag.line), subject=tag.tag))
    return _with_package_notes(robot, expansion.resolver)
