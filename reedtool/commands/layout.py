"""`reedtool layout`: a top view of the rotor layout, as PX4's airframe reference draws it
(report/layout_picture.py draws it; see there for what the picture holds).
"""

from __future__ import annotations

from pathlib import Path

import click

from reedtool.commands.params import (
    model_inputs,
    note_model_files,
    one_model_request,
    validation_options,
)
from reedtool.report.layout_picture import output_format


@click.command("layout")
@model_inputs()
@click.option("-o", "--output", "output", type=click.Path(path_type=Path, dir_okay=False),
              required=True, help="Picture to write: .svg or .png.")
@click.option("--force", is_flag=True, help="Overwrite an existing output file.")
@validation_options
def command(inputs: tuple[str, ...], package_paths: tuple[Path, ...],
            model_name: str | None, launch_file: Path | None, output: Path, force: bool,
            ignore: tuple[str, ...] = (), ignore_validation: bool = False) -> int:
    """Draw MODEL's rotor layout seen from above (x forward up the page, y left).

    MODEL is a .urdf, .xacro (.urdf.xacro), .gazebo, .sdf or .world file, or a directory,
    glob or ROS package holding one model; NAME:=VALUE words are its xacro arguments.
    Numbered rotors (autopilot's 1-based number and the model's index), disc radius, spin
    arrows, body outline, front marker, COM and arm lengths; SVG or PNG by the extension.
    validate's rules run first: the rotors its findings name are drawn in red and its
    errors listed; a structure error refuses the model (exit 1) unless --ignore CODE or
    --ignore-validation is given.
    """
    from reedtool.io.fileio import check_writable, note_input

    output_format(output)
    note_model_files(inputs)          # the model is never an output of its own run
    check_writable(output, force)         # a device, FIFO or existing file is refused here
    model, request = one_model_request("layout", inputs, package_paths, model_name,
                                       launch_file, ignore)
    note_input(model)
    from reedtool.workflows.diagram import draw_layout

    drawn = draw_layout(model, request, output, force, ignore_validation=ignore_validation,
                        on_validation=_show_validation(model, ignore_validation))
    if not drawn:
        return 1
    click.echo(f"wrote {output}")
    return 0


def _show_validation(model: Path, ignore_validation: bool):
    """validate's errors and what was done about them, before the picture is drawn."""
    def show(verdict, refused: bool) -> None:
        from reedtool.report.validation_note import validation_text

        click.echo(validation_text(str(model), verdict.refusing, verdict.reported, refused,
                                   "drawing it", ignore_validation), nl=False)
    return show
