"""`reedtool layout`: a top view of the rotor layout, as PX4's airframe reference draws it
(report/layout_picture.py draws it; see there for what the picture holds).
"""

from __future__ import annotations

from pathlib import Path

import click

from reedtool.commands.params import model_arguments
from reedtool.errors import ReedtoolError
from reedtool.report.layout_picture import output_format


@click.command("layout")
@model_arguments
@click.option("-o", "--output", "output", type=click.Path(path_type=Path, dir_okay=False),
              required=True, help="Picture to write: .svg or .png.")
@click.option("--force", is_flag=True, help="Overwrite an existing output file.")
def command(model: Path, mappings: tuple[str, ...], package_paths: tuple[Path, ...],
            model_name: str | None, output: Path, force: bool) -> int:
    """Draw MODEL's rotor layout seen from above (x forward up the page, y left).

    Numbered rotors (autopilot's 1-based number and the model's index), disc radius, spin
    arrows, body outline, front marker, COM and arm lengths; SVG or PNG by the extension.
    """
    from reedtool.io.fileio import check_writable

    output_format(output)
    check_writable(output, force)         # a device, FIFO or existing file is refused here
    if not model.is_file():
        raise ReedtoolError("model file not found", file=model,
                            hint="pass the path of a .urdf, .xacro or .sdf file")
    from reedtool.assembly.diagram import write_layout
    from reedtool.io.loader import load_robot
    from reedtool.io.mappings import parse_mappings

    robot = load_robot(model, parse_mappings(mappings), list(package_paths),
                       model_name=model_name)
    write_layout(robot, output, force)
    click.echo(f"wrote {output}")
    return 0
