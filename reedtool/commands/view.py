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


def _views(value: str | None) -> tuple[str, ...]:
    from reedtool.report.render_png import VIEWS_DEG

    if value is None:
        return ("iso",)
    names = tuple(part.strip().lower() for part in value.split(",") if part.strip())
    unknown = [name for name in names if name not in VIEWS_DEG]
    if unknown or not names:
        raise ReedtoolError(f"--views '{value}': no such view",
                            hint=f"choose among {', '.join(VIEWS_DEG)} (comma-separated, "
                                 "e.g. top,front,side,iso)")
    return names


def _size(value: str | None) -> tuple[int, int] | None:
    if value is None:
        return None
    width, sep, height = value.lower().partition("x")
    try:
        size = (int(width), int(height))
    except ValueError:
        size = None
    if not sep or size is None or not (64 <= size[0] <= 8000 and 64 <= size[1] <= 8000):
        raise ReedtoolError(f"--size '{value}' is not a picture size",
                            hint="give WIDTHxHEIGHT in pixels, each 64-8000, e.g. 1200x900")
    return size


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
@click.option("--views", "views_text", metavar="top,front,side,iso",
              help="PNG: the cameras to draw side by side, orthographic (default: iso).")
@click.option("--size", "size_text", metavar="WxH",
              help="PNG: picture size in pixels (default 576x504, wider for several views).")
@click.option("--discs", "disc_style", type=click.Choice(["filled", "outline"]),
              default="filled", show_default=True,
              help="Rotor discs filled, or as outlines so the frame and motor mounts show.")
@ignore_option
@click.option("--embed-outside-files", is_flag=True,
              help="Also draw (so embed in the GLB/HTML) mesh files that lie outside the "
                   "model's packages (an absolute file:// URI, a path climbing out with ..). "
                   "Without it they are left out, with a note.")
@click.option("--force", is_flag=True, help="Overwrite an existing output file.")
def command(inputs: tuple[str, ...], package_paths: tuple[Path, ...], model_name: str | None,
            launch_file: Path | None, output: Path, collision: bool, show_findings: bool,
            views_text: str | None, size_text: str | None, disc_style: str,
            ignore: tuple[str, ...], embed_outside_files: bool, force: bool) -> int:
    """Show MODEL in 3-D: links where Gazebo puts them, rotor discs coloured by spin
    (blue ccw, orange cw), thrust axes, COM, base axes, a scale bar.

    MODEL is a .urdf, .xacro (.urdf.xacro), .gazebo, .sdf or .world file, or a directory,
    glob or ROS package holding one model; NAME:=VALUE words are its xacro arguments.
    .glb opens in any glTF viewer (Blender, VS Code, browsers); .png is an offline render
    for CI and READMEs; .html is one self-contained page showing the GLB (the
    viewer is inside it: it draws offline, from file://). A picture refuses no model for validate's errors: with
    --findings they colour the links they name.
    """
    from reedtool.io.fileio import atomic_write_bytes, check_writable, note_input

    fmt = output_format(output)
    views, size_px = _views(views_text), _size(size_text)
    if fmt != "png" and (views_text or size_text):
        raise ReedtoolError("--views and --size shape the PNG picture only", file=output,
                            hint="name the output .png, or drop them: the GLB and the page "
                                 "are turned in the viewer")
    note_model_files(inputs)          # the model is never an output of its own run
    check_writable(output, force)         # a device, FIFO or existing file is refused here
    model, request = one_model_request("view", inputs, package_paths, model_name,
                                       launch_file, ignore)
    note_input(model)

    from reedtool.workflows.view import view_model

    view, findings = view_model(model, request, collision=collision,
                                with_findings=show_findings, disc_style=disc_style,
                                embed_outside_files=embed_outside_files)
    title = f"{view.name} ({'collision' if collision else 'visual'} geometry)"
    if fmt == "glb":
        from reedtool.report.scene import glb_bytes

        data = glb_bytes(view)
    elif fmt == "png":
        from reedtool.report.render_png import render_png

        from reedtool.report.render_png import DEFAULT_SIZE_PX

        if size_px is None:       # each further view beside the first widens the picture
            columns = 2 if len(views) == 4 else len(views)
            rows = 2 if len(views) == 4 else 1
            size_px = (DEFAULT_SIZE_PX[0] * columns, DEFAULT_SIZE_PX[1] * rows)
        data = render_png(view, title, views=views, size_px=size_px)
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
