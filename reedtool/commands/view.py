"""`reedtool view`: the model in 3-D as Gazebo would place it, as GLB, PNG or HTML."""

from __future__ import annotations

from pathlib import Path

import click

from reedtool.commands.params import (
    ignore_option,
    model_inputs,
    note_model_files,
    one_model_request,
)
from reedtool.errors import ReedtoolError

FORMATS = (".glb", ".png", ".html")


def output_format(path: Path) -> str:
    suffix = path.suffix.lower()
    if suffix not in FORMATS:
        raise ReedtoolError(f"cannot tell the output format from '{path.suffix or path.name}'",
                            file=path, hint="name the output .glb, .png or .html")
    return suffix[1:]


@click.command("view")
@model_inputs()
@click.option("-o", "--output", "output", type=click.Path(path_type=Path, dir_okay=False),
              required=True, help="File to write: .glb (glTF), .png (picture) or .html (page).")
@click.option("--collision", is_flag=True, help="Show the collision geometry, not the visuals.")
@click.option("--findings", "show_findings", is_flag=True,
              help="Colour the links validate's findings name, by severity.")
@ignore_option
@click.option("--embed-outside-files", is_flag=True,
              help="Also draw (so embed in the GLB/HTML) mesh files that lie outside the "
                   "model's packages (an absolute file:// URI, a path climbing out with ..). "
                   "Without it they are left out, with a note.")
@click.option("--force", is_flag=True, help="Overwrite an existing output file.")
def command(inputs: tuple[str, ...], package_paths: tuple[Path, ...], model_name: str | None,
            launch_file: Path | None, output: Path, collision: bool, show_findings: bool,
            ignore: tuple[str, ...], embed_outside_files: bool, force: bool) -> int:
    """Show MODEL in 3-D: links where Gazebo puts them, rotor discs coloured by spin
    (blue ccw, orange cw), thrust axes, COM, base axes, a scale bar.

    MODEL is a .urdf, .xacro (.urdf.xacro), .gazebo, .sdf or .world file, or a directory,
    glob or ROS package holding one model; NAME:=VALUE words are its xacro arguments.
    .glb opens in any glTF viewer (Blender, VS Code, browsers); .png is an offline render
    for CI and READMEs; .html is one page showing the GLB (it loads the model-viewer
    script from the network). A picture refuses no model for validate's errors: with
    --findings they colour the links they name.
    """
    from reedtool.io.fileio import atomic_write_bytes, check_writable, note_input

    fmt = output_format(output)
    note_model_files(inputs)          # the model is never an output of its own run
    check_writable(output, force)         # a device, FIFO or existing file is refused here
    model, request = one_model_request("view", inputs, package_paths, model_name,
                                       launch_file, ignore)
    note_input(model)

    from reedtool.assembly.view import view_model

    view, findings = view_model(model, request, collision=collision,
                                with_findings=show_findings,
                                embed_outside_files=embed_outside_files)
    title = f"{view.name} ({'collision' if collision else 'visual'} geometry)"
    if fmt == "glb":
        from reedtool.report.scene import glb_bytes

        data = glb_bytes(view)
    elif fmt == "png":
        from reedtool.report.render_png import render_png

        data = render_png(view, title)
    else:
        from reedtool.report.html_viewer import render_html

        data = render_html(view, title).encode("utf-8")
    atomic_write_bytes(output, data, force=force)
    for note in view.notes:
        click.echo(f"note: {note}", err=True)
    if findings is not None:
        click.echo(f"{len(findings)} findings, {len(view.link_severity)} links coloured"
                   + ("" if not findings else " (run `reedtool validate` for the messages)"))
    click.echo(f"wrote {output}: {view.framing.caption()}")
    return 0
