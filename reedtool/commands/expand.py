"""`reedtool expand`: xacro -> URDF without ROS, resolving packages the way ROS would."""

from __future__ import annotations

from pathlib import Path

import click

from reedtool.commands.params import model_inputs, one_model_request
from reedtool.errors import ReedtoolError


def _fix_legacy(model: Path, mappings: dict[str, str], package_paths: list[Path]) -> None:
    from reedtool.io.fileio import atomic_write_text
    from reedtool.resolve.packages import is_bundled
    from reedtool.io.xacro_expand import display_path, scan_legacy

    scan = scan_legacy(model, mappings, package_paths)
    for path, text in scan.fixed_text.items():
        if is_bundled(path):
            continue  # reedtool's own files are never rewritten
        count = sum(1 for tag in scan.tags if tag.file == display_path(path))
        backup = atomic_write_text(path, text, force=True, backup=True, in_place=True)
        click.echo(f"reedtool: rewrote {count} legacy xacro tag(s) in {display_path(path)} "
                   f"(backup: {display_path(backup) if backup else 'none'})", err=True)


def _refuse_non_xacro(model: Path) -> None:
    """A mesh or an SDF file named as the model: say what it is rather than "malformed XML"
    or an SDF echoed back under a header telling the user to edit .xacro sources."""
    from reedtool.io.loader import SDF_SUFFIXES, refuse_mesh

    refuse_mesh(model)
    if model.is_dir() or model.suffix.lower() in SDF_SUFFIXES:
        what = "a Gazebo model directory (SDF)" if model.is_dir() else "SDF"
        raise ReedtoolError(f"is {what}: expand turns xacro into URDF, and SDF needs no "
                            "expansion", file=model,
                            hint=f"`reedtool validate {model.name}` checks it as Gazebo reads it")


@click.command(name="expand")
@model_inputs()
@click.option("-o", "--output", type=click.Path(path_type=Path, dir_okay=False),
              help="Write the URDF here instead of standard output ('-': standard output).")
@click.option("--force", is_flag=True, help="Overwrite an existing output file.")
@click.option("--fix-legacy", is_flag=True,
              help="Rewrite legacy xacro tags (<property>, <macro>, <include>, unprefixed "
                   "macro calls) in the model's files first, keeping a .bak of each.")
def command(inputs: tuple[str, ...], package_paths: tuple[Path, ...], model_name: str | None,
            launch_file: Path | None, output: Path | None, force: bool,
            fix_legacy: bool) -> int:
    """Expand a xacro MODEL into URDF, with $(find) and package:// resolved without ROS.

    MODEL is a .xacro (.urdf.xacro, .gazebo) or .urdf file, or a directory, glob or ROS
    package holding one; NAME:=VALUE words set $(arg NAME), as roslaunch and xacro take
    them, after `[tool.reedtool] args` and --launch's.
    """
    from reedtool.io.fileio import atomic_write_text, check_writable, is_stdout, note_input
    from reedtool.io.xacro_expand import expand_xacro

    if model_name is not None:
        raise ReedtoolError("--model picks one model of an SDF world; expand writes a "
                            "xacro's URDF", hint="drop --model")
    model, request = one_model_request("expand", inputs, package_paths, model_name,
                                       launch_file)
    _refuse_non_xacro(model)
    from reedtool.workflows.robots import model_mappings

    mappings = model_mappings(model, request)
    if is_stdout(output):
        output = None
    note_input(model)
    if output is not None:
        check_writable(output, force)   # fail before the work, not after
    if fix_legacy:
        _fix_legacy(model, mappings, list(package_paths))

    expansion = expand_xacro(model, mappings, list(package_paths))
    if expansion.legacy:
        for tag in expansion.legacy:
            click.echo(f"reedtool: {tag}", err=True)
        raise ReedtoolError(
            f"{len(expansion.legacy)} legacy xacro tag(s): xacro 2.x and ROS copy them into "
            "the URDF unexpanded, so the model is broken as written", file=model,
            hint=f"rewrite them with 'reedtool expand --fix-legacy {model}'; "
                 "each file keeps a .bak backup")
    for warning in expansion.warnings:
        click.echo(f"reedtool: warning: {warning}", err=True)

    if output is None:
        click.echo(expansion.urdf_xml, nl=False)
    else:
        for source in expansion.files:
            note_input(source)   # every xacro the model pulled in is off limits as output
        atomic_write_text(output, expansion.urdf_xml, force=force)
        click.echo(f"reedtool: wrote {output}", err=True)
    return 0
