"""`reedtool validate`: every static mistake that makes a model fail in Gazebo, with its line."""

from __future__ import annotations

import os
import sys
from pathlib import Path

import click

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
@click.option("--diagram", type=click.Path(path_type=Path, dir_okay=False), default=None,
              help="Also draw the rotor layout (.svg/.png), rotors named by findings in red.")
@click.option("--force", is_flag=True, help="Overwrite an existing --diagram file.")
def command(model: Path | None, mappings: tuple[str, ...], package_paths: tuple[Path, ...],
            fmt: str, select: tuple[str, ...], ignore: tuple[str, ...],
            explain_code: str | None, strict: bool | None, no_color: bool,
            controller_files: tuple[Path, ...] = (), diagram: Path | None = None,
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
    from reedtool.io.loader import load_robot
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
    robot = load_robot(model, parse_mappings(mappings), list(package_paths))
    controllers = []
    if controller_files:
        from reedtool.flightstack.controller_tables import load_controller_yaml

        controllers = [load_controller_yaml(path) for path in controller_files]
    findings = run_checks(robot, selection, controllers=controllers)
    if diagram is not None:
        from reedtool.commands.layout import write_diagram

        write_diagram(robot, diagram, findings, force)

    click.echo(render(findings, str(model), fmt, color=_use_color(no_color)), nl=False,
               color=_use_color(no_color))
    strict = config.strict if strict is None else strict
    failing = {"error", "warning"} if strict else {"error"}
    return 1 if any(f.severity in failing for f in findings) else 0
