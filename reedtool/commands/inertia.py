"""`reedtool inertia`: declared link inertia against the geometry's; whole-robot properties."""

from __future__ import annotations

from pathlib import Path

import click

from reedtool.commands.params import model_inputs, one_model_request, validation_options
from reedtool.errors import ReedtoolError


@click.command("inertia")
@model_inputs()
@click.option("--format", "fmt", type=click.Choice(["text", "json"]), default="text",
              show_default=True, help="Output format.")
@click.option("--fix", is_flag=True,
              help="Write the geometry's inertia into the model (with a numbered .bak "
                   "backup): a .urdf's <inertial>, or the <inertia/> in your xacro file the "
                   "link's tensor comes from (a macro's block property, e.g. body_inertia "
                   "in NAME.xacro); what cannot be placed is printed with its line.")
@click.option("--force", is_flag=True,
              help="Kept for compatibility: --fix never overwrites a backup (it picks the first "
                   "free NAME.bak, NAME.bak.1, ...).")
@validation_options
def command(inputs: tuple[str, ...], package_paths: tuple[Path, ...],
            model_name: str | None, launch_file: Path | None, fmt: str,
            fix: bool, force: bool, ignore: tuple[str, ...] = (),
            ignore_validation: bool = False) -> int:
    """Compare each link's declared inertia with its geometry's; whole-robot mass properties.

    MODEL is a .urdf, .xacro (.urdf.xacro), .gazebo, .sdf or .world file, or a directory,
    glob or ROS package holding one model; NAME:=VALUE words are its xacro arguments.
    Geometry is the first collision shape, else the first visual, as a uniform solid with
    the declared mass. The verdicts are validate's (one function): exit 1 exactly when
    validate reports an inertia error (I201-I203, I207-I210) or a mesh Gazebo cannot load
    or must not open (S130, S131); 0 otherwise, 2 on unreadable input. validate's other
    errors are listed too; a structure error refuses the model (exit 1) unless --ignore
    CODE or --ignore-validation is given.
    """
    model, request = one_model_request("inertia", inputs, package_paths, model_name,
                                       launch_file, ignore)
    from reedtool.report import inertia_text
    from reedtool.workflows.inertia_check import check_inertia, still_failing

    report = check_inertia(model, request, fix=fix, ignore_validation=ignore_validation)
    if report.refused:
        if fmt == "text":
            click.echo(inertia_text.refusal_text(report), nl=False)
        else:
            click.echo(inertia_text.refusal_json(report))
        return 1
    render = inertia_text.render_json if fmt == "json" else inertia_text.render_text
    click.echo(render(report), nl=False)
    if not fix:
        return report.exit_code()
    # The report is on screen before the user's file is edited (a refused edit leaves it).
    from reedtool.workflows.inertia_fix import apply_fix

    notes, fixed, is_urdf = apply_fix(model, report.comparisons)
    # Keep JSON on stdout parseable: fix notes go to stderr there.
    click.echo("\n".join(notes), err=(fmt == "json"))
    return report.exit_code(still_failing(report, fixed, is_urdf))
