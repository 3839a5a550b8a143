"""`reedtool validate`: every static mistake that makes a model fail in Gazebo, with its line."""

from __future__ import annotations

import os
import sys
from pathlib import Path

import click

from reedtool.commands.params import model_option
from reedtool.errors import ReedtoolError


def explain(code: str) -> int:
    from reedtool.checks.registry import get_rule

    found = get_rule(code)
    if found is None:
        raise ReedtoolError(f"unknown rule '{code}'",
                            hint="docs/rules.md lists every rule code")
    click.echo(f"{found.code} {found.slug} ({found.severity}, {found.family})\n")
    click.echo(f"{found.summary}\n")
    click.echo(found.explanation)
    return 0


def _use_color(no_color: bool) -> bool:
    if no_color or os.environ.get("NO_COLOR"):
        return False
    return sys.stdout.isatty()


@click.command(name="validate")
@click.argument("model", required=False, type=click.Path(path_type=Path))
@click.argument("mappings", nargs=-1)
@click.option("--package-path", "package_paths", multiple=True, metavar="DIR",
              type=click.Path(path_type=Path, file_okay=False),
              help="Directory to search for ROS packages first (repeatable).")
@model_option
@click.option("--format", "fmt", type=click.Choice(["text", "json", "github"]),
              default="text", show_default=True, help="Output format.")
@click.option("--select", multiple=True, metavar="PREFIX,...",
              help="Run only rules whose code starts with these prefixes.")
@click.option("--ignore", multiple=True, metavar="PREFIX,...",
              help="Skip rules whose code starts with these prefixes.")
@click.option("--explain", "explain_code", metavar="CODE",
              help="Print the documentation of one rule and exit.")
@click.option("--strict/--no-strict", default=None,
              help="Exit 1 on warnings as well as errors (default: the config's `strict`).")
@click.option("--no-color", is_flag=True, help="Never colour the text output.")
@click.option("--controller", "controller_files", multiple=True, metavar="FILE.yaml",
              type=click.Path(path_type=Path, dir_okay=False),
              help="RotorS-style vehicle parameter YAML to cross-check against the model "
                   "(repeatable).")
@click.option("--airframe", "airframe_files", multiple=True, metavar="FILE",
              type=click.Path(path_type=Path, dir_okay=False),
              help="PX4 airframe script or parameter file to cross-check (repeatable).")
@click.option("--autopilot-params", "autopilot_files", multiple=True, metavar="FILE.parm",
              type=click.Path(path_type=Path, dir_okay=False),
              help="ArduPilot .parm file to cross-check (FRAME_CLASS/TYPE, SERVOn_FUNCTION).")
@click.option("--diagram", type=click.Path(path_type=Path, dir_okay=False), default=None,
              help="Also draw the rotor layout (.svg/.png), rotors named by findings in red.")
@click.option("--force", is_flag=True, help="Overwrite an existing --diagram file.")
def command(model: Path | None, mappings: tuple[str, ...], package_paths: tuple[Path, ...],
            model_name: str | None, fmt: str, select: tuple[str, ...], ignore: tuple[str, ...],
            explain_code: str | None, strict: bool | None, no_color: bool,
            controller_files: tuple[Path, ...] = (), airframe_files: tuple[Path, ...] = (),
            autopilot_files: tuple[Path, ...] = (), diagram: Path | None = None,
            force: bool = False) -> int:
    """Check MODEL (.urdf, .xacro or .sdf, with xacro NAME:=VALUE arguments) for mistakes.

    Exit 0 when there is no error, 1 when there are errors (or warnings with --strict),
    2 on bad usage or unreadable input.
    """
    if explain_code:
        return explain(explain_code)
    if model is None:
        raise click.UsageError("missing argument 'MODEL' (or use --explain CODE)")
    if not model.exists():
        # Checked before the config lookup, which walks up from the model's directory.
        raise ReedtoolError("file not found", file=model, hint="check the model path")

    from reedtool.checks.runner import (
        Selection,
        parse_selectors,
        parse_severity_overrides,
        run_checks,
    )
    from reedtool.config import load_config
    from reedtool.io.loader import load_robots
    from reedtool.io.mappings import parse_mappings
    from reedtool.report import render

    config = load_config(model)
    origin = str(config.path) if config.path else "config"
    if select and not parse_selectors(select, origin="--select"):
        # `--select ""` would run no rule and report a clean model.
        raise ReedtoolError("--select names no rule", hint="give a code or prefix such as S, "
                            "I203 or R; ALL selects every rule")
    selection = Selection(
        select=(parse_selectors(select, origin="--select") if select
                else parse_selectors(config.select, origin=origin) if config.select is not None
                else ("",)),
        ignore=(parse_selectors(config.ignore, origin=origin)
                + parse_selectors(ignore, origin="--ignore")),
        severity=parse_severity_overrides(config.severity, origin=origin),
    )
    robots = load_robots(model, parse_mappings(mappings), list(package_paths),
                         model_name=model_name)
    controllers = []
    if controller_files:
        from reedtool.flightstack.controller_tables import load_controller_yaml

        controllers = [load_controller_yaml(path) for path in controller_files]
    from reedtool.flightstack.params_files import load_flight_params

    flight_params = load_flight_params(airframe_files, autopilot_files)
    findings = []
    outputs = []
    for robot in robots:
        robot_findings = run_checks(robot, selection, controllers=controllers,
                                    flight_params=flight_params)
        findings += robot_findings
        # A world checked model by model reports each under its name.
        label = str(model) if len(robots) == 1 else f"{model} [model {robot.name}]"
        outputs.append(render(robot_findings, label, fmt, color=_use_color(no_color)))
        if diagram is not None:
            from reedtool.commands.layout import write_diagram

            # A world's models each get their own picture: NAME.svg -> NAME-MODEL.svg.
            target = diagram if len(robots) == 1 else diagram.with_name(
                f"{diagram.stem}-{robot.name}{diagram.suffix}")
            write_diagram(robot, target, robot_findings, force)
    if fmt == "json" and len(outputs) > 1:
        text = "[\n" + ",\n".join(out.rstrip("\n") for out in outputs) + "\n]\n"
    else:
        text = ("\n" if fmt == "text" else "").join(outputs)
    click.echo(text, nl=False, color=_use_color(no_color))
    strict = config.strict if strict is None else strict
    failing = {"error", "warning"} if strict else {"error"}
    return 1 if any(f.severity in failing for f in findings) else 0
