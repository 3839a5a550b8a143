"""`reedtool authority`: can this multirotor lose a rotor and still be flown down?

A static analysis (no simulation): the available control authority index (ACAI) of the
intact vehicle and of every single-rotor failure, with and without yaw control, and the
thrust-to-weight at which each failure becomes survivable. See docs/fault-tolerance.md.

Exit 0 when the model meets --require, 1 when it does not, 2 on unreadable input.
"""

from __future__ import annotations

from pathlib import Path

import click

from reedtool.commands.params import (
    FiniteFloatRange,
    model_inputs,
    one_model_request,
    validation_options,
)
from reedtool.workflows.authority import POLICIES


@click.command(name="authority")
@model_inputs()
@click.option("--efficiency", "efficiency_items", multiple=True, metavar="ROTOR=ETA",
              help="Degrade a rotor: its maximum thrust times ETA in [0, 1] (repeatable).")
@click.option("--degrade", "degrade", type=FiniteFloatRange(0.0, 1.0, max_open=True),
              default=0.0, show_default=True, metavar="ETA",
              help="Each case leaves its rotor ETA of its thrust instead of stopping it "
                   "(0: a failure; 0.5: a damaged propeller).")
@click.option("--require", "policy", type=click.Choice(list(POLICIES)), default="hover",
              show_default=True, help="What must hold for exit 0.")
@click.option("--fly", is_flag=True,
              help="Also fly each failure closed-loop: hover, lose the rotor at --fail-at, "
                   "fly on until --duration.")
@click.option("--fail-at", "fail_at_s", type=FiniteFloatRange(0.0, 600.0), default=1.0,
              show_default=True, metavar="S", help="With --fly: when the rotor stops [s].")
@click.option("--duration", "duration_s", type=FiniteFloatRange(0.5, 600.0), default=6.0,
              show_default=True, metavar="S", help="With --fly: length of each flight [s].")
@click.option("--plot", "plot_path", type=click.Path(path_type=Path, dir_okay=False),
              help="With --fly: the first failure flight that does not hold (else the first) "
                   "as .png or .svg, the failure time marked.")
@click.option("--force", is_flag=True, help="Overwrite an existing --plot file.")
@click.option("--format", "fmt", type=click.Choice(["text", "json"]), default="text",
              show_default=True, help="Output format.")
@validation_options
def command(inputs: tuple[str, ...], package_paths: tuple[Path, ...],
            model_name: str | None, launch_file: Path | None, efficiency_items: tuple[str, ...], degrade: float,
            policy: str, fly: bool,
            fail_at_s: float, duration_s: float, plot_path: Path | None, force: bool,
            fmt: str, ignore: tuple[str, ...] = (), ignore_validation: bool = False) -> int:
    """Control authority of MODEL about hover, intact and after each single rotor failure.

    MODEL is a .urdf, .xacro (.urdf.xacro), .gazebo, .sdf or .world file with motor
    plugins, or a directory, glob or ROS package holding one such model; NAME:=VALUE words
    are its xacro arguments. validate's rules run first: a structure, mass or rotor error
    refuses the model (exit 1) unless --ignore CODE or --ignore-validation is given; other
    errors are listed beside the analysis.
    """
    model, request = one_model_request("authority", inputs, package_paths, model_name,
                                       launch_file, ignore)
    from reedtool.workflows.authority import AuthorityOptions, run_authority

    options = AuthorityOptions(efficiency_items=efficiency_items, degrade=degrade,
                               policy=policy, fly=fly, fail_at_s=fail_at_s,
                               duration_s=duration_s, plot_path=plot_path, force=force,
                               ignore_validation=ignore_validation)
    result = run_authority(model, request, options,
                           on_validation=_show_validation(model, fmt, ignore_validation))
    from reedtool.report.authority_text import render_json, render_text

    if fmt == "json":
        click.echo(render_json(result))
    elif not result.refused:     # a refusal's text is validate's errors, already shown
        click.echo(render_text(result))
    return 0 if result.passed else 1


def _show_validation(model: Path, fmt: str, ignore_validation: bool):
    """validate's errors, shown in the text report before the analysis."""
    def show(verdict, refused: bool) -> None:
        if fmt == "text":
            from reedtool.report.validation_note import validation_text

            click.echo(validation_text(str(model), verdict.refusing, verdict.reported, refused,
                                       "analysing it", ignore_validation), nl=False)
    return show
