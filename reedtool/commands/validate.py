"""`reedtool validate`: every static mistake that makes a model fail in Gazebo, with its line.

Many models per run (files, directories, globs, ROS packages, every multirotor of a
world), one report, one exit code over all: 0 clean, 1 findings at a failing severity,
2 when an input could not be read (the other models are still checked and reported), 3
when a rule failed internally (its finding says so; every other finding is reported).
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

import click

from reedtool.commands.params import ignore_option, model_inputs
from reedtool.errors import ReedtoolError

FORMATS = ("text", "json", "github", "sarif", "junit")


def explain(code: str) -> int:
    from reedtool.checks.registry import get_rule
    from reedtool.report.rules_text import explanation_text

    found = get_rule(code)
    if found is None:
        raise ReedtoolError(f"unknown rule '{code}'",
                            hint="`reedtool rules` lists every rule code and name")
    click.echo(explanation_text(found))
    return 0


def _use_color(no_color: bool) -> bool:
    if no_color or os.environ.get("NO_COLOR"):
        return False
    return sys.stdout.isatty()


# ------------------------------------------------------------------ the command

@click.command(name="validate")
@model_inputs(metavar="[MODEL|DIR|GLOB|PACKAGE]... [NAME:=VALUE]...")
@click.option("--format", "fmt", type=click.Choice(FORMATS), default="text",
              show_default=True, help="Output format.")
@click.option("--output-file", "-o", "output_file", type=click.Path(path_type=Path,
                                                                    dir_okay=False),
              help="Write the report to FILE instead of standard output.")
@click.option("--force", is_flag=True,
              help="Overwrite an existing --output-file or --diagram file.")
@click.option("--select", multiple=True, metavar="CODE,...",
              help="Run only rules whose code starts with these prefixes (or these rule names).")
@ignore_option
@click.option("--explain", "explain_code", metavar="CODE",
              help="Print the documentation of one rule (code or name) and exit.")
@click.option("--strict/--no-strict", default=None,
              help="Exit 1 on warnings as well as errors (default: the config's `strict`).")
@click.option("--exit-zero", is_flag=True,
              help="Exit 0 even when there are findings (input errors still exit 2).")
@click.option("--statistics", "show_statistics", is_flag=True,
              help="Add a count of findings per rule to the report.")
@click.option("--show-settings", is_flag=True,
              help="Print the configuration file and settings each model gets, and exit.")
@click.option("--no-color", is_flag=True, help="Never colour the text output.")
@click.option("--controller", "controller_files", multiple=True, metavar="FILE.yaml",
              type=click.Path(path_type=Path, dir_okay=False),
              help="RotorS-style vehicle parameter YAML to cross-check against the model, "
                   "and RotorS Lee gain files (lee_controller_NAME.yaml) with it "
                   "(repeatable).")
@click.option("--airframe", "airframe_files", multiple=True, metavar="FILE",
              type=click.Path(path_type=Path, dir_okay=False),
              help="PX4 airframe script or parameter file to cross-check (repeatable).")
@click.option("--autopilot-params", "autopilot_files", multiple=True, metavar="FILE.parm",
              type=click.Path(path_type=Path, dir_okay=False),
              help="ArduPilot .parm file to cross-check (FRAME_CLASS/TYPE, SERVOn_FUNCTION).")
@click.option("--diagram", type=click.Path(path_type=Path, dir_okay=False), default=None,
              help="Also draw the rotor layout (.svg/.png), rotors named by findings in red.")
@click.option("--force-exclude", is_flag=True,
              help="Apply the configuration's exclude to files named on the command line too "
                   "(as pre-commit passes them; the config's `force-exclude`).")
@click.option("--baseline", "baseline_file", type=click.Path(path_type=Path, dir_okay=False),
              help="Report only findings not recorded in this baseline file (default: the "
                   "config's `baseline`).")
@click.option("--write-baseline", "write_baseline", metavar="FILE",
              type=click.Path(path_type=Path, dir_okay=False),
              help="Record every finding of this run in FILE as accepted and exit 0 "
                   "(--force to replace it).")
@click.option("--jobs", "-j", type=click.IntRange(min=0), default=1, show_default=True,
              metavar="N", help="Check the models in N processes (0: one per available "
                                "CPU); the report keeps the models' order.")
def command(inputs: tuple[str, ...], package_paths: tuple[Path, ...], model_name: str | None,
            launch_file: Path | None, fmt: str, output_file: Path | None, force: bool,
            select: tuple[str, ...], ignore: tuple[str, ...], explain_code: str | None,
            strict: bool | None, exit_zero: bool, show_statistics: bool, show_settings: bool,
            no_color: bool, controller_files: tuple[Path, ...] = (),
            airframe_files: tuple[Path, ...] = (), autopilot_files: tuple[Path, ...] = (),
            diagram: Path | None = None, jobs: int = 1, force_exclude: bool = False,
            baseline_file: Path | None = None, write_baseline: Path | None = None) -> int:
    """Check models (.urdf, .xacro (.urdf.xacro), .gazebo, .sdf or .world files,
    directories, globs, ROS packages, or a changed pyproject.toml/reedtool.toml: the
    models it configures) for mistakes; NAME:=VALUE words are xacro arguments for every
    model.

    Exit 0 when there is no error, 1 when there are errors (or warnings with --strict),
    2 on bad usage or when a model could not be read, 3 when a rule failed internally (a
    reedtool bug: that rule's finding says so, the rest of the report is complete).
    """
    if explain_code:
        return explain(explain_code)
    from reedtool.resolve.packages import shared_crawls
    from reedtool.workflows import validate_run as run_

    context = click.get_current_context(silent=True)
    if context is not None:       # every model of the run resolves against the same roots
        context.with_resource(shared_crawls())
    paths, request = run_.read_words(inputs, package_paths=package_paths,
                                     model_name=model_name, launch_file=launch_file,
                                     select=select, ignore=ignore, force_exclude=force_exclude)
    if not paths:
        raise click.UsageError("missing argument 'MODEL' (or use --explain CODE)")
    targets = run_.find_targets(paths, request)
    if show_settings:
        from reedtool.report.settings_text import settings_lines

        for settings in run_.settings_of(targets, request):
            click.echo("\n".join(settings_lines(settings)))
        return 0
    options = run_.RunOptions(request=request, diagram=diagram, force=force)
    run_.load_cross_checks(options, controller_files, airframe_files, autopilot_files)
    run = run_.run_validate(targets, options, jobs=jobs, strict=strict,
                            baseline_file=baseline_file,
                            apply_baselines=write_baseline is None)
    if write_baseline is not None:
        return _write_baseline(run, write_baseline, force)
    _show(run, fmt, output_file, force, _use_color(no_color) and output_file is None,
          show_statistics)
    return run.exit_code(exit_zero)


def _show(run, fmt: str, output_file: Path | None, force: bool, color: bool,
          show_statistics: bool) -> None:
    """The report to standard output or --output-file; the notes after it (on stderr for
    a machine format or a file, whose text stays as it is)."""
    from reedtool.report import render

    text = render(run.results, fmt, color=color, show_statistics=show_statistics,
                  failing=run.failing)
    if output_file is not None:
        from reedtool.io.fileio import atomic_write_text

        atomic_write_text(output_file, text, force=force)
    else:
        click.echo(text, nl=False, color=color)
    for note in run.notes:
        click.echo(note, err=fmt != "text" or output_file is not None)


def _write_baseline(run, path: Path, force: bool) -> int:
    """--write-baseline: exit 0 once written; the models that could not be read are shown
    before the refusal (exit 2)."""
    from reedtool.report import render
    from reedtool.workflows.validate_run import write_run_baseline

    if run.unread:
        click.echo(render(run.unread, "text"), nl=False)
    count, checked = write_run_baseline(run, path, force)
    click.echo(f"reedtool: wrote {count} finding(s) of {checked} model(s) to {path}")
    return 0
