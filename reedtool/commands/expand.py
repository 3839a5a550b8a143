"""`reedtool expand`: xacro -> URDF without ROS, resolving packages the way ROS would."""

from __future__ import annotations

from pathlib import Path

import click

from reedtool.commands.params import model_inputs, one_model_request
from reedtool.errors import ReedtoolError


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
    from reedtool.io.fileio import is_stdout
    from reedtool.workflows.expansion import expand_model

    if model_name is not None:
        raise ReedtoolError("--model picks one model of an SDF world; expand writes a "
                            "xacro's URDF", hint="drop --model")
    model, request = one_model_request("expand", inputs, package_paths, model_name,
                                       launch_file)
    urdf = expand_model(model, request, None if is_stdout(output) else output, force=force,
                        legacy_fix=fix_legacy, note=lambda line: click.echo(line, err=True))
    if urdf is not None:
        click.echo(urdf, nl=False)
    return 0
